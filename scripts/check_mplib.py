"""Check whether mplib can plan for ManiSkill's Panda in this Python environment, and how fast.

Builds ``mplib.Planner`` from ManiSkill's ``panda_v2.urdf`` / ``.srdf`` (move group
``panda_hand_tcp``), then plans with RRTConnect from the task's rest pose to a TCP pose 7 cm in front
of a 28 x 60 x 50 cm box of 20,000 points (base frame, metres), without and with the cloud as an
obstacle, and once with the screw planner. Prints one JSON object (versions, timings in seconds,
each plan's status and waypoint count). Under numpy 2 mplib 0.1.1 crashes while building the
planner (a segmentation fault: exit status 139, no output); see docs/scripted_opener.md.

    python scripts/check_mplib.py [--json PATH]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

REST_QPOS = np.array([0.0, 0.39, 0.0, -1.95, 0.0, 2.32, 0.8, 0.04, 0.04])
"""rad (7 arm joints) and m (2 fingers): about the Panda's rest pose in the task."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", type=Path, default=None, help="also write the result here")
    args = parser.parse_args()

    import mani_skill
    import mplib

    robot = Path(mani_skill.__file__).parent / "assets" / "robots" / "panda"
    start = time.perf_counter()
    planner = mplib.Planner(urdf=str(robot / "panda_v2.urdf"), srdf=str(robot / "panda_v2.srdf"),
                            move_group="panda_hand_tcp")
    result: dict = {"numpy": np.__version__, "mplib": mplib.__version__,
                    "load_s": round(time.perf_counter() - start, 4)}
    rng = np.random.default_rng(0)
    box = np.column_stack([rng.uniform(0.62, 0.9, 20000), rng.uniform(-0.3, 0.3, 20000),
                           rng.uniform(0.0, 0.5, 20000)])
    planner.update_point_cloud(box, radius=0.01)
    c = float(np.cos(np.pi / 4))
    goal = np.array([0.55, 0.15, 0.25, c, 0.0, c, 0.0])  # TCP approach along +x (wxyz)
    for use_cloud in (False, True):
        start = time.perf_counter()
        plan = planner.plan_qpos_to_pose(goal, REST_QPOS, time_step=1 / 20, use_point_cloud=use_cloud,
                                         planning_time=2.0)
        result[f"rrt_{'cloud' if use_cloud else 'free'}"] = {
            "status": plan["status"], "s": round(time.perf_counter() - start, 4),
            "waypoints": int(len(plan["position"])) if plan["status"] == "Success" else 0}
    start = time.perf_counter()
    plan = planner.plan_screw(goal, REST_QPOS, time_step=1 / 20, use_point_cloud=True)
    result["screw_cloud"] = {"status": plan["status"], "s": round(time.perf_counter() - start, 4)}
    text = json.dumps(result, indent=1)
    print(text)
    if args.json is not None:
        args.json.write_text(text + "\n")


if __name__ == "__main__":
    main()
