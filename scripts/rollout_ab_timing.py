"""Interleaved A/B of scripted-opener rollout wall time per episode between a base git revision and the
working tree: two cameras, CAPT every 5 steps, the same seeds on both sides.

Each block runs the same episodes under the base revision's code (a ``git worktree`` on PYTHONPATH)
and under this tree's, in ABBA order, so drift of a shared machine's speed hits both alike. Each side
times every episode inside its process (env make and checkpoint load excluded) and reports success,
so a speed-up that changed the episodes would show. Set OMP_NUM_THREADS before calling.

    OMP_NUM_THREADS=1 .venv/bin/python scripts/rollout_ab_timing.py --base 5eabaf8 \\
        --categories cabinet_door laptop --episodes 4 --first-seed 300 --json benchmarks/rollout_ab.json
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

# Runs inside the side's code: make_env moved from agents.scripted.rollout to capt_env in this tree.
EPISODES = r"""
import json, sys, time, yaml
try:
    from capt_env.env_factory import make_env
except ImportError:
    from agents.scripted.rollout import make_env
from agents.scripted.opener import ScriptedOpener
from agents.scripted.rollout import run_episode
from perception.checkpoints import default_checkpoint
category, first, n, task_file = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
task = yaml.safe_load(open(task_file))
wrapper = {"source": "capt", "checkpoint": str(default_checkpoint(category)), "every_k_steps": 5}
env = make_env(category, wrapper, task=task, obs_mode="pointcloud")
opener = ScriptedOpener()
out = []
for seed in range(first, first + n):
    t = time.perf_counter()
    r = run_episode(env, opener, seed)
    out.append({"seed": seed, "seconds": time.perf_counter() - t, "success": r.success, "steps": r.steps})
print("EPISODES " + json.dumps(out))
"""


def run_side(tree: Path, category: str, first: int, n: int) -> list[dict]:
    """Episodes ``first..first+n-1`` of ``category`` with the code of ``tree``: seconds, success, steps."""
    task = tree / "configs" / "tasks" / "two_cameras.yaml"
    env = {**os.environ, "PYTHONPATH": str(tree)}
    with tempfile.TemporaryDirectory() as tmp:
        done = subprocess.run([sys.executable, "-c", EPISODES, category, str(first), str(n), str(task)],
                              env=env, cwd=tmp, check=True, capture_output=True, text=True)
    line = next(ln for ln in done.stdout.splitlines() if ln.startswith("EPISODES "))
    return json.loads(line[len("EPISODES "):])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument("--base", required=True, help="git revision of the A side")
    parser.add_argument("--categories", nargs="+", default=["cabinet_door"])
    parser.add_argument("--episodes", type=int, default=4, help="episodes per block and side")
    parser.add_argument("--first-seed", type=int, default=300)
    parser.add_argument("--rounds", type=int, default=1, help="ABBA blocks per category")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    results = {}
    with base_worktree(args.base) as base_tree:
        for cat in args.categories:
            blocks = abba(lambda tree, cat=cat: run_side(tree, cat, args.first_seed, args.episodes),
                          base_tree, args.rounds)
            runs = {side: [e for block in eps for e in block] for side, eps in blocks.items()}
            row = {side: {"seconds_per_episode_mean": statistics.mean(e["seconds"] for e in eps),
                          "seconds_per_step_mean": (sum(e["seconds"] for e in eps)
                                                    / sum(e["steps"] for e in eps)),
                          "success": statistics.mean(float(e["success"]) for e in eps),
                          "episodes": eps} for side, eps in runs.items()}
            row["speedup"] = row["base"]["seconds_per_episode_mean"] / row["tree"]["seconds_per_episode_mean"]
            results[cat] = row
            print(f"{cat}: base {row['base']['seconds_per_episode_mean']:.1f} s, tree "
                  f"{row['tree']['seconds_per_episode_mean']:.1f} s per episode (x{row['speedup']:.2f}); "
                  f"success {row['base']['success']:.2f} / {row['tree']['success']:.2f}", flush=True)
    write_json(args.json, {"base": args.base, "threads": os.environ.get("OMP_NUM_THREADS"),
                           "results": results}, script_command())


if __name__ == "__main__":
    main()
