#!/usr/bin/env bash
# Regenerates the gallery (docs/gallery/) with the commands shown beside each picture in
# docs/GUIDE.md (the README shows four of them).
# Needs tmux for the player screenshot (skipped with a note when it is missing).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
cargo build --release --quiet --example terminal_screenshot
T=target/release/tidepool
G=docs/gallery
mkdir -p "$G"

$T render pool --size 640x360 --out "$G/pool-caustics.png"
$T render pool --size 480x270 --frames 75 --fps 25 --out "$G/stones.gif"
$T render ocean --beaufort 3 --size 640x360 --out "$G/sea-beaufort-3.png"
$T render ocean --beaufort 6 --direction 60 --size 640x360 --out "$G/sea-beaufort-6.png"
$T render ocean --beaufort 9 --size 640x360 --sun 200,12 --out "$G/sea-beaufort-9.png"
for preset in calm-morning trade-wind north-atlantic-gale long-swell; do
  $T render ocean --preset "$preset" --size 640x360 --out "$G/preset-$preset.png"
done
$T spectrum --preset trade-wind --out "$G/spectrum-trade-wind.png" >/dev/null
if $T render lake --help >/dev/null 2>&1; then
  $T render lake --wind 0 --size 640x360 --out "$G/lake-calm.png"
  $T render lake --wind 6 --size 640x360 --out "$G/lake-windy.png"
fi

if command -v tmux >/dev/null; then
  session="tidepool-gallery-$$"
  tmux new-session -d -s "$session" -x 120 -y 36 "COLORTERM=truecolor $T play --seed 7 --graphics cells"
  sleep 2
  # Three left clicks and a right click, as SGR mouse reports, then a moment for the rings.
  for click in '0;30;10' '0;55;24' '0;75;8' '2;96;20'; do
    tmux send-keys -t "$session" -l $'\e[<'"$click"'M'$'\e[<'"$click"'m'
    sleep 0.12
  done
  sleep 0.3
  tmux capture-pane -t "$session" -e -N -p > "$G/player.ans"
  tmux send-keys -t "$session" q
  sleep 0.3
  tmux kill-session -t "$session" 2>/dev/null || true
  target/release/examples/terminal_screenshot "$G/player.ans" "$G/player.png" 120 36
  rm "$G/player.ans"
else
  echo "tmux not found: the player screenshot was not regenerated" >&2
fi
ls -la "$G"
