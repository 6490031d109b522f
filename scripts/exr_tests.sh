#!/usr/bin/env bash
# The EXR maps' check against an independent reader (OpenEXR's own Python bindings, with numpy
# and pillow: scripts/check_exr_maps.py). A fresh machine has only the Rust toolchain, so the
# README's test command lists this test as ignored, naming this script; this installs the
# reader with pip when it is missing, then runs the test.
#   scripts/exr_tests.sh            install if needed, run the test
#   scripts/exr_tests.sh --install  install if needed, run nothing
# Without the reader the test fails, saying so; it never passes without it.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! python3 -c 'import OpenEXR, numpy, PIL' >/dev/null 2>&1; then
    echo "exr_tests: the OpenEXR reader is missing; installing it with pip (OpenEXR numpy pillow)" >&2
    python3 -m pip install --quiet OpenEXR numpy pillow
fi
echo "exr_tests: $(python3 -c 'import OpenEXR, numpy; print("OpenEXR", OpenEXR.__version__, "numpy", numpy.__version__)')" >&2
if [ "${1:-}" = --install ]; then
    exit 0
fi
# Every feature, as the README's test command builds: .ci/run runs this after that command,
# and the same features reuse its build.
exec cargo test --all-features --test integration ocean::exr_maps_read_back_by_an_independent_reader -- --ignored "$@"
