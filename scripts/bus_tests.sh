#!/usr/bin/env bash
# The bus's tests (feature `bus`: `tidepool serve --bus`) start real nats-server processes with
# JetStream. This installs Debian's nats-server when it is missing (apt-get), then runs them.
#   scripts/bus_tests.sh            install if needed, run the bus tests
#   scripts/bus_tests.sh --install  install if needed, run nothing (.ci/run does this before
#                                   `cargo test --all-features`, which runs them)
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
exec cargo test --features bus --test serve bus:: "$@"
