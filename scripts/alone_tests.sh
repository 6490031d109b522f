#!/usr/bin/env bash
# The tests that measure a rate in real time, each run alone: a slow kitty's rate over a pty
# and through serve. Beside the test command's other tests (debug players, fake terminals and
# pictures decoded on 2 cores) the player is short of CPU, its answers read late look like a
# queue, and the rate falls for reasons of the test machine, not of the link control (10 kB/s
# in two runs of three in CI, 135-370 kB/s alone). The test command lists them as ignored,
# naming this script; `.ci/run` runs it after that command, on the build it made.
#   scripts/alone_tests.sh            both tests, one after the other
# Nothing else should run meanwhile; a failure here is a failure of the link control.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --all-features --test integration -- --ignored --exact \
    fake_terminals::a_kitty_slow_to_answer_keeps_its_rate_over_ssh "$@"
cargo test --all-features --test serve -- --ignored --exact \
    fake_terminals::a_kitty_slow_to_answer_keeps_its_rate_through_serve "$@"
