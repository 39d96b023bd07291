"""How far the resting-arm rule moves objects: the first 50 resets from seed 10000 of a category, or
the first 10 of each object of an objects YAML; two cameras, state observations.

    python measure_moves.py CATEGORY | OBJECTS_YAML
"""

import sys

import numpy as np
import yaml

import capt_env.shipped_configs as sc
import capt_env.tasks.open_articulated as task_module
from capt_env.commands.object_targets import load_objects_yaml, target_task
from capt_env.env_factory import make_env

MOVES: list[float] = []
_measure = task_module.clear_of_resting_arm


def _recorded(*args):  # the rule, recording each reset's move (m)
    moved = _measure(*args)
    MOVES.append(float(moved[0]))
    return moved


def report(label: str, env, resets: int) -> None:
    MOVES.clear()
    for seed in range(10000, 10000 + resets):
        env.reset(seed=seed)
    moved = [m for m in MOVES[-resets:] if m > 0]
    median = float(np.median(moved)) if moved else 0.0
    print(f"{label}: {len(moved)} of {resets} resets moved, median {median:.3f} m, "
          f"max {max(MOVES[-resets:]):.3f} m")


def main() -> None:
    task_module.clear_of_resting_arm = _recorded
    task = yaml.safe_load(open(sc.resolve_config("tasks", "two_cameras")))
    what = sys.argv[1]
    if what.endswith(".yaml"):
        for target in load_objects_yaml(what):
            env = make_env(None, {"source": "oracle"}, task=target_task(target, task), obs_mode="state")
            report(target.label, env, 10)
            env.close()
    else:
        report(what, make_env(what, {"source": "oracle"}, task=task, obs_mode="state"), 50)


if __name__ == "__main__":
    main()
