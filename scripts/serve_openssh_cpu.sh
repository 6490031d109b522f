#!/usr/bin/env bash
# Server CPU per delivered frame with real OpenSSH clients (issue 31, item 4): N `ssh` clients
# at 80x24, each given a pty by `script` (a terminal that answers nothing, as many scripted or
# minimal clients are; 256 colours, since SSH drops COLORTERM), all in one pool on one
# address. Each client drops a stone every 4 s (staggered) and quits with `q` after the run.
# The figure is the whole server process's CPU (user+sys from /proc, over its life) divided by
# the frames it delivered (the sum of its players' "frames sent" lines).
#
#   scripts/serve_openssh_cpu.sh                     # 40 clients, 40 s, target/release/tidepool
#   CLIENTS=10 SECS=20 BIN=/path/to/tidepool scripts/serve_openssh_cpu.sh
#   PORT=4300 FPS=30 SERVER_FLAGS="--rain 0" scripts/serve_openssh_cpu.sh
#
# Needs `ssh` and `script` (Debian: openssh-client, bsdutils). Talks to 127.0.0.1 only, stops
# by itself (each client quits after SECS, the server is stopped after them) and cleans up.
set -euo pipefail
cd "$(dirname "$0")/.."
clients=${CLIENTS:-40}
secs=${SECS:-40}
port=${PORT:-4300}
fps=${FPS:-30}
bin=${BIN:-target/release/tidepool}
for tool in ssh script "$bin"; do
    command -v "$tool" >/dev/null || { echo "serve_openssh_cpu.sh: $tool not found (Debian: apt-get install openssh-client bsdutils; cargo build --release --features serve)" >&2; exit 2; }
done
work=$(mktemp -d /tmp/serve-openssh-cpu.XXXXXX)
server=""
cleanup() {
    # Only what this script started: the clients' process group and the server.
    jobs -p | xargs -r kill 2>/dev/null || true
    [ -n "$server" ] && kill "$server" 2>/dev/null || true
    wait 2>/dev/null || true
    rm -rf "$work"
}
trap cleanup EXIT
mkdir -p "$work/home"
# shellcheck disable=SC2086
"$bin" serve --listen "127.0.0.1:$port" --host-key "$work/host_key" --max-clients $((clients + 8)) \
    --max-per-address $((clients + 8)) --handshake-timeout-ms 60000 --fps "$fps" ${SERVER_FLAGS:-} \
    >"$work/server.out" 2>"$work/server.log" &
server=$!
for _ in $(seq 100); do
    grep -q "ssh -p" "$work/server.out" 2>/dev/null && break
    sleep 0.1
done
grep -q "ssh -p" "$work/server.out" || { echo "the server did not start: $(cat "$work/server.log")" >&2; exit 1; }
ssh_cmd="ssh -F /dev/null -p $port -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null -o BatchMode=yes -o LogLevel=ERROR -tt localhost"
started=$(date +%s.%N)
for i in $(seq 0 $((clients - 1))); do
    # Keys: a stone every 4 s (the first after a staggered offset), `q` at the end.
    (
        sleep "$(awk -v i="$i" -v n="$clients" 'BEGIN { printf "%.2f", 2 + 4 * i / n }')"
        end=$(($(date +%s) + secs - 2))
        while [ "$(date +%s)" -lt "$end" ]; do printf ' '; sleep 4; done
        sleep 1
        printf q
        sleep 5
    ) | HOME="$work/home" TERM=xterm-256color script -q -e -c "stty cols 80 rows 24; exec $ssh_cmd" /dev/null >/dev/null 2>&1 &
done
wait_clients() {
    for pid in $(jobs -p); do
        [ "$pid" = "$server" ] || wait "$pid" 2>/dev/null || true
    done
}
wait_clients
ended=$(date +%s.%N)
read -r utime stime < <(awk '{ print $14, $15 }' "/proc/$server/stat")
hz=$(getconf CLK_TCK)
kill -TERM "$server"
wait "$server" 2>/dev/null || true
server=""
cpu=$(awk -v u="$utime" -v s="$stime" -v hz="$hz" 'BEGIN { printf "%.3f", (u + s) / hz }')
frames=$(grep -o '[0-9]* frames sent' "$work/server.log" | awk '{ s += $1 } END { print s + 0 }')
group=$(grep -o '([0-9]* from its group)' "$work/server.log" | tr -d '(' | awk '{ s += $1 } END { print s + 0 }')
players=$(grep -c ' left (' "$work/server.log" || true)
wall=$(awk -v a="$started" -v b="$ended" 'BEGIN { printf "%.1f", b - a }')
echo "clients: $clients OpenSSH at 80x24 under script, $secs s each; players seen by the server: $players"
echo "server CPU (user+sys, whole process): $cpu s over $wall s of wall time"
echo "frames delivered: $frames ($group from a group's encoding, $(awk -v g="$group" -v f="$frames" 'BEGIN { printf "%.0f", 100 * g / (f > 0 ? f : 1) }') %)"
# A player's frame rate: its frames over the pictures published while it played, times the
# pictures' rate (its session's length in published pictures, whatever its start and end).
echo "fps per player: $(grep -o '[0-9]* frames sent.* skipped of [0-9]* published' "$work/server.log" \
    | awk -v fps="$fps" '{ r = $1 / $(NF - 1) * fps; s += r; if (min == "" || r < min) min = r; n++ } END { printf "mean %.1f, min %.1f", s / n, min }')"
echo "server CPU per delivered frame: $(awk -v c="$cpu" -v f="$frames" 'BEGIN { printf "%.4f", 1000 * c / (f > 0 ? f : 1) }') ms"
echo "left: $(grep -o 'joined its group.*' "$work/server.log" | awk '{ j += $4; o += $8; b += $13; k += $15 } END { printf "joined %d, left for an overlay %d, behind %d, for another group %d", j, o, b, k }')"
echo "links (B/s): $(grep -o 'link [-0-9]* B/s' "$work/server.log" | awk '{ print $2 }' | sort -n | uniq -c | awk '{ printf "%s x%s  ", $2, $1 }')"
[ -n "${KEEP_LOG:-}" ] && cp "$work/server.log" "$KEEP_LOG"
grep "stopped in" "$work/server.log" || true
