"""``capt estimate-errors``: how far the wrapper's CAPT estimate is from the truth on unseen env resets.

``capt evaluate`` scores the network on dataset clouds; this scores what a policy is given: the
observation wrapper's estimate (object isolation, CAPT, the handle and axis-sign geometry and, when
on, the hinge put on the moving part's edge, found on the part's coplanar panel) on freshly reset
test-split scenes or user files (``--object``), world frame.
Errors per reset: the signed direction error (degrees; a flipped axis counts as ~180), the
distance between the estimated and true axis lines (revolute joints only, metres) and the grasp
point's distance to the true one (metres).
"""

from __future__ import annotations

import argparse
import itertools
from typing import Any

import numpy as np

from capt_common.json_report import write_json
from capt_env.commands.object_targets import add_object_arguments, object_targets, target_task
from capt_env.commands.task_overrides import add_task_argument, task_overrides
from capt_env.wrappers.config import PerceptionWrapperConfig
from capt_env.wrappers.estimate import JointAxisEstimate


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_object_arguments(parser, ["cabinet_door"])
    parser.add_argument("--episodes", type=int, default=8,
                        help="episodes (unseen instances, each estimated at its reset) per category")
    parser.add_argument("--first-seed", type=int, default=0, help="episodes use seeds first..first+n-1")
    parser.add_argument("--checkpoint", default=None, help="CAPT checkpoint (default: the shipped one)")
    parser.add_argument("--hinge-on-part-edge", default="both", choices=["both", "on", "off"],
                        help="score the wrapper with the hinge-on-edge check, without it, or both")
    parser.add_argument("--dense-geometry", default="on", choices=["both", "on", "off"],
                        help="look for handles among all isolated points (on), only CAPT's "
                             "downsampled input (off), or score both")
    parser.add_argument("--slide-along-front", default="on", choices=["both", "on", "off"],
                        help="slide a prismatic estimate along its part's front normal (on), keep "
                             "CAPT's direction (off), or score both")
    parser.add_argument("--coplanar-panel", default="on", choices=["both", "on", "off"],
                        help="look for a closed part's hinge edge and handle on the whole flat panel "
                             "it lies on (on: the wrapper's default panel_max_state), only on CAPT's "
                             "moving points (off: panel_max_state 0), or score both")
    add_task_argument(parser)
    parser.add_argument("--markdown", default=None, help="also write the table as Markdown here")


def estimate_errors(est: JointAxisEstimate, truth: JointAxisEstimate) -> dict[str, Any]:
    """Errors of one estimate against the truth (both world frame): ``direction_deg`` (signed
    directions, [0, 180]), ``sign_right`` (the estimated axis opens the part the same way),
    ``line_m`` (distance between the axis lines; None for a prismatic truth) and ``grasp_m``."""
    from perception.metrics import direction_error_deg, line_distance

    direction = direction_error_deg(est.direction, truth.direction)
    line = None
    if truth.joint_type == "revolute":
        line = line_distance(est.direction, est.pivot, truth.direction, truth.pivot)
    return {"direction_deg": direction, "sign_right": bool(direction < 90.0), "line_m": line,
            "grasp_m": float(np.linalg.norm(np.asarray(est.grasp_point) - truth.grasp_point)),
            "type_right": est.joint_type == truth.joint_type}


def _summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    lines = [r["line_m"] for r in rows if r["line_m"] is not None]
    return {"resets": len(rows),
            "direction_deg_mean": float(np.mean([r["direction_deg"] for r in rows])),
            "sign_right": float(np.mean([r["sign_right"] for r in rows])),
            "line_m_mean": float(np.mean(lines)) if lines else None,
            "line_m_median": float(np.median(lines)) if lines else None,
            "grasp_m_mean": float(np.mean([r["grasp_m"] for r in rows])),
            "grasp_far": float(np.mean([r["grasp_m"] > 0.1 for r in rows])),
            "type_right": float(np.mean([r["type_right"] for r in rows]))}


def _on(flag: bool) -> str:
    return "on" if flag else "off"


def _cm(v: float | None) -> str:
    return "-" if v is None else f"{100 * v:.1f}"


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from capt_env.env_factory import make_env
    from capt_env.wrappers.perception_sources import ground_truth_estimate
    from perception.checkpoints import default_checkpoint

    if args.episodes < 1:
        raise SystemExit(f"--episodes must be >= 1, got {args.episodes}")
    choices = {"both": [False, True], "on": [True], "off": [False]}
    switches = ("hinge_on_part_edge", "dense_geometry", "slide_along_front", "coplanar_panel")
    combos = [dict(zip(switches, values, strict=True)) for values in itertools.product(
        *(choices[getattr(args, name)] for name in switches))]
    panel_on = PerceptionWrapperConfig().panel_max_state
    seeds = list(range(args.first_seed, args.first_seed + args.episodes))
    task = task_overrides(args.task)
    targets = object_targets(args)
    header = ("| object | hinge on part edge | dense geometry | slide along front | coplanar panel | "
              "direction (deg) | sign right | line (cm, mean) | line (cm, median) | grasp point (cm) | "
              "grasp > 10 cm | resets |")
    table, results = [header, "|" + " --- |" * 12], []
    for target in targets:
        like = target.model_category()
        for combo in combos:
            wrapper = {"source": "capt", "every_k_steps": 1,
                       "hinge_on_part_edge": combo["hinge_on_part_edge"],
                       "dense_geometry": combo["dense_geometry"],
                       "slide_along_front": combo["slide_along_front"],
                       "panel_max_state": panel_on if combo["coplanar_panel"] else 0.0,
                       "checkpoint": str(args.checkpoint or default_checkpoint(like))}
            env = make_env(target.category, wrapper, task=target_task(target, task), obs_mode="pointcloud")
            rows = []
            try:
                desc = target.label + "".join(f" {k.split('_')[0]} {_on(v)}" for k, v in combo.items())
                for seed in tqdm(seeds, desc=desc, leave=False):
                    _, info = env.reset(seed=seed)
                    rows.append({"seed": seed, **estimate_errors(env.estimate, ground_truth_estimate(info))})
            finally:
                env.close()
            s = _summary(rows)
            results.append({"object": target.label, "category": target.category,
                            "checkpoint": wrapper["checkpoint"], **combo, **s, "per_reset": rows})
            on_off = "".join(f"{_on(v)} | " for v in combo.values())
            table.append(f"| {target.label.replace('_', ' ')} | {on_off}"
                         f"{s['direction_deg_mean']:.1f} | {s['sign_right']:.2f} | {_cm(s['line_m_mean'])} | "
                         f"{_cm(s['line_m_median'])} | {100 * s['grasp_m_mean']:.1f} | "
                         f"{s['grasp_far']:.2f} | {s['resets']} |")
    text = "\n".join(table)
    print(text)
    if args.markdown:
        with open(args.markdown, "w") as fh:
            fh.write(text + "\n")
    if args.json:
        write_json(args.json, {"command": "estimate-errors", "seeds": seeds, "task": args.task,
                               "results": results})
    return 0
