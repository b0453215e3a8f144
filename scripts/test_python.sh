#!/usr/bin/env bash
# The Python package's tests (called by scripts/test.sh): builds the `reacthuman` wheel
# from this checkout with maturin (sharing target/ with the workspace build), installs it
# into a fresh virtual environment, and runs python/tests with pytest against this
# checkout's release binaries (target/release, built by test.sh before).
# pytest's exit codes: 0 passed; 1 failures; 2 interrupted; 3 internal error; 4 usage
# error; 5 no tests collected (a broken suite: counted as a failure too).
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
python3 -m maturin build --release --quiet --out "$work/wheels"
# Fresh venv; numpy, pyarrow, gymnasium, pytest and inspect_ai (pinned) come from the
# system site (scripts/setup.sh installs them), so the test needs no network.
python3 -m venv --system-site-packages "$work/venv"
"$work/venv/bin/python" -m pip install --quiet --no-deps --no-index --disable-pip-version-check \
  "$work"/wheels/reacthuman-*.whl
"$work/venv/bin/python" -c "import reacthuman, gymnasium, inspect_ai; print('reacthuman', reacthuman.versions(), 'inspect_ai', inspect_ai.__version__)"
rc=0
( cd "$work" && RH_BIN_DIR="$OLDPWD/target/release" "$work/venv/bin/python" -m pytest -q \
    -p no:cacheprovider "$OLDPWD/python/tests" ) || rc=$?
case "$rc" in
  0) echo "test_python: all passed" ;;
  1) echo "test_python: some tests failed" >&2; exit 1 ;;
  5) echo "test_python: pytest collected no tests (broken suite)" >&2; exit 1 ;;
  *) echo "test_python: pytest stopped with exit code $rc (2 interrupted, 3 internal error, 4 usage error)" >&2; exit "$rc" ;;
esac
