#!/usr/bin/env bash
# The test suite: builds the real binaries, then runs every unit and end-to-end test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
cargo build --release --workspace --bins
cargo test --release --workspace --no-fail-fast
# The Python package (python/, docs/python.md): its wheel built from this checkout with
# maturin, installed into a fresh virtual environment (dependencies from the system site,
# installed by setup.sh), and its pytest suite run against this build's binaries.
bash scripts/test_python.sh
# The quick start's main job, end to end on a reduced size (8 rendered scenes).
qs_out="$(mktemp -d)"
RH_QUICKSTART_N=8 RH_OUT="$qs_out" bash scripts/quickstart.sh
test -s "$qs_out/report.md" && test -s "$qs_out/sheet.png"
rm -rf "$qs_out"
