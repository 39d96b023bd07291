"""Markdown of a refiner ablation: ``capt estimate-errors --without-refiner all --json`` results, one
table per object, each row's change against the full ``capt`` row, and how often each refiner fired.

    .venv/bin/python scripts/refiner_ablation_table.py benchmarks/refiner_ablation_procedural.json \\
        --out benchmarks/refiner_ablation_procedural.md

Units: direction in degrees between signed axes, line (distance between the estimated and true axis
lines, hinges only) and grasp point in centimetres, state in degrees (hinges) or centimetres
(slides). "fired" is the share of resets at which the left-out refiner changed the full pipeline's
estimate.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def _cm(v: float | None) -> str:
    return "-" if v is None else f"{100 * v:.1f}"


def _state(row: dict[str, Any]) -> float:
    v = row["state_error_mean"]
    return v * 57.29577951308232 if row["joint_type"] == "revolute" else 100 * v


def _delta(v: float | None, ref: float | None, scale: float = 1.0) -> str:
    if v is None or ref is None:
        return ""
    d = scale * (v - ref)
    return "" if abs(d) < 0.05 else f" ({d:+.1f})"


def object_table(rows: list[dict[str, Any]]) -> list[str]:
    """The Markdown lines of one object's rows (capt_raw, capt, capt without each refiner)."""
    full = next(r for r in rows if r["perception"] == "capt" and r["without_refiner"] is None)
    fired: dict[str, float] = {}
    for reset in full["per_reset"]:
        for name in reset["fired"]:
            fired[name] = fired.get(name, 0.0) + 1.0 / len(full["per_reset"])
    unit = "deg" if full["joint_type"] == "revolute" else "cm"
    lines = [f"| source | refiners | fired | direction (deg, mean) | direction (deg, median) | sign right | "
             f"line (cm, mean) | line (cm, median) | state ({unit}, mean) | grasp point (cm, mean) |",
             "|" + " --- |" * 10]
    for r in rows:
        left_out = r["without_refiner"]
        share = "-" if left_out is None else f"{fired.get(left_out, 0.0):.2f}"
        lines.append(
            f"| {r['perception']} | {r['refiners']} | {share} | "
            f"{r['direction_deg_mean']:.1f}{_delta(r['direction_deg_mean'], full['direction_deg_mean'])} | "
            f"{r['direction_deg_median']:.1f} | {r['sign_right']:.2f} | "
            f"{_cm(r['line_m_mean'])}{_delta(r['line_m_mean'], full['line_m_mean'], 100)} | "
            f"{_cm(r['line_m_median'])} | {_state(r):.1f} | "
            f"{100 * r['grasp_m_mean']:.1f}{_delta(r['grasp_m_mean'], full['grasp_m_mean'], 100)} |")
    return lines


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("json", nargs="+", help="capt estimate-errors --json files")
    parser.add_argument("--out", required=True, help="Markdown file to write")
    args = parser.parse_args(argv)
    text = []
    for path in args.json:
        data = json.loads(Path(path).read_text())
        text.append(f"`{data['command']}` (`{path}`), seeds "
                    f"{data['seeds'][0]}-{data['seeds'][-1]}. In brackets: the change against `capt` "
                    "with every refiner.\n")
        objects = list(dict.fromkeys(r["object"] for r in data["results"]))
        for obj in objects:
            rows = [r for r in data["results"] if r["object"] == obj]
            text += [f"### {obj}", "", *object_table(rows), ""]
    Path(args.out).write_text("\n".join(text) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
