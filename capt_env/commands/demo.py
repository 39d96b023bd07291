"""``capt demo``, the main job: unseen objects -> depth cloud -> CAPT estimate -> open them.

For each episode (test-split instances, fixed seeds): render the object, isolate its points, estimate
the joints with the shipped CAPT checkpoint, print the axis errors against the simulator's ground
truth, save a PNG of the cloud coloured by predicted part with predicted (red) and true (green) axes,
then run the scripted opening policy on CAPT's estimates and save an MP4 of the episode.

Only the categories the opener is measured on (``OPENED_CATEGORIES``, as in ``capt rollout``'s
benchmarks) are opened; eyeglasses are estimated only: the scripted opener was never built or
measured for unfolding a temple a few millimetres thick, and failed it on every recorded demo run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from capt_common.json_report import write_json
from capt_env.commands.object_targets import add_object_arguments, object_targets, target_task
from capt_env.commands.task_overrides import add_task_argument, task_overrides

OPENED_CATEGORIES = ("laptop", "oven", "washing_machine", "drawer_cabinet", "cabinet_door", "sliding_panel")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--categories", nargs="*", default=None,
                        help="object categories (default: every category with a shipped checkpoint, or "
                             "none when user files are given)")
    parser.add_argument("--checkpoint", default=None, help="CAPT checkpoint (default: the shipped one)")
    parser.add_argument("--episodes", type=int, default=1, help="episodes per category")
    parser.add_argument("--first-seed", type=int, default=0, help="episodes use seeds first..first+n-1")
    parser.add_argument("--out", default="outputs/demo", help="where PNGs and MP4s go")
    parser.add_argument("--no-policy", action="store_true", help="only estimate; do not open the object")
    parser.add_argument("--no-video", action="store_true", help="run the policy without recording MP4s")
    add_task_argument(parser)
    add_object_arguments(parser, None, with_categories=False)


def axis_errors(est_joint, info: dict) -> dict[str, float | None]:
    """Direction error (deg), axis-line distance (m, revolute only) and state error (deg or m)."""
    from perception.metrics import direction_error_deg, line_distance

    k = est_joint.joint_index
    u = np.asarray(info["joint_axis"][k], np.float64)
    q = np.asarray(info["joint_pivot"][k], np.float64)
    revolute = est_joint.type == "revolute"
    state_err = abs(float(est_joint.state) - float(info["joint_state"][k]))
    return {
        "direction_deg": direction_error_deg(est_joint.direction, u),
        "position_m": line_distance(est_joint.direction, est_joint.pivot, u, q) if revolute else None,
        "state": float(np.degrees(state_err)) if revolute else state_err,
        "state_unit": "deg" if revolute else "m",
    }


def estimate_episode(env, estimator, seed: int, out_dir: Path, tag: str) -> dict:
    """Reset, estimate from the segmented object cloud, save the PNG; return the errors."""
    from perception.figures import plot_cloud_with_axes

    obs, info = env.reset(seed=seed)
    pc = obs["pointcloud"]
    mask = pc["part_label"] >= 0
    cloud = pc["xyzw"][mask, :3].astype(np.float64)
    est = estimator.predict(cloud)
    k = int(info["target_joint"])
    joint = next(j for j in est.joints if j.joint_index == k)
    errors = axis_errors(joint, info)
    true_axes = [(info["joint_axis"][i], info["joint_pivot"][i]) for i in range(len(info["joint_type"]))]
    png = plot_cloud_with_axes(out_dir / f"{tag}.png", cloud, est.part_labels,
                               [(j.direction, j.pivot) for j in est.joints], true_axes,
                               title=f"{tag}: direction error {errors['direction_deg']:.1f} deg")
    return {"instance_id": int(env.unwrapped.object.instance_id), "seed": seed, "points": int(len(cloud)),
            "latency_ms": est.latency_ms, "confidence": joint.confidence, "png": str(png), **errors}


def run(args: argparse.Namespace) -> int:
    import gymnasium as gym

    import capt_env
    from perception.checkpoints import default_checkpoint, shipped_categories
    from perception.inference import ArticulationEstimator

    files = bool(args.object or args.objects)
    if args.categories is None:
        args.categories = [] if files else shipped_categories()
    if not args.categories and not files:
        raise SystemExit("no shipped checkpoint found; pass --categories and --checkpoint")
    out_dir = Path(args.out)
    overrides = {"cameras": [{"width": 160, "height": 160}], **task_overrides(args.task)}
    report = []
    for target in object_targets(args):
        category = target.category
        ckpt = args.checkpoint or default_checkpoint(target.model_category())
        estimator = ArticulationEstimator.from_checkpoint(ckpt)
        task = target_task(target, overrides)
        if category is None:
            env = gym.make(capt_env.registration.GENERIC_ID, obs_mode="pointcloud", task=task)
        else:
            env = gym.make(capt_env.env_id(category), obs_mode="pointcloud", task={"split": "test", **task})
        try:
            for ep in range(args.episodes):
                tag = f"{target.label}_episode{ep}"
                row = {"object": target.label, "category": category,
                       **estimate_episode(env, estimator, args.first_seed + ep, out_dir, tag)}
                if not args.no_policy and (category is None or category in OPENED_CATEGORIES):
                    from capt_env.commands.demo_policy import open_with_capt

                    row.update(open_with_capt(category, ckpt, args.first_seed + ep, out_dir, tag,
                                              video=not args.no_video, task=task))
                elif not args.no_policy:
                    row["not_opened"] = "estimate only: the scripted opener is not built for this category"
                report.append(row)
                pos = "-" if row["position_m"] is None else f"{100 * row['position_m']:.1f} cm"
                opened = ""
                if "not_opened" in row:
                    opened = f"  ({row['not_opened']})"
                elif "success" in row:
                    outcome = "SUCCESS" if row["success"] else "failed"
                    opened = f"  opened {row['open_fraction']:.0%} -> {outcome}"
                what = "user file" if category is None else f"instance {row['instance_id']}, unseen"
                print(f"{tag} ({what}): axis direction error "
                      f"{row['direction_deg']:.1f} deg, position {pos}, state {row['state']:.2f} "
                      f"{row['state_unit']}, {row['latency_ms']:.0f} ms{opened}")
        finally:
            env.close()
    print(f"pictures and videos in {out_dir}/")
    write_json(args.json, {"episodes": report})
    return 0
