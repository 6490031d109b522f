#!/usr/bin/env bash
# The serve benchmarks (not CI tests): 1,000 players for five minutes, and 10,000 connects and
# disconnects. Each talks to a server on 127.0.0.1 only, stops by itself, and prints a report.
#
#   scripts/serve_load.sh            # 1,000 players, 5 minutes, --client-bandwidth auto
#   LOAD_BANDWIDTH=100k scripts/serve_load.sh   # each player's link fixed at 100 kB/s
#   LOAD_PLAYERS=200 LOAD_MINUTES=1 scripts/serve_load.sh   # a quick calibration
#   scripts/serve_load.sh churn      # 10,000 sessions, memory and descriptors before and after
#   scripts/serve_load.sh flat       # 200 players, 2 minutes: memory flat within 2 % (asserted)
set -euo pipefail
cd "$(dirname "$0")/.."
# 1,000 players: a socket each on both sides, and the server's own.
ulimit -n 20000
case "${1:-load}" in
    load) filter=load_1000 ;;
    churn) filter=churn_10000 ;;
    flat) filter=load_200_players_for_two_minutes ;;
    *) echo "usage: $0 [load|churn|flat]" >&2; exit 2 ;;
esac
cargo test --release --features serve --test serve -- --ignored --nocapture --test-threads 1 "$filter" 2>&1 | grep -v '^serve: 127'
