#!/usr/bin/env bash
# The whole test suite, slow and browser tests included, on both cores (plain `pytest` skips those); it ends with
# the 20 slowest tests, for keeping CI within its 15 minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/bootstrap.sh
.venv/bin/python -m pytest -m "slow or not slow or browser" -n 2 --dist loadgroup --durations=20 "$@"
