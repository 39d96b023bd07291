"""Gradient alignment of the state loss with the other CAPT loss terms, per checkpoint.

For each checkpoint (with its dataset), the first ``--batches`` batches of a split (validation by
default, un-augmented, as ``capt train`` validates) are scored in eval mode, and each weighted term's
gradient on the shared weights is compared with the state term's (``perception/gradient_alignment.py``
says what is measured and why). The motion term uses ``--motion-weight`` (the paper's 0.1) on every
checkpoint, also on CAPT-plain ones that trained without it.

    .venv/bin/python scripts/loss_gradient_alignment.py \
        --checkpoint perception/checkpoints/laptop.pt --data data/laptop \
        --checkpoint perception/checkpoints/washing_machine.pt --data data/washing_machine \
        --markdown benchmarks/gradient_alignment.md --json benchmarks/gradient_alignment.json
"""

from __future__ import annotations

import argparse
import math
from dataclasses import asdict
from pathlib import Path

import torch
from torch.utils.data import DataLoader
from tqdm import tqdm

from capt_common.json_report import script_command, write_json, write_markdown
from perception.checkpoint import CheckpointError, build_model, load_checkpoint
from perception.data import CaptShardDataset
from perception.gradient_alignment import LOSS_TERMS, PARAMETER_GROUPS, alignments, term_gradients

REFERENCE = "state"
OTHERS = tuple(t for t in LOSS_TERMS if t != REFERENCE)


def measure(checkpoint: Path, data: Path, split: str, batches: int, batch_size: int,
            motion_weight: float) -> dict:
    """Alignment rows of one checkpoint on the first ``batches`` batches of ``data``'s ``split``."""
    ckpt = load_checkpoint(checkpoint)
    model = build_model(ckpt)
    dataset = CaptShardDataset(data, split, ckpt.config.model, augment=False)
    if len(dataset) == 0:
        raise SystemExit(f"error: {data} has no {split} samples")
    loader = DataLoader(dataset, batch_size=batch_size, shuffle=False)
    per_batch = []
    for i, batch in enumerate(tqdm(loader, total=min(batches, len(loader)), desc=checkpoint.name)):
        if i >= batches:
            break
        per_batch.append(term_gradients(model, batch, ckpt.config, LOSS_TERMS, motion_weight))
    rows = alignments(per_batch, REFERENCE, OTHERS, PARAMETER_GROUPS)
    return {"checkpoint": str(checkpoint), "data": str(data), "category": ckpt.category,
            "variant": ckpt.config.model.variant, "rows": [asdict(r) for r in rows]}


def _fmt(value: float, spec: str) -> str:
    """``value`` formatted, or "-" where it is undefined (a term that does not reach the group)."""
    return "-" if math.isnan(value) else format(value, spec)


def markdown(results: list[dict], group: str) -> str:
    """One line per checkpoint and term on ``group``."""
    lines = [f"State term against each other term, parameter group `{group}` "
             "(mean per-batch cosine, share of batches below 0, cosine of the summed gradients, "
             "norm ratio |g_term| / |g_state|):", "",
             "| checkpoint | variant | term | mean cos | cos < 0 | summed cos | norm ratio |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        for row in r["rows"]:
            if row["group"] != group:
                continue
            lines.append(f"| {r['checkpoint']} | {r['variant']} | {row['other']} | "
                         f"{_fmt(row['mean_cosine'], '+.3f')} | {_fmt(row['negative_share'], '.2f')} | "
                         f"{_fmt(row['summed_cosine'], '+.3f')} | {row['norm_ratio']:.3f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--checkpoint", type=Path, action="append", required=True,
                        help="a checkpoint; give one --data for each, in the same order")
    parser.add_argument("--data", type=Path, action="append", required=True)
    parser.add_argument("--split", default="val")
    parser.add_argument("--batches", type=int, default=25, help="batches per checkpoint (default 25)")
    parser.add_argument("--batch-size", type=int, default=8, help="as capt train (default 8)")
    parser.add_argument("--motion-weight", type=float, default=0.1,
                        help="W_motion (default 0.1, the paper's)")
    parser.add_argument("--threads", type=int, default=None, help="torch threads (default: torch's)")
    parser.add_argument("--markdown", type=Path)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    if len(args.checkpoint) != len(args.data):
        parser.error(f"{len(args.checkpoint)} --checkpoint but {len(args.data)} --data: "
                     "give one --data each")
    if args.batches < 1 or args.batch_size < 1:
        parser.error("--batches and --batch-size must be at least 1")
    if args.motion_weight <= 0:
        parser.error("--motion-weight must be positive")
    if args.threads:
        torch.set_num_threads(args.threads)
    torch.manual_seed(0)
    results = []
    for ckpt, data in zip(args.checkpoint, args.data, strict=True):
        try:
            results.append(measure(ckpt, data, args.split, args.batches, args.batch_size, args.motion_weight))
        except (CheckpointError, FileNotFoundError) as exc:
            raise SystemExit(f"error: {exc}") from None
    command = script_command()
    text = "\n".join(markdown(results, g) for g in ("shared", "articulation_shared"))
    print(text)
    write_markdown(args.markdown, text, command)
    write_json(args.json, {"split": args.split, "batches": args.batches, "batch_size": args.batch_size,
                           "motion_weight": args.motion_weight, "results": results}, command)


if __name__ == "__main__":
    main()
