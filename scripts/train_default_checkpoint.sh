#!/usr/bin/env bash
# Reproduce a shipped default checkpoint: generate the category's dataset, train CAPT (and, with
# --baselines, CAPT-plain and direct-regression PCT), evaluate them side by side on the unseen test
# split, and record every number under benchmarks/.
#
#   bash scripts/train_default_checkpoint.sh CATEGORY [EPOCHS] [--baselines]
set -euo pipefail
cd "$(dirname "$0")/.."
cat=${1:?category}
epochs=${2:-12}
variants="capt"
[ "${3:-}" = "--baselines" ] && variants="capt capt_plain pct_regression"
capt=.venv/bin/capt
$capt generate --config "configs/generate/$cat.yaml" --out "data/$cat" --json "benchmarks/generate_$cat.json"
ckpts=()
for v in $variants; do
  $capt train --config "configs/perception/$v.yaml" --data "data/$cat" --out "runs/$cat/$v" \
    --epochs "$epochs" --device cpu --json "benchmarks/train_${cat}_$v.json"
  ckpts+=("runs/$cat/$v/best.pt")
done
$capt evaluate "${ckpts[@]}" --data "data/$cat" --split test --markdown "benchmarks/perception_$cat.md" \
  --figures "benchmarks/figures" --json "benchmarks/perception_$cat.json"
