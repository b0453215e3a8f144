#!/usr/bin/env bash
# The test suite: builds the real binaries, then runs every unit and end-to-end test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
cargo build --release --workspace --bins
cargo test --release --workspace
