"""CAPT vs CAPT-plain vs direct-regression PCT across categories, from `capt evaluate --json` files.

Each input file is one `capt evaluate` run that scored the three variants side by side on one
category's test split. Prints, per category and as the mean over categories, the mean direction
error (degrees), position error (normalised object frame), and state error, in degrees over revolute
joints and in metres over prismatic ones (never averaged together), each first averaged over the
category's joints. A joint without a position error is prismatic (``capt evaluate`` reports none for
them). A mean over no value (e.g. position when every category is prismatic) is "-".

    .venv/bin/python scripts/compare_variants.py benchmarks/perception_laptop.json \
        benchmarks/perception_oven.json --markdown benchmarks/variants_mean.md \
        --json benchmarks/variants_mean.json
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path

METRICS = (("dir_med", "direction (deg)"), ("pos_aed", "position (normalised)"),
           ("state_deg", "state, revolute (deg)"), ("state_m", "state, prismatic (m)"))


def joint_mean(values: list[float | None]) -> float | None:
    """Mean of the values that exist (over a category's joints, skipping joints without the metric,
    or over categories); None when none does."""
    present = [v for v in values if v is not None]
    return statistics.fmean(present) if present else None


def category_errors(s: dict) -> dict[str, float | None]:
    """One method's joint means on one category from its ``capt evaluate`` summary ``s``; the state
    is split by joint type (a joint with no position error is prismatic)."""
    revolute = [p is not None for p in s["pos_aed"]]
    return {"dir_med": joint_mean(s["dir_med"]), "pos_aed": joint_mean(s["pos_aed"]),
            "state_deg": joint_mean([v for v, r in zip(s["state_med"], revolute, strict=True) if r]),
            "state_m": joint_mean([v for v, r in zip(s["state_med"], revolute, strict=True) if not r])}


def compare(paths: list[Path]) -> dict:
    """{"methods": [...], "categories": {cat: {method: {metric: value}}}, "mean": {method: {...}}}."""
    per_cat: dict[str, dict[str, dict[str, float | None]]] = {}
    for path in paths:
        summary = json.loads(path.read_text())["summary"]
        for method, cats in summary.items():
            for cat, s in cats.items():
                per_cat.setdefault(cat, {})[method] = category_errors(s)
    methods = sorted(set.intersection(*(set(v) for v in per_cat.values())))
    if not methods:
        raise SystemExit("no method was evaluated on every category")
    mean = {m: {k: joint_mean([per_cat[c][m][k] for c in per_cat]) for k, _ in METRICS}
            for m in methods}
    return {"methods": methods, "categories": per_cat, "mean": mean, "inputs": [str(p) for p in paths]}


def markdown(result: dict) -> str:
    head = "| category | method | " + " | ".join(label for _, label in METRICS) + " |"
    lines = [head, "|" + " --- |" * (len(METRICS) + 2)]
    rows = [*((c, result["categories"][c]) for c in sorted(result["categories"])), ("mean", result["mean"])]
    for cat, by_method in rows:
        for m in result["methods"]:
            cells = ["-" if by_method[m][k] is None else f"{by_method[m][k]:.4g}" for k, _ in METRICS]
            lines.append(f"| {cat} | {m} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="+", type=Path, help="capt evaluate --json files")
    parser.add_argument("--markdown", type=Path, default=None)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    result = compare(args.inputs)
    table = markdown(result)
    print(table, end="")
    if args.markdown:
        args.markdown.write_text(table)
    if args.json:
        args.json.write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
