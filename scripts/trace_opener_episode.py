"""Trace one scripted-opener episode step by step: phase, TCP, finger gap, the estimate and the part's
true state, and the estimate's errors against the truth (direction in degrees, axis line and grasp
point in cm), for finding which situation an opening fails in (development seeds only).

    python scripts/trace_opener_episode.py --objects data/real_objects/corpus.yaml --name mw_window \
        --seed 100 --every 5 --json /tmp/trace.json

Prints one line every ``--every`` steps and at each phase change; ``--json`` keeps every step. Each
step also records which bodies touch the moving part (``contacts``: the simulator's contacts with a
non-zero impulse), which tells a hand that slipped from one pushed off by its own palm or arm.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from agents.scripted import ScriptedOpener
from agents.scripted.geometry import quat_to_matrix
from capt_env.commands.estimate_errors import estimate_errors
from capt_env.commands.object_targets import load_objects_yaml, target_task
from capt_env.commands.rollout import opener_config
from capt_env.commands.task_overrides import task_overrides
from capt_env.env_factory import make_env
from capt_env.wrappers.joint_observation import decode_observation
from capt_env.wrappers.perception_sources import ground_truth_estimate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="data/real_objects/corpus.yaml")
    parser.add_argument("--name", required=True, help="the object's label in --objects, or a category")
    parser.add_argument("--seed", type=int, default=100)
    parser.add_argument("--task", default="two_cameras")
    parser.add_argument("--max-steps", type=int, default=200)
    parser.add_argument("--every", type=int, default=5)
    parser.add_argument("--json", default=None)
    parser.add_argument("--perception", default="oracle", choices=["oracle", "capt", "capt_raw"],
                        help="perception source; capt/capt_raw use the object's shipped model (`like`)")
    parser.add_argument("--every-k-steps", type=int, default=5, help="perception every k control steps")
    parser.add_argument("--opener", default=None, help="YAML of ScriptedOpenerConfig overrides")
    args = parser.parse_args()
    if args.seed >= 10000:
        raise SystemExit("seeds from 10000 are held out for reporting; trace development seeds")
    task = task_overrides(args.task)
    targets = {t.label: t for t in load_objects_yaml(args.objects)}
    wrapper: dict = {"source": args.perception, "every_k_steps": args.every_k_steps}
    target = targets.get(args.name)
    if args.perception != "oracle":
        from perception.checkpoints import default_checkpoint

        wrapper["checkpoint"] = str(default_checkpoint(target.model_category() if target else args.name))
    obs_mode = "state" if args.perception == "oracle" else "pointcloud"
    if target is not None:
        env = make_env(None, wrapper, task=target_task(target, task), obs_mode=obs_mode)
    else:
        env = make_env(args.name, wrapper, task=task, obs_mode=obs_mode)
    opener = ScriptedOpener(opener_config(args.opener))
    obs, info = env.reset(seed=args.seed)
    opener.reset()
    steps, last_phase = [], None
    for step in range(1, args.max_steps + 1):
        proprio, est = decode_observation(obs)
        qpos = np.asarray(proprio["qpos"], dtype=np.float64).reshape(-1)
        tcp = np.asarray(proprio["tcp_pose"], dtype=np.float64)
        action = opener.act(obs, info)
        err = estimate_errors(est, ground_truth_estimate(info))
        if step == 1:
            approach = opener.ctx.grasp.target_r[:, 2] if opener.ctx.grasp.target_r is not None else None
            print(f"joint {est.joint_type} axis {np.round(est.direction, 3)} pivot {np.round(est.pivot, 3)} "
                  f"grasp {np.round(est.grasp_point, 3)} approach {np.round(approach, 3)} "
                  f"closing {np.round(opener.ctx.grasp.target_r[:, 1], 3)} base {opener.ctx.base} "
                  f"tcp {np.round(tcp[:3], 3)}")
            print("rehearsals (nearer, other):", opener.rehearsals)
        obs, _, _, truncated, info = env.step(action)
        row = {"step": step, "phase": opener.phase.value, "tcp": tcp[:3].round(4).tolist(),
               "gap": round(float(qpos[7] + qpos[8]), 4),
               "pull_pivot": (None if opener.ctx.pull.grasp_pivot is None else np.round(
                   opener.ctx.pull.hinge_fit if opener.ctx.pull.hinge_fit is not None
                   else opener.ctx.pull.grasp_pivot, 4).tolist()),
               "arc_fitted": opener.ctx.pull.hinge_fit is not None,
               "fingers": [round(float(qpos[7]), 4), round(float(qpos[8]), 4)],
               "handle_in_hand": np.round(quat_to_matrix(tcp[3:7]).T
                                          @ (ground_truth_estimate(info).grasp_point - tcp[:3]), 4).tolist(),
               "state": round(float(est.state), 4),
               "grasp": np.round(est.grasp_point, 4).tolist(),
               "open_fraction": round(float(info["open_fraction"]), 3), "success": bool(info["success"]),
               "action": np.round(action, 2).tolist(),
               "approach": np.round(quat_to_matrix(tcp[3:7])[:, 2], 3).tolist(),
               "closing": np.round(quat_to_matrix(tcp[3:7])[:, 1], 3).tolist(),
               "arm": np.round(qpos[:7], 2).tolist(),
               "error": {"direction_deg": round(err["direction_deg"], 1),
                         "line_cm": None if err["line_m"] is None else round(100 * err["line_m"], 1),
                         "grasp_cm": round(100 * err["grasp_m"], 1)}}
        row["contacts"] = part_contacts(env)
        steps.append(row)
        if opener.phase.value != last_phase or step % args.every == 0:
            print(f"{step:4d} {row['phase']:9s} tcp {row['tcp']} gap {row['gap']:.4f} "
                  f"state {row['state']:+.3f} open {row['open_fraction']:.2f} ok {int(row['success'])} "
                  f"grasp {row['grasp']} err {row['error']} "
                  f"act {row['action']} appr {row['approach']} clos {row['closing']} arm {row['arm']} "
                  f"touching {row['contacts']}")
            if opener.phase.value == "approach" and last_phase != "approach":
                print("     rehearsals (nearer, other):", opener.rehearsals)
            last_phase = opener.phase.value
        if truncated:
            break
    print("success", bool(info["success"]), "log", opener.phase_log)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"steps": steps, "phase_log": opener.phase_log}, fh)
    env.close()


def part_contacts(env) -> list[str]:
    """Names of the bodies touching the target joint's moving link now (sub-scene 0), sorted."""
    base = env.unwrapped
    part = base.object.joints[base.object.target_joint].child_link.name
    touching = set()
    for contact in base.scene.get_contacts():
        a, b = (body.entity.name for body in contact.bodies)
        if part in (a, b) and any(np.linalg.norm(point.impulse) > 1e-4 for point in contact.points):
            touching.add(b if a == part else a)
    return sorted(touching)


if __name__ == "__main__":
    main()
