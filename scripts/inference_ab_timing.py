"""Interleaved A/B of CAPT inference between a base git revision and the working tree: speed and metrics.

For each category, ``capt evaluate`` scores the shipped checkpoint on the same test clouds under the
base revision's code (a ``git worktree`` on PYTHONPATH) and under this tree's, in ABBA order, so drift
of a shared machine's speed hits both alike. Reports the median ms per cloud of each run and whether
every metric of Table I is equal to the printed digits (the ``capt evaluate`` table less its ms
column). Both sides run with the same environment (set OMP_NUM_THREADS before calling).

    OMP_NUM_THREADS=1 .venv/bin/python scripts/inference_ab_timing.py --base 98e1963 \\
        --data /tmp/capt_data --json benchmarks/inference_ab_session47.json
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from revision_ab import abba, base_worktree

from capt_common.json_report import script_command, write_json

CATEGORIES = ["laptop", "oven", "washing_machine", "eyeglasses", "drawer_cabinet", "cabinet_door"]


def evaluate(tree: Path, category: str, data: Path, timing_clouds: int) -> dict:
    """``capt evaluate`` of the shipped ``category`` checkpoint with the code of ``tree``."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "eval.json"
        env = {**os.environ, "PYTHONPATH": str(tree)}
        code = ("import sys; from capt_env.cli import main; sys.exit(main(sys.argv[1:]))")
        ckpt = tree / "perception" / "checkpoints" / f"{category}.pt"
        subprocess.run([sys.executable, "-c", code, "evaluate", str(ckpt), "--data", str(data / category),
                        "--timing-clouds", str(timing_clouds), "--json", str(out)],
                       env=env, cwd=tmp, check=True, capture_output=True)
        result = json.loads(out.read_text())
    table = [row.rsplit("|", 2)[0] for row in result["table_markdown"].splitlines()]  # less ms/input
    return {"ms": result["median_ms_per_input"]["capt"], "table": table}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument("--base", default="HEAD", help="git revision of the A side")
    parser.add_argument("--data", type=Path, required=True, help="holds <category>/ test splits")
    parser.add_argument("--categories", nargs="+", default=CATEGORIES)
    parser.add_argument("--rounds", type=int, default=2, help="ABBA blocks per category")
    parser.add_argument("--timing-clouds", type=int, default=200, help="timed calls per evaluate run")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    results = {}
    with base_worktree(args.base) as base_tree:
        for cat in args.categories:
            runs = abba(lambda tree, cat=cat: evaluate(tree, cat, args.data, args.timing_clouds), base_tree,
                        args.rounds)
            same = all(r["table"] == runs["base"][0]["table"] for side in runs.values() for r in side)
            row = {side: statistics.median(r["ms"] for r in rs) for side, rs in runs.items()}
            row.update(metrics_equal=same, table=runs["tree"][0]["table"],
                       ms_runs={side: [r["ms"] for r in rs] for side, rs in runs.items()})
            if not same:
                row["base_table"] = runs["base"][0]["table"]
            results[cat] = row
            print(f"{cat}: base {row['base']:.1f} ms, tree {row['tree']:.1f} ms per cloud "
                  f"(x{row['base'] / row['tree']:.2f}); metrics equal to printed digits: {same}", flush=True)
    write_json(args.json, {"base": args.base, "threads": os.environ.get("OMP_NUM_THREADS"),
                           "results": results}, script_command())


if __name__ == "__main__":
    main()
