#!/usr/bin/env bash
# How the shipped checkpoints degrade on corrupted depth clouds, with and without double voting, and
# what the statistical outlier filter buys back. Needs the four categories' data (`capt generate
# --config configs/generate/<category>.yaml --out data/<category>`). Writes, per category and
# condition, benchmarks/robustness/<category>_<condition>.{md,json.gz} (`capt evaluate`), per condition
# the mean over the categories with CAPT minus CAPT w/o DV and its paired 95% interval
# (benchmarks/robustness/mean_<condition>.{md,json}, scripts/compare_variants.py), and the summary
# table benchmarks/robustness/summary.{md,json} (scripts/robustness_table.py).
#   bash scripts/robustness_sweep.sh [category ...]     (default: laptop oven washing_machine eyeglasses)
# CONDITIONS="clean outliers5" runs only those conditions (the summary still reads every mean_ file).
# CHECKPOINTS="runs/{category}/capt_seed3/best.pt runs/{category}/capt_plain_seed3/best.pt" scores
# those checkpoints side by side instead of the shipped one ({category} is replaced per category), and
# OUT=benchmarks/robustness/variants_seed3 writes there instead.
set -euo pipefail
cd "$(dirname "$0")/.."
categories=("${@:-laptop oven washing_machine eyeglasses}")
read -r -a categories <<< "${categories[*]}"
out=${OUT:-benchmarks/robustness}
read -r -a checkpoint_patterns <<< "${CHECKPOINTS:-perception/checkpoints/{category\}.pt}"
mkdir -p "$out"
# condition name -> capt evaluate options
declare -A conditions=(
  [clean]=""
  [jitter2mm]="--test-jitter 0.002"
  [jitter5mm]="--test-jitter 0.005"
  [outliers5]="--test-outliers 0.05"
  [outliers20]="--test-outliers 0.2"
  [clean_filtered]="--filter-outliers"
  [outliers5_filtered]="--test-outliers 0.05 --filter-outliers"
  [outliers20_filtered]="--test-outliers 0.2 --filter-outliers"
  [clean_filtered_r5]="--filter-outliers --filter-std-ratio 5"
  [outliers5_filtered_r5]="--test-outliers 0.05 --filter-outliers --filter-std-ratio 5"
  [outliers20_filtered_r5]="--test-outliers 0.2 --filter-outliers --filter-std-ratio 5"
)
order=(clean jitter2mm jitter5mm outliers5 outliers20 clean_filtered outliers5_filtered outliers20_filtered
       clean_filtered_r5 outliers5_filtered_r5 outliers20_filtered_r5)
read -r -a run <<< "${CONDITIONS:-${order[*]}}"
for cond in "${run[@]}"; do
  [[ -v "conditions[$cond]" ]] || { echo "unknown condition: $cond (known: ${order[*]})" >&2; exit 2; }
  files=()
  for cat in "${categories[@]}"; do
    checkpoints=("${checkpoint_patterns[@]//\{category\}/$cat}")
    # shellcheck disable=SC2086  # the options are meant to split
    .venv/bin/capt evaluate "${checkpoints[@]}" --data "data/$cat" --split test \
      --without-double-voting --timing-clouds 1 ${conditions[$cond]} \
      --markdown "$out/${cat}_$cond.md" --json "$out/${cat}_$cond.json" > /dev/null
    files+=("$out/${cat}_$cond.json")
  done
  .venv/bin/python scripts/compare_variants.py "${files[@]}" \
    --markdown "$out/mean_$cond.md" --json "$out/mean_$cond.json" > /dev/null
  gzip -f "${files[@]}"  # the per-cloud files are kept compressed (compare_variants.py reads .json.gz)
  echo "done: $cond"
done
means=()
for cond in "${order[@]}"; do
  if [[ -f "$out/mean_$cond.json" ]]; then means+=("$out/mean_$cond.json"); fi
done
.venv/bin/python scripts/robustness_table.py "${means[@]}" --markdown "$out/summary.md" --json "$out/summary.json"
