#!/usr/bin/env bash
# Checks the documented deployment (docs/serve/deploy/): the nats-server configuration with TLS
# and accounts, and the systemd units. With a throwaway CA (openssl) and the configuration's
# paths pointed at a temporary folder:
#   1. `nats-server -t -c` accepts the configuration;
#   2. that nats-server runs, and an edge (`tidepool serve --bus tls://edge1:PASSWORD@...
#      --bus-ca ca.pem`) joins the pool over TLS and takes the sequencer's role;
#   3. an edge with a wrong password, and one with none, are refused and never join;
#   4. `systemd-analyze verify` accepts both units without a warning.
# Ports 4303 (NATS) and 2304-2306, on 127.0.0.1; stops what it started and removes its files.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BIN:-target/release/tidepool}
for tool in nats-server openssl systemd-analyze "$bin"; do
    command -v "$tool" >/dev/null || { echo "bus_deploy_check.sh: $tool not found (scripts/bus_tests.sh --install; apt-get install openssl; cargo build --release --features bus)" >&2; exit 2; }
done
work=$(mktemp -d /tmp/bus-deploy.XXXXXX)
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    wait 2>/dev/null || true
    rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "bus_deploy_check.sh: FAILED: $*" >&2; exit 1; }
port=4303
# A CA and the server's certificate for 127.0.0.1.
openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj "/CN=tidepool test CA" \
    -keyout "$work/ca-key.pem" -out "$work/ca.pem" 2>/dev/null
openssl req -newkey rsa:2048 -nodes -subj "/CN=127.0.0.1" -keyout "$work/server-key.pem" \
    -out "$work/server.csr" 2>/dev/null
printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\n' >"$work/san.ext"
openssl x509 -req -in "$work/server.csr" -CA "$work/ca.pem" -CAkey "$work/ca-key.pem" -CAcreateserial \
    -days 2 -extfile "$work/san.ext" -out "$work/server.pem" 2>/dev/null
sed -e "s|/etc/nats/tls/|$work/|g" -e "s|/var/lib/nats|$work/js|" -e "s|0.0.0.0:4222|127.0.0.1:$port|" \
    docs/serve/deploy/nats-server.conf >"$work/nats-server.conf"
export TIDEPOOL_EDGE1_PASSWORD=pw-edge1-$$ TIDEPOOL_EDGE2_PASSWORD=pw-edge2-$$ TIDEPOOL_EDGE3_PASSWORD=pw-edge3-$$
export NATS_ADMIN_PASSWORD=pw-admin-$$
nats-server -t -c "$work/nats-server.conf" >"$work/t.log" 2>&1 || fail "nats-server -t: $(cat "$work/t.log")"
echo "1. nats-server -t -c: $(tail -1 "$work/t.log")"
nats-server -c "$work/nats-server.conf" >"$work/nats.log" 2>&1 &
pids+=($!)
for _ in $(seq 50); do grep -q "Server is ready" "$work/nats.log" && break; sleep 0.2; done
grep -q "Server is ready" "$work/nats.log" || fail "nats-server did not start: $(tail -5 "$work/nats.log")"
# An edge: returns when its log has $2 within $3 s (0) or not (1).
edge() {
    local name=$1 url=$2 listen=$3
    "$bin" serve --listen "127.0.0.1:$listen" --host-key "$work/host_key" --bus "$url" --pool main \
        --bus-edge "$name" --bus-ca "$work/ca.pem" >"$work/$name.out" 2>"$work/$name.log" &
    pids+=($!)
}
wait_log() {
    for _ in $(seq $(($3 * 5))); do grep -q "$2" "$work/$1.log" 2>/dev/null && return 0; sleep 0.2; done
    return 1
}
edge good "tls://edge1:$TIDEPOOL_EDGE1_PASSWORD@127.0.0.1:$port" 2304
wait_log good "this edge is the sequencer" 20 || fail "the edge did not join over TLS: $(tail -5 "$work/good.log")"
echo "2. an edge with edge1's password over TLS joined: $(grep -m1 'sequencer' "$work/good.log")"
edge wrong "tls://edge1:not-the-password@127.0.0.1:$port" 2305
edge nobody "tls://127.0.0.1:$port" 2306
sleep 6
for name in wrong nobody; do
    grep -q "joined\|sequencer" "$work/$name.log" && fail "edge '$name' joined: $(tail -3 "$work/$name.log")"
    echo "3. edge '$name' refused: $(grep -m1 -i 'bus' "$work/$name.log" | cut -c1-160)"
done
grep -qi "authorization" "$work/nats.log" && echo "   nats-server: $(grep -m1 -i 'authorization' "$work/nats.log" | cut -c1-160)"
# The units, with their programs where this machine has them: any warning fails.
sed "s|/usr/local/bin/tidepool|$(realpath "$bin")|" docs/serve/deploy/tidepool-edge.service >"$work/tidepool-edge.service"
sed "s|/usr/sbin/nats-server|$(command -v nats-server)|" docs/serve/deploy/nats-server.service >"$work/nats-server.service"
verify=$(systemd-analyze verify "$work/tidepool-edge.service" "$work/nats-server.service" 2>&1) || fail "systemd-analyze verify: $verify"
[ -z "$verify" ] || fail "systemd-analyze verify: $verify"
echo "4. systemd-analyze verify: both units accepted, no warning"
echo "bus_deploy_check.sh: the deployment's configuration checks passed"
