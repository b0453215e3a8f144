#!/usr/bin/env bash
# The main job on the embedded defaults: install what is missing, build, make a small
# dataset, verify its replay, and score baseline predictions against it.
# Output goes to ${RH_OUT:-out/quickstart}; RH_QUICKSTART_N scenes (default 60; CI runs
# it with fewer, from scripts/test.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
cargo build --release --workspace --bins

out="${RH_OUT:-out/quickstart}"
dataset="$out/dataset"
rm -rf "$dataset"
mkdir -p "$out"
./target/release/rh-pipeline build --n "${RH_QUICKSTART_N:-60}" --out "$dataset"
./target/release/rh-pipeline verify "$dataset"
./target/release/rh-pipeline sheet "$dataset" --out "$out/sheet.png"

preds="$out/preds.jsonl"
: > "$preds"
for baseline in oracle majority random always-catch freeze; do
  ./target/release/rh-score baseline "$baseline" --dataset "$dataset" --model "$baseline" >> "$preds"
done
./target/release/rh-score "$preds" --dataset "$dataset" \
  --json "$out/report.json" --csv "$out/report.csv" --markdown "$out/report.md" --figures "$out/figures" \
  --html "$out/site"
echo "quickstart: dataset in $dataset (videos/, frames/; contact sheet $out/sheet.png), report in $out/report.md, figures in $out/figures"
echo "quickstart: open the report site: file://$(cd "$out/site" && pwd)/index.html"
