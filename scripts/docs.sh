#!/usr/bin/env bash
# The documentation site: docs/ (Markdown, the executed gallery of docs/demos, the reference generated from the
# code) → docs/_build/html/index.html, warnings as errors.  Open that file in a browser; nothing is fetched online.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/bootstrap.sh
.venv/bin/python -m sphinx -b html -W --keep-going docs docs/_build/html "$@"
echo "open docs/_build/html/index.html"
