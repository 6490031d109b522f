#!/usr/bin/env bash
# CPU per scene: plays each scene for SECONDS (default 20) in a 160x48 tmux window at the
# default 30 fps and reads the player's user + system CPU time from /proc, as a share of one
# core. A `space` stone every second keeps the pool busy. Needs tmux.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
command -v tmux >/dev/null || { echo "cpu_per_scene.sh: needs tmux" >&2; exit 2; }
cargo build --release -q
ticks=$(getconf CLK_TCK)
for scene in pool ocean lake; do
    session="tidepool-cpu-$scene-$$"
    tmux new -d -s "$session" -x 160 -y 48 -e COLORTERM=truecolor "./target/release/tidepool play $scene"
    sleep 2
    pid=$(pgrep -n -f "target/release/tidepool play $scene")
    read -r u0 s0 < <(awk '{print $14, $15}' "/proc/$pid/stat")
    for _ in $(seq "$seconds"); do tmux send-keys -t "$session" space; sleep 1; done
    read -r u1 s1 < <(awk '{print $14, $15}' "/proc/$pid/stat")
    status=$(tmux capture-pane -t "$session" -p | tail -1 | sed 's/  */ /g')
    tmux send-keys -t "$session" q
    sleep 0.5
    tmux kill-session -t "$session" 2>/dev/null || true
    python3 -c "print(f'$scene: {(($u1 - $u0) + ($s1 - $s0)) / $ticks / $seconds * 100:.1f}% of one core over $seconds s  (status: $status)')"
done
