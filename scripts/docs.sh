#!/usr/bin/env bash
# The documentation site: docs/ (Markdown, the executed gallery of docs/demos, the reference generated from the
# code) → docs/_build/html/index.html, warnings as errors.  Open that file in a browser; nothing is fetched online.
# A build that ended otherwise than done (0) or with warnings (1) — interrupted, its environment saved and its search
# index half written, or killed — is not continued: the next one starts afresh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/bootstrap.sh
site=docs/_build/html
building=docs/_build/building
if [ -e "$building" ]; then
  echo "ngwear: the last docs build was interrupted: building anew" >&2
  rm -rf "$site"
fi
mkdir -p docs/_build && touch "$building"
status=0
.venv/bin/python -m sphinx -b html -W --keep-going docs "$site" "$@" || status=$?
[ "$status" -gt 1 ] || rm -f "$building"
[ "$status" = 0 ] || exit "$status"
echo "open $site/index.html"
