#!/usr/bin/env bash
# One pool over NATS at scale (issue 31, item 5), all on this machine: a nats-server with
# JetStream, EDGES edges (`tidepool serve --bus`, release) and, for each edge, a load client in a
# process of its own (tests/serve/crowd_client.rs) with PLAYERS players of 80x24, each dropping
# a stone every STONE_MS. After everyone is in and a warm-up, it measures for RUN_SECONDS: each
# edge's CPU (user+sys from /proc) and memory, the players' frame rates, nats-server's messages
# and bytes a second (its /varz), and a key's latency from one edge's player to another edge
# taking it from the log (the edges' TIDEPOOL_BUS_TRACE lines; same machine clock).
#
#   scripts/bus_scale.sh                          # 3 edges x 300 players, 300 s, --fps 15
#   EDGES=3 PLAYERS=100 RUN_SECONDS=60 scripts/bus_scale.sh
#
# Ports 4301 (NATS), 4302 (its monitor) and 2301.. (the edges), 127.0.0.1 only. It stops by
# itself (the clients end after their window; everything this script started is then stopped)
# and removes its files unless KEEP=DIR names a folder for the logs.
set -euo pipefail
cd "$(dirname "$0")/.."
edges=${EDGES:-3}
players=${PLAYERS:-300}
seconds=${RUN_SECONDS:-300}
stone_ms=${STONE_MS:-4000}
fps=${FPS:-15}
warm=${WARM_UP:-15}
slack=${CLIENT_SLACK:-30}
nats_port=${NATS_PORT:-4301}
monitor=$((nats_port + 1))
first_port=${EDGE_PORT:-2301}
bin=${BIN:-target/release/tidepool}
command -v nats-server >/dev/null || { echo "bus_scale.sh: nats-server not found (scripts/bus_tests.sh --install)" >&2; exit 2; }
[ -x "$bin" ] || { echo "bus_scale.sh: $bin not found (cargo build --release --features bus)" >&2; exit 2; }
# The load client is built with the edges' features: a build with fewer would relink
# target/release/tidepool without `--bus` (cargo builds the binary for the test target).
client=$(cargo test --release --features bus --test serve --no-run 2>&1 | grep -o 'target/release/deps/serve-[0-9a-f]*' | tail -1)
[ -x "$client" ] || { echo "bus_scale.sh: the load client did not build" >&2; exit 1; }
work=$(mktemp -d /tmp/bus-scale.XXXXXX)
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    wait 2>/dev/null || true
    [ -n "${KEEP:-}" ] && mkdir -p "$KEEP" && cp "$work"/*.log "$KEEP"/ 2>/dev/null
    rm -rf "$work"
}
trap cleanup EXIT
ulimit -n 20000
nats-server -js -a 127.0.0.1 -p "$nats_port" -m "$monitor" -sd "$work/js" >"$work/nats.log" 2>&1 &
nats=$!
pids+=("$nats")
for _ in $(seq 50); do curl -sf "http://127.0.0.1:$monitor/varz" >/dev/null 2>&1 && break; sleep 0.2; done
pool="h31scale$$"
edge_pids=()
for i in $(seq 0 $((edges - 1))); do
    port=$((first_port + i))
    TIDEPOOL_BUS_TRACE=1 "$bin" serve --listen "127.0.0.1:$port" --host-key "$work/host_key" \
        --max-clients $((players + 16)) --max-per-address $((players + 16)) --handshake-timeout-ms 120000 \
        --fps "$fps" --total-bandwidth 256M --bus "nats://127.0.0.1:$nats_port" --pool "$pool" --bus-edge "e$i" \
        >"$work/edge$i.out" 2>"$work/edge$i.log" &
    edge_pids+=($!)
    pids+=($!)
    for _ in $(seq 100); do grep -q "ssh -p" "$work/edge$i.out" 2>/dev/null && break; sleep 0.2; done
done
client_pids=()
for i in $(seq 0 $((edges - 1))); do
    # Each client times its own window from when its own players are all in, which can be well
    # before the others' (round 8: 10 s). They play CLIENT_SLACK s past this script's window, so
    # every memory and CPU reading below is taken while all the players are still connected (each
    # reading checks it and says so).
    CROWD_PORT=$((first_port + i)) CROWD_PLAYERS="$players" CROWD_SECONDS=$((seconds + slack)) CROWD_WARM_UP="$warm" \
        CROWD_STONE_MS="$stone_ms" "$client" --ignored --exact crowd_client::crowd_client --nocapture \
        >"$work/client$i.log" 2>&1 &
    client_pids+=($!)
    pids+=($!)
done
# The window starts when every client says so.
until [ "$(cat "$work"/client*.log 2>/dev/null | grep -c 'window starts')" -ge "$edges" ]; do
    for p in "${client_pids[@]}"; do kill -0 "$p" 2>/dev/null || { echo "a client ended early:"; tail -5 "$work"/client*.log; exit 1; }; done
    for i in "${!edge_pids[@]}"; do kill -0 "${edge_pids[$i]}" 2>/dev/null || { echo "edge e$i ended early:"; tail -5 "$work/edge$i.log"; exit 1; }; done
    sleep 1
done
stat_cpu() { awk '{ print $14 + $15 }' "/proc/$1/stat"; }
stat_rss() { awk '/VmRSS/ { print $2 }' "/proc/$1/status"; }
# The clients whose process has ended (their players left): empty while every one still plays.
gone_clients() {
    local i gone=""
    for i in "${!client_pids[@]}"; do kill -0 "${client_pids[$i]}" 2>/dev/null || gone="$gone client$i"; done
    echo "${gone# }"
}
# The clients' CPU ticks together, or nothing when one of them has ended.
clients_cpu() {
    local p sum=0 t
    for p in "${client_pids[@]}"; do t=$(stat_cpu "$p" 2>/dev/null) || return 0; sum=$((sum + t)); done
    echo "$sum"
}
varz() { curl -sf "http://127.0.0.1:$monitor/varz"; }
t0=$(date +%s.%N)
t0_us=$(date +%s%6N)
v0=$(varz)
cpu0=(); rss0=()
for p in "${edge_pids[@]}"; do cpu0+=("$(stat_cpu "$p")"); rss0+=("$(stat_rss "$p")"); done
ncpu0=$(stat_cpu "$nats")
ccpu0=$(clients_cpu)
echo "window: $seconds s from $(date -u +%T), load average $(cut -d' ' -f1-3 /proc/loadavg)"
# Memory every 30 s.
samples=""
for _ in $(seq $((seconds / 30))); do
    sleep 30
    line="$(( $(date +%s) - ${t0%.*} ))s:"
    for p in "${edge_pids[@]}"; do line="$line $(stat_rss "$p")"; done
    gone=$(gone_clients)
    [ -z "$gone" ] || line="$line (after $gone left)"
    samples="$samples$line kB; "
done
sleep $((seconds % 30))
t1=$(date +%s.%N)
v1=$(varz)
rss1=(); for p in "${edge_pids[@]}"; do rss1+=("$(stat_rss "$p")"); done
ccpu1=$(clients_cpu)
gone=$(gone_clients)
hz=$(getconf CLK_TCK)
wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }')
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
for i in $(seq 0 $((edges - 1))); do
    p=${edge_pids[$i]}
    cores=$(awk -v a="${cpu0[$i]}" -v b="$(stat_cpu "$p")" -v hz="$hz" -v w="$wall" 'BEGIN { printf "%.3f", (b - a) / hz / w }')
    echo "edge e$i: CPU $cores cores ($(awk -v c="$cores" -v n="$players" 'BEGIN { printf "%.5f", c / n }') cores a player), memory ${rss0[$i]} kB at the start, ${rss1[$i]} kB at the end"
done
if [ -z "$gone" ]; then
    echo "edges' memory (s: kB each; every reading with all clients' players connected): $samples"
else
    echo "edges' memory (s: kB each): $samples (the end's reading after $gone left: raise CLIENT_SLACK)"
fi
if [ -n "$ccpu0" ] && [ -n "$ccpu1" ]; then
    echo "the load clients' processes: CPU $(awk -v a="$ccpu0" -v b="$ccpu1" -v hz="$hz" -v w="$wall" 'BEGIN { printf "%.3f", (b - a) / hz / w }') cores together"
else
    echo "the load clients' processes: CPU not read (a client had ended)"
fi
ncores=$(awk -v a="$ncpu0" -v b="$(stat_cpu "$nats")" -v hz="$hz" -v w="$wall" 'BEGIN { printf "%.3f", (b - a) / hz / w }')
python3 - "$wall" "$ncores" <<EOF
import json, sys
v0, v1 = json.loads('''$v0'''), json.loads('''$v1''')
wall, cores = float(sys.argv[1]), sys.argv[2]
d = lambda k: (v1[k] - v0[k]) / wall
print(f"nats-server: in {d('in_msgs'):.0f} msgs/s {d('in_bytes'):.0f} B/s, out {d('out_msgs'):.0f} msgs/s {d('out_bytes'):.0f} B/s, CPU {cores} cores, memory {v1['mem'] // 1024} kB")
EOF
for p in "${client_pids[@]}"; do wait "$p" || true; done
grep -h '^crowd:.*players' "$work"/client*.log || true
# A key's latency: `bus-trace sent EDGE N TIME` on one edge, `bus-trace taken EDGE N at STEP
# for STAMP TIME BYTES` on the others (microseconds since the epoch).
python3 - "$work" "$edges" "$fps" "$t0_us" <<'EOF'
import sys
work, edges, fps, t0_us = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
sent, took = {}, []
for i in range(edges):
    for line in open(f"{work}/edge{i}.log", errors="replace"):
        w = line.split()
        if len(w) >= 5 and w[0] == "bus-trace" and w[1] == "sent":
            sent[(w[2], w[3])] = float(w[4])
for i in range(edges):
    for line in open(f"{work}/edge{i}.log", errors="replace"):
        w = line.split()
        if len(w) >= 10 and w[0] == "bus-trace" and w[1] == "taken" and w[2] != f"e{i}":
            t0 = sent.get((w[2], w[3]))
            # Keys sent in the window only (not while the crowd was connecting).
            if t0 is not None and t0 >= t0_us:
                step, stamp, t1 = float(w[5]), float(w[7]), float(w[8])
                took.append(((t1 - t0) / 1000, (t1 - t0) / 1000 + max(stamp - step, 0) / 60 * 1000 + 1000 / fps / 2))
if took:
    log = sorted(t[0] for t in took); screen = sorted(t[1] for t in took)
    p = lambda v, q: v[int((len(v) - 1) * q)]
    print(f"a key (sent in the window) from one edge's player to another edge: n {len(log)}, taken from the log median {p(log, .5):.1f} ms p95 {p(log, .95):.1f} ms; "
          f"ring on its screen (modelled: + the lead to the stamp + half a frame) median {p(screen, .5):.1f} ms p95 {p(screen, .95):.1f} ms")
else:
    print("no key was traced across edges")
EOF
grep -h "refused\|lost" "$work"/edge*.log | head -5 || true
# The sequencer's role over the whole run (warm-up included): how often an edge took it, and
# the requests its holders refused (each logged, or summed up once a second).
python3 - "$work" "$edges" <<'EOF'
import re, sys
work, edges = sys.argv[1], int(sys.argv[2])
took, refused = 0, 0
for i in range(edges):
    for line in open(f"{work}/edge{i}.log", errors="replace"):
        if "this edge is the sequencer (term" in line:
            took += 1
        elif line.startswith("bus: refused a request"):
            refused += 1
        elif (m := re.match(r"bus: refused (\d+) more requests", line)):
            refused += int(m.group(1))
print(f"the sequencer's role: taken {took} times (moved {max(took - 1, 0)} times); requests refused: {refused}")
EOF
