#!/usr/bin/env bash
# The sea's wall-clock targets (issue 23), each the median of three runs of the release binary,
# the pool's 1080p still measured in the same run as the baseline:
#   - a 1080p gale still (Beaufort 9, foam from its short history) against the default 1080p pool;
#   - a calm still (Beaufort 2: no whitecaps, the foam's history skipped);
#   - a cold 1024x1024 map set (height, displacement, normals, foam);
#   - a 256x256 series of 300 frames that loops (a 100 s period at 3 fps: frame 300 is frame 0).
#
#     cargo build --release && bash scripts/ocean_speed.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bin=target/release/tidepool
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
median() { sort -n | sed -n 2p; }
time_of() {
    for _ in 1 2 3; do
        rm -rf "$work/out"; mkdir -p "$work/out"
        local t0 t1
        t0=$(date +%s.%N); "$@" >/dev/null 2>&1; t1=$(date +%s.%N)
        echo "$t1 - $t0" | bc -l
    done | median
}
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
pool=$(time_of "$bin" render pool --size 1920x1080 --out "$work/out/pool.png")
gale=$(time_of "$bin" render ocean --beaufort 9 --size 1920x1080 --out "$work/out/gale.png")
calm=$(time_of "$bin" render ocean --beaufort 2 --size 1920x1080 --out "$work/out/calm.png")
maps=$(time_of "$bin" render ocean --beaufort 6 --maps "$work/out/maps" --size 1024x1024)
series=$(time_of "$bin" render ocean --beaufort 6 --maps "$work/out/series" --size 256x256 --loop 100 --frames 300 --fps 3)
printf '| what | median of 3, s | target |\n|---|---|---|\n'
printf '| `render pool --size 1920x1080` (baseline) | %.2f | |\n' "$pool"
printf '| `render ocean --beaufort 9 --size 1920x1080` | %.2f (%.1fx the pool) | within 2.5x of the pool |\n' "$gale" "$(echo "$gale / $pool" | bc -l)"
printf '| `render ocean --beaufort 2 --size 1920x1080` | %.2f (%.1fx the pool) | no foam history |\n' "$calm" "$(echo "$calm / $pool" | bc -l)"
printf '| `render ocean --beaufort 6 --maps DIR --size 1024x1024` (cold) | %.2f | <= 2 s |\n' "$maps"
printf '| `render ocean --beaufort 6 --maps DIR --size 256x256 --loop 100 --frames 300 --fps 3` | %.2f | <= 10 s |\n' "$series"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
