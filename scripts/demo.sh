#!/usr/bin/env bash
# The main job: the paper's scene (section 5), results + VTU/PVD + pictures in out/paper_strip.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/bootstrap.sh
.venv/bin/ngwear run geometries/paper_strip.toml --out out/paper_strip "$@"
