#!/usr/bin/env bash
# The player screenshots the README and the guide show (docs/images/player-{80x24,160x48,240x70}.png): the pool
# with the player's defaults in a tmux pane of that size, 4 s of warm-up, two `space` stones
# half a second apart, then a second for the rings; the pane captured with its colours and
# painted by examples/terminal_screenshot.rs.
#
#     cargo build --release --examples && bash scripts/player_screenshots.sh
#
# Needs tmux.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=target/release/tidepool
for size in 80x24 160x48 240x70; do
    cols=${size%x*} rows=${size#*x} session=tidepool-shot-$$
    tmux new-session -d -s "$session" -x "$cols" -y "$rows" "COLORTERM=truecolor $bin play --graphics cells"
    sleep 4
    tmux send-keys -t "$session" space
    sleep 0.5
    tmux send-keys -t "$session" space
    sleep 1
    tmux capture-pane -t "$session" -e -N -p > "/tmp/player-$size.ans"
    tmux send-keys -t "$session" q
    sleep 0.3
    tmux kill-session -t "$session" 2>/dev/null || true
    target/release/examples/terminal_screenshot "/tmp/player-$size.ans" "docs/images/player-$size.png" "$cols" "$rows"
    rm "/tmp/player-$size.ans"
done
ls -la docs/images/player-*.png
