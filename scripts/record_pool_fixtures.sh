#!/usr/bin/env bash
# Re-records the pool sessions in tests/fixtures/ the way a player makes them: `tidepool play`
# with its defaults in a 160x48 tmux pane, a 4 s warm-up, then `space` stones (a stone at a
# random spot) at a steady pace, then `q`. The replay holds the events at their steps, so the
# timing of tmux's keys does not have to be exact.
#
#     bash scripts/record_pool_fixtures.sh            # both sessions into tests/fixtures/
#
# Needs tmux and a release build (cargo build --release).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${TIDEPOOL:-target/release/tidepool}
record() { # NAME STONES INTERVAL_S
    local out=tests/fixtures/$1 session=tidepool-record-$$
    rm -f "$out"
    tmux new-session -d -s "$session" -x 160 -y 48 "$bin play --graphics cells --record $out"
    sleep 4
    for _ in $(seq "$2"); do
        tmux send-keys -t "$session" space
        sleep "$3"
    done
    tmux send-keys -t "$session" q
    for _ in $(seq 50); do tmux has-session -t "$session" 2>/dev/null || break; sleep 0.1; done
    tmux kill-session -t "$session" 2>/dev/null || true
    echo "$out: $(wc -l < "$out") lines, $(head -c 300 "$out")"
}
record pool-160x48.jsonl 8 1          # the player's defaults, a stone a second
record pool-stones-160x48.jsonl 16 0.5  # a stone every half second
