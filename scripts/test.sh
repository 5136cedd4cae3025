#!/usr/bin/env bash
# The whole test suite, slow tests included, on both cores (plain `pytest` skips the slow ones).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/bootstrap.sh
.venv/bin/python -m pytest -m "slow or not slow" -n 2 "$@"
