#!/usr/bin/env bash
# The committed alive-pool session (tests/fixtures/alive-160x48.jsonl) played by timg, for the
# The guide's bandwidth comparison (docs/GUIDE.md): tidepool renders the session's exact frames (160x94 pixels,
# 30 fps, as the player showed them), ffmpeg packs them losslessly (FFV1), and timg plays the
# video in a 160x48 pseudo-terminal with half blocks in truecolor, as the player draws; the
# bytes it writes are counted. The player's own figure for the same frames is the codec
# benchmark's unlimited row (CODEC=table cargo bench --bench codec).
#
# Needs Debian's timg and ffmpeg (apt-get install timg ffmpeg) and util-linux's `script`.
set -euo pipefail
cd "$(dirname "$0")/.."
for tool in timg ffmpeg script; do
    command -v "$tool" >/dev/null || { echo "timg_compare.sh: needs $tool (apt-get install timg ffmpeg)" >&2; exit 2; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cargo build --release -q
frames=368
./target/release/tidepool render pool --replay tests/fixtures/alive-160x48.jsonl --steps 0 \
    --frames "$frames" --fps 30 --out "$work/f_{frame:04}.png" 2>/dev/null
ffmpeg -loglevel error -framerate 30 -i "$work/f_%04d.png" -c:v ffv1 "$work/alive.mkv"
# 160x47 cells of picture (the player keeps the last row for its status line); -V plays it
# as a video at its own 30 fps.
script -q -c "stty cols 160 rows 48; TERM=xterm-256color COLORTERM=truecolor timg -V -ph -g160x47 --loops=1 $work/alive.mkv" \
    /dev/null > "$work/timg.out"
bytes=$(stat -c %s "$work/timg.out")
seconds=$(python3 -c "print($frames / 30)")
version=$(timg --version 2>&1 | head -1 | awk '{print $2}')
python3 -c "b=$bytes; s=$seconds; print(f'timg $version: {b:,} bytes for $frames frames ({s:.1f} s) = {b / s / 1000:,.0f} kB/s')"
