"""One table of how each method's mean errors move with the test clouds' corruption, from
`scripts/compare_variants.py --json` files (one per condition, each the mean over the same categories).

A row per condition and method: the mean direction error (degrees), position error (normalised object
frame) and revolute state error (degrees) over the categories, the share of axes pointing the wrong way
(direction error over 90 degrees; "-" in files older than it), and, for every method beside the
reference, the reference's paired gap (reference minus method) with its 95% bootstrap interval over the
test clouds. The condition's name is the file's stem less a leading ``mean_``; its corruption and
outlier filter are read from the file.

    .venv/bin/python scripts/robustness_table.py benchmarks/robustness/mean_{clean,outliers20}.json \
        --markdown benchmarks/robustness/summary.md --json benchmarks/robustness/summary.json
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from capt_common.json_report import script_command, write_json, write_markdown

METRICS = (("dir_med", "direction (deg)", ".2f"), ("pos_aed", "position (normalised)", ".4f"),
           ("state_deg", "state (deg)", ".2f"))


def condition_name(path: Path) -> str:
    """``mean_outliers20.json`` -> ``outliers20``."""
    return path.stem.removeprefix("mean_")


def rows(paths: list[Path]) -> list[dict]:
    """One dict per (condition, method): condition, corruption, outlier_filter, method, the mean errors,
    and ``gap`` {metric: {difference, low, high}} for non-reference methods (None without paired gaps)."""
    out = []
    for path in paths:
        result = json.loads(path.read_text())
        reference = result["reference"]
        for method in result["methods"]:
            gap = None
            paired_mean = result.get("paired", {}).get(method, {}).get("mean")
            if method != reference and paired_mean:
                gap = {k: paired_mean.get(k) for k, _, _ in METRICS}
            out.append({"condition": condition_name(path), "corruption": result.get("test_corruption"),
                        "outlier_filter": result.get("outlier_filter"), "method": method,
                        "reference": reference, **{k: result["mean"][method][k] for k, _, _ in METRICS},
                        "dir_flipped": result["mean"][method].get("dir_flipped"),
                        "gap": gap})
    return out


def _cell(value: float | None, fmt: str) -> str:
    return "-" if value is None else format(value, fmt)


def _gap_cell(gap: dict | None, fmt: str) -> str:
    if gap is None:
        return "-"
    return f"{gap['difference']:+{fmt}} [{gap['low']:+{fmt}}, {gap['high']:+{fmt}}]"


def markdown(table: list[dict]) -> str:
    head = (["condition", "method"] + [label for _, label, _ in METRICS] + ["direction flipped (share)"]
            + [f"reference minus method, {label}" for _, label, _ in METRICS])
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for r in table:
        gaps = [_gap_cell(None if r["gap"] is None else r["gap"][k], f) for k, _, f in METRICS]
        cells = [r["condition"], r["method"], *(_cell(r[k], f) for k, _, f in METRICS),
                 _cell(r["dir_flipped"], ".3f"), *gaps]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="+", type=Path,
                        help="compare_variants.py --json files, one per condition")
    parser.add_argument("--markdown", type=Path, default=None)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    missing = [str(p) for p in args.inputs if not p.is_file()]
    if missing:
        parser.error(f"no such compare_variants.py --json file: {', '.join(missing)}")
    names = [condition_name(p) for p in args.inputs]
    if len(set(names)) != len(names):
        parser.error(f"two inputs have the same condition name: {names}")
    table = rows(args.inputs)
    text = markdown(table)
    print(text, end="")
    command = script_command()
    write_markdown(args.markdown, text, command)
    write_json(args.json, {"inputs": [str(p) for p in args.inputs], "rows": table}, command)


if __name__ == "__main__":
    main()
