#!/usr/bin/env bash
# Two players on two edges of one pool, seen in two real terminals (issue 31): a nats-server,
# two edges (`tidepool serve --bus`), and under Xvfb two xterms side by side, each running the
# OpenSSH client to its own edge. Each player drops stones (keys typed by xdotool into its own
# window); then the screen is saved as docs/serve/bus-two-edges.png (or OUT=FILE).
#
#   scripts/bus_screenshot.sh
#
# Display :90, ports 4311 (NATS) and 2311-2312, 127.0.0.1 only; stops what it started.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BIN:-target/release/tidepool}
out=${OUT:-docs/serve/bus-two-edges.png}
display=${DISPLAY_NUMBER:-:90}
for tool in nats-server Xvfb xterm xdotool import ssh "$bin"; do
    command -v "$tool" >/dev/null || { echo "bus_screenshot.sh: $tool not found (apt-get install nats-server xvfb xterm xdotool imagemagick openssh-client)" >&2; exit 2; }
done
work=$(mktemp -d /tmp/bus-shot.XXXXXX)
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    wait 2>/dev/null || true
    rm -rf "$work"
}
trap cleanup EXIT
nats-server -js -a 127.0.0.1 -p 4311 -sd "$work/js" >"$work/nats.log" 2>&1 &
pids+=($!)
sleep 1
for i in 0 1; do
    "$bin" serve --listen "127.0.0.1:$((2311 + i))" --host-key "$work/host_key" --bus nats://127.0.0.1:4311 \
        --pool shot --bus-edge "edge$i" --seed 7 --rain 0 >"$work/edge$i.out" 2>"$work/edge$i.log" &
    pids+=($!)
    for _ in $(seq 100); do grep -q "joined" "$work/edge$i.log" 2>/dev/null && break; sleep 0.2; done
    grep -q "joined" "$work/edge$i.log" || { echo "edge $i did not join: $(tail -3 "$work/edge$i.log")" >&2; exit 1; }
done
Xvfb "$display" -screen 0 1180x400x24 >/dev/null 2>&1 &
pids+=($!)
sleep 1
export DISPLAY=$display
mkdir -p "$work/home"
for i in 0 1; do
    HOME="$work/home" LANG=C.UTF-8 xterm -xrm 'XTerm*allowSendEvents: true' -T "edge$i" -geometry "80x24+$((i * 590))+0" -fa "DejaVu Sans Mono" -fs 8 -u8 -bg black \
        -e ssh -F /dev/null -p "$((2311 + i))" -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null \
        -o BatchMode=yes localhost &
    pids+=($!)
done
sleep 6
# Stones from both players, in turn: each xterm gets its own keys.
for round in 1 2 3; do
    for i in 0 1; do
        win=$(xdotool search --name "edge$i" | head -1)
        [ -n "$win" ] && xdotool type --window "$win" " " 2>/dev/null
        sleep 0.4
    done
done
sleep 1.5
import -window root "$out"
echo "saved $out; the edges' logs:"
grep -h "playing\|joined\|sequencer" "$work"/edge*.log | head -6
