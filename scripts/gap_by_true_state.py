"""The gap between two methods' errors, split by the true joint state of the test clouds.

`capt evaluate` scores every checkpoint on the clouds of one split in the dataset's order, so the
i-th sample of a method is the split's i-th cloud, whose true state this reads from the dataset
(joint ``--joint``, degrees for a revolute joint, metres for a prismatic one). Each cloud goes into
the bin ``[edge_k, edge_k+1)`` of ``--edges`` (in those units; a cloud outside every bin is left
out), and per bin the paired gap reference minus method is bootstrapped as in
`scripts/compare_variants.py` (`perception/paired_comparison.py`): several files that score the
same method are training runs, averaged per cloud; ``--resample instances`` draws test instances.
The bins are chosen after looking, so read an interval that excludes 0 in one of several bins as a
lead, not a finding.

    .venv/bin/python scripts/gap_by_true_state.py \
        benchmarks/perception_washing_machine_voting_ablation_seed{0,1,2}.json \
        --data data/washing_machine --reference capt_without_dv --methods capt_without_dv capt_plain \
        --edges 0 25 45 70 105 --markdown benchmarks/state_gap_by_true_state_washing_machine.md
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path

import numpy as np

from capt_common.json_report import script_command, write_json, write_markdown
from perception.data import load_split
from perception.paired_comparison import METRICS, RESAMPLE_UNITS, paired_differences

REVOLUTE = 0


def bin_label(low: float, high: float, unit: str) -> str:
    """The name a bin's rows carry, e.g. ``true state 25-45 deg``."""
    return f"true state {low:g}-{high:g} {unit}"


def binned_samples(runs: Sequence[dict], true_states: np.ndarray, instance_ids: np.ndarray,
                   edges: Sequence[float], unit: str, methods: Sequence[str] | None) -> list[dict]:
    """The per-sample dicts of ``runs`` (``capt evaluate --json`` payloads) with ``category`` replaced
    by the bin of their cloud's true state and ``run`` set to the file's index. Raises ValueError when a
    method scored another number of clouds than ``true_states`` holds or an instance id disagrees."""
    if len(edges) < 2 or any(b <= a for a, b in zip(edges, edges[1:], strict=False)):
        raise ValueError(f"edges must be at least two increasing values, got {list(edges)}")
    out = []
    for index, run in enumerate(runs):
        counts: dict[str, int] = {}
        for sample in run.get("samples", []):
            method = sample["method"]
            if methods is not None and method not in methods:
                continue
            i = counts.get(method, 0)
            counts[method] = i + 1
            if i >= len(true_states):
                continue  # reported below
            if sample.get("instance_id") not in (None, int(instance_ids[i])):
                raise ValueError(f"run {index} {method} sample {i} is instance {sample['instance_id']}, "
                                 f"the split's cloud {i} instance {int(instance_ids[i])}: another dataset?")
            k = int(np.searchsorted(edges, true_states[i], side="right")) - 1
            if 0 <= k < len(edges) - 1:
                out.append({**sample, "category": bin_label(edges[k], edges[k + 1], unit), "run": index})
        wrong = {m: n for m, n in counts.items() if n != len(true_states)}
        if wrong:
            raise ValueError(f"run {index}: methods scored {wrong} clouds, "
                             f"the split holds {len(true_states)}")
    if not out:
        raise ValueError("no sample falls in any bin (check --edges, --methods)")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", type=Path, nargs="+", help="capt evaluate --json files of one category")
    parser.add_argument("--data", type=Path, required=True, help="the dataset the files were scored on")
    parser.add_argument("--split", default="test")
    parser.add_argument("--joint", type=int, default=0, help="joint slot whose true state bins the clouds")
    parser.add_argument("--edges", type=float, nargs="+", required=True,
                        help="bin edges, degrees (revolute) or metres (prismatic)")
    parser.add_argument("--reference", default="capt")
    parser.add_argument("--methods", nargs="+", default=None, help="read only these methods")
    parser.add_argument("--draws", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--resample", choices=RESAMPLE_UNITS, default="clouds")
    parser.add_argument("--markdown", type=Path)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    split = load_split(args.data, args.split)
    if not 0 <= args.joint < split["joint_states"].shape[1]:
        parser.error(f"--joint {args.joint}: the data has {split['joint_states'].shape[1]} joint slots")
    if not split["joint_mask"][:, args.joint].all():
        parser.error(f"joint {args.joint} is absent in some clouds of {args.data}")
    revolute = bool((split["joint_types"][:, args.joint] == REVOLUTE).all())
    states = split["joint_states"][:, args.joint]
    unit = "deg" if revolute else "m"
    true_states = np.degrees(states) if revolute else states
    try:
        samples = binned_samples([json.loads(p.read_text()) for p in args.inputs], true_states,
                                 split["instance_id"], args.edges, unit, args.methods)
        gaps = paired_differences(samples, args.reference, args.draws, args.seed, args.resample)
    except ValueError as exc:
        raise SystemExit(f"error: {exc}") from None
    bins = [bin_label(a, b, unit) for a, b in zip(args.edges, args.edges[1:], strict=False)]
    counts = {b: sum(1 for s in samples if s["category"] == b and s["method"] == args.reference
                     and s["run"] == 0) for b in bins}
    metrics = [m for m in METRICS if not (m == "pos_aed" and not revolute)
               and m != ("state_m" if revolute else "state_deg")]
    unit_word = "instances" if args.resample == "instances" else "clouds"
    lines = [f"{args.reference} minus each method per bin of the true state of joint {args.joint}, "
             f"95% paired bootstrap over the test {unit_word} ({args.draws} draws, seed {args.seed}; "
             f"{len(args.inputs)} file(s), runs of a method averaged per cloud):", "",
             "| bin | clouds | method | " + " | ".join(metrics) + " |", "|" + " --- |" * (len(metrics) + 3)]
    for other, rows in gaps.items():
        for b in bins:
            if b not in rows:
                continue
            cells = []
            for m in metrics:
                d = rows[b][m]
                cells.append("-" if d is None or math.isnan(d.difference)
                             else f"{d.difference:+.3g} [{d.low:+.3g}, {d.high:+.3g}]")
            lines.append(f"| {b} | {counts[b]} | {args.reference} - {other} | " + " | ".join(cells) + " |")
    text = "\n".join(lines) + "\n"
    print(text)
    command = script_command()
    write_markdown(args.markdown, text, command)
    write_json(args.json, {
        "inputs": [str(p) for p in args.inputs], "reference": args.reference, "edges": args.edges,
        "unit": unit, "counts": counts, "resample": args.resample, "draws": args.draws, "seed": args.seed,
        "gaps": {o: {b: {m: None if d is None else asdict(d) for m, d in r.items()}
                     for b, r in rows.items() if b != "mean"} for o, rows in gaps.items()}}, command)


if __name__ == "__main__":
    main()
