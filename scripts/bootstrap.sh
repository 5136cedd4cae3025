#!/usr/bin/env bash
# Create .venv (Python >= 3.11) with ngwear and its extras (test, app, docs), and the documentation's MathJax
# (npm, into docs/node_modules); idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
# Debian packages: EGL (headless pictures: VTK renders through EGL with Mesa's software rasteriser) and
# Chromium (the browser tests drive it through Playwright, which cannot download its own browser here);
# npm (the documentation serves its own MathJax, from the npm registry).
missing=()
ldconfig -p | grep -q 'libEGL.so.1' || missing+=(libegl1 libgl1 libgl1-mesa-dri)
[ -x /usr/bin/chromium ] || missing+=(chromium)
command -v npm >/dev/null || missing+=(npm)
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then
    bash scripts/apt_get.sh update -qq && bash scripts/apt_get.sh install -y -qq --no-install-recommends "${missing[@]}"
  else
    echo "ngwear: pictures, browser tests and the docs need: sudo apt-get install ${missing[*]}" >&2
  fi
fi
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
stamp=.venv/.ngwear-installed
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
  .venv/bin/python -m pip install --quiet --upgrade pip
  .venv/bin/python -m pip install --quiet -e '.[test,app,docs]'
  touch "$stamp"
fi
mathjax=docs/node_modules/mathjax/package.json
if command -v npm >/dev/null && { [ ! -f "$mathjax" ] || [ docs/package-lock.json -nt "$mathjax" ]; }; then
  npm ci --prefix docs --no-audit --no-fund --silent
  touch "$mathjax"
fi
