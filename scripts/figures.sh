#!/usr/bin/env bash
# Measures every figure the guide quotes in its figure tables in one run (criterion benchmarks of
# the pool, ocean, lake and encoder, a wall-clock render, peak memory, the player's bytes per
# frame) and rewrites those tables in docs/GUIDE.md, with the machine, date and load beside
# them. Takes about 15 minutes on 2 cores. `scripts/figures.py --tables-only` rewrites from
# the last run.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v /usr/bin/time >/dev/null || { echo "figures.sh: needs /usr/bin/time (apt-get install time)" >&2; exit 2; }
exec python3 scripts/figures.py "$@"
