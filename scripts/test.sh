#!/usr/bin/env bash
# The whole test suite, slow and browser tests included, on both cores (plain `pytest` skips those); it ends with
# the 20 slowest tests, for keeping CI within its 15 minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/bootstrap.sh
# Two workers on two cores: each worker's BLAS, MKL and OpenMP on one thread (a caller's setting wins).  With two
# threads each they oversubscribe the cores, and threads that wait for a busy core slow the suite down.
export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}" MKL_NUM_THREADS="${MKL_NUM_THREADS:-1}" \
       OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"
.venv/bin/python -m pytest -m "slow or not slow or browser" -n 2 --dist loadgroup --durations=20 "$@"
