#!/usr/bin/env bash
# The bus's tests (feature `bus`: `tidepool serve --bus`) start real nats-server processes with
# JetStream. This installs Debian's nats-server when it is missing (apt-get), then runs them.
#   scripts/bus_tests.sh            install if needed, run the bus tests (ignored by the
#                                   README's test command: a fresh machine has no nats-server)
#   scripts/bus_tests.sh --install  install if needed, run nothing
#   scripts/bus_tests.sh memory     an edge's memory flat under 40 players (about 50 s, so not
#                                   in the default run: tests/serve/bus/memory.rs)
#   scripts/bus_tests.sh load       the bus's figures (BUS_EDGES, BUS_PLAYERS per edge,
#                                   BUS_SECONDS, BUS_STONE_MS: see tests/serve/bus_load.rs)
# Without nats-server the tests fail, saying so; they never pass without it.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v nats-server >/dev/null 2>&1; then
    echo "bus_tests: nats-server is missing; installing Debian's package" >&2
    sudo=""
    [ "$(id -u)" = 0 ] || sudo="sudo"
    $sudo apt-get install -y nats-server || { $sudo apt-get update && $sudo apt-get install -y nats-server; }
fi
echo "bus_tests: $(nats-server --version)" >&2
if [ "${1:-}" = --install ]; then
    exit 0
fi
if [ "${1:-}" = load ]; then
    ulimit -n 20000
    TIDEPOOL_BUS_TRACE=1 exec cargo test --release --features bus --test serve bus_load:: -- --ignored --nocapture
fi
if [ "${1:-}" = memory ]; then
    exec cargo test --all-features --test serve bus::memory:: -- --ignored --nocapture
fi
# Every feature, as the README's test command builds: .ci/run runs this after that command,
# and the same features reuse its build. First the library's own (the sequencer's role on its
# thread: src/cli/serve/bus/lead_tests.rs), then the edges as processes. Ports:
# TIDEPOOL_BUS_TEST_PORTS=FIRST-LAST (default 42000-42999).
cargo test --all-features --lib cli::serve::bus:: -- --ignored "$@"
exec cargo test --all-features --test serve bus:: -- --ignored --skip bus::memory:: "$@"
