"""Add each sample's ``instance_id`` to a `capt evaluate --json` file written before evaluate recorded it.

`capt evaluate` scores every checkpoint on the clouds of one split in the dataset's order, so the i-th
sample of each method is the split's i-th cloud. This reads that split's instance ids (and categories,
as a check) from the dataset the file was scored on and writes them into the samples, so that
``scripts/compare_variants.py --resample instances`` can draw whole instances. Refuses a file whose
methods scored another number of clouds than the split holds (e.g. ``--max-samples``), or whose
categories do not match the split's, and a sample that already has a different id.

    .venv/bin/python scripts/attach_instance_ids.py benchmarks/perception_laptop.json \
        --data data/laptop --out /tmp/perception_laptop_ids.json
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from capt_common.json_report import script_command, write_json
from perception.data import load_split


def attach(run: dict, instance_ids: list[int], categories: list[str]) -> dict:
    """A copy of ``run`` whose samples carry the instance id of the cloud they scored."""
    scored: dict[str, int] = {}
    samples_out = []
    for sample in run.get("samples", []):
        method = sample["method"]
        i = scored.get(method, 0)
        scored[method] = i + 1
        if i >= len(instance_ids):
            continue  # reported below with the method's count
        if sample["category"] != categories[i]:
            raise ValueError(f"{method} sample {i} is a {sample['category']}, "
                             f"the split's cloud {i} a {categories[i]}")
        if sample.get("instance_id") not in (None, instance_ids[i]):
            raise ValueError(f"{method} sample {i} already has instance_id {sample['instance_id']}, "
                             f"the split's cloud {i} shows {instance_ids[i]}")
        samples_out.append({**sample, "instance_id": instance_ids[i]})
    if not scored:
        raise ValueError("the file holds no per-sample results")
    for method, count in scored.items():
        if count != len(instance_ids):
            raise ValueError(f"{method} scored {count} clouds, the split holds {len(instance_ids)}")
    return {**run, "samples": samples_out}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input", type=Path, help="capt evaluate --json file")
    parser.add_argument("--data", type=Path, required=True, help="the dataset directory it was scored on")
    parser.add_argument("--out", type=Path, default=None, help="where to write (default: in place)")
    args = parser.parse_args()
    if not args.input.is_file():
        parser.error(f"no such capt evaluate --json file: {args.input}")
    run = json.loads(args.input.read_text())
    split = run.get("split", "test")
    try:
        arrays = load_split(args.data, split)
        result = attach(run, [int(x) for x in arrays["instance_id"]], [str(c) for c in arrays["category"]])
    except (ValueError, FileNotFoundError) as err:
        parser.error(f"{args.input}: {err}")
    out = args.out or args.input
    # keeps the evaluation's own command and machine (those of this script if the file had none)
    write_json(out, result, result.get("command") or script_command())
    ids = sorted({s["instance_id"] for s in result["samples"]})
    print(f"{len(result['samples'])} samples, {len(ids)} instances of the {split} split")


if __name__ == "__main__":
    main()
