"""``capt estimate-errors``: how far the wrapper's CAPT estimate is from the truth on unseen env resets.

``capt evaluate`` scores the network on dataset clouds; this scores what a policy is given: the
observation wrapper's estimate on freshly reset test-split scenes or user files (``--object``),
world frame, from each perception source named by ``--perception``: ``capt_raw`` (the network with
double voting alone) and ``capt`` (refined by the geometric refiners), and with
``--without-refiner`` from ``capt`` without one refiner at a time (an ablation). Every row of a
target is computed from the same look (one render and one network run per reset), so rows differ
only by the refiners.
Errors per reset: the signed direction error (degrees; a flipped axis counts as ~180), the
distance between the estimated and true axis lines (revolute joints only, metres), the state error
(radians or metres), the grasp point's distance to the true one (metres) and whether any camera
had the true grasp point in its picture (a handle no camera sees cannot be found; see
``OpenArticulatedEnv.grasp_point_views``).
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from capt_common.json_report import write_json
from capt_env.commands.object_targets import add_object_arguments, object_targets, target_task
from capt_env.commands.task_overrides import add_task_argument, task_overrides
from capt_env.wrappers.estimate import JointAxisEstimate


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from capt_env.wrappers.refiners import REFINER_NAMES

    add_object_arguments(parser, ["cabinet_door"])
    parser.add_argument("--episodes", type=int, default=8,
                        help="episodes (unseen instances, each estimated at its reset) per category")
    parser.add_argument("--first-seed", type=int, default=0, help="episodes use seeds first..first+n-1")
    parser.add_argument("--checkpoint", default=None, help="CAPT checkpoint (default: the shipped one)")
    parser.add_argument("--perception", nargs="+", default=["capt_raw", "capt"], choices=["capt_raw", "capt"],
                        help="perception sources to score: capt_raw (the network alone), capt (refined)")
    parser.add_argument("--without-refiner", nargs="+", default=[], metavar="NAME",
                        choices=[*REFINER_NAMES, "all"],
                        help="also score capt without each named refiner, one at a time ('all': every "
                             f"refiner in turn); names: {', '.join(REFINER_NAMES)}")
    add_task_argument(parser)
    parser.add_argument("--markdown", default=None, help="also write the table as Markdown here")


def estimate_errors(est: JointAxisEstimate, truth: JointAxisEstimate) -> dict[str, Any]:
    """Errors of one estimate against the truth (both world frame): ``direction_deg`` (signed
    directions, [0, 180]), ``sign_right`` (the estimated axis opens the part the same way),
    ``line_m`` (distance between the axis lines; None for a prismatic truth), ``state_error``
    (|state difference|, radians or metres), ``grasp_m`` and ``type_right``."""
    from perception.metrics import direction_error_deg, line_distance

    direction = direction_error_deg(est.direction, truth.direction)
    line = None
    if truth.joint_type == "revolute":
        line = line_distance(est.direction, est.pivot, truth.direction, truth.pivot)
    return {"direction_deg": direction, "sign_right": bool(direction < 90.0), "line_m": line,
            "state_error": abs(float(est.state) - float(truth.state)),
            "grasp_m": float(np.linalg.norm(np.asarray(est.grasp_point) - truth.grasp_point)),
            "type_right": est.joint_type == truth.joint_type}


def _summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    lines = [r["line_m"] for r in rows if r["line_m"] is not None]
    direction = [r["direction_deg"] for r in rows]
    state = [r["state_error"] for r in rows]
    return {"resets": len(rows),
            "direction_deg_mean": float(np.mean(direction)),
            "direction_deg_median": float(np.median(direction)),
            "sign_right": float(np.mean([r["sign_right"] for r in rows])),
            "line_m_mean": float(np.mean(lines)) if lines else None,
            "line_m_median": float(np.median(lines)) if lines else None,
            "state_error_mean": float(np.mean(state)),
            "state_error_median": float(np.median(state)),
            "grasp_m_mean": float(np.mean([r["grasp_m"] for r in rows])),
            "grasp_far": float(np.mean([r["grasp_m"] > 0.1 for r in rows])),
            "grasp_seen": float(np.mean([r["grasp_seen"] for r in rows])),
            "type_right": float(np.mean([r["type_right"] for r in rows]))}


def variants(perception: list[str], without: list[str]) -> list[tuple[str, str | None]]:
    """(source, refiner left out or None) of every row: each source in ``perception``, then
    ``capt`` without each refiner in ``without`` (``all``: every refiner, in pipeline order)."""
    from capt_env.wrappers.refiners import REFINER_NAMES

    left_out = list(REFINER_NAMES) if "all" in without else list(dict.fromkeys(without))
    return [(p, None) for p in perception] + [("capt", name) for name in left_out]


def _pipeline(source: str, left_out: str | None) -> Any:
    """A fresh estimate pipeline of ``source`` (the wrapper's defaults) without ``left_out``."""
    from capt_env.wrappers.config import PerceptionWrapperConfig
    from capt_env.wrappers.perception_sources import capt_pipeline
    from capt_env.wrappers.refiners import REFINER_NAMES, without

    refiners = REFINER_NAMES if left_out is None else without(left_out)
    return capt_pipeline(PerceptionWrapperConfig(source=source, checkpoint="-", refiners=refiners))


def refiners_label(source: str, left_out: str | None) -> str:
    """The table's refiners cell: ``none`` (capt_raw), ``all`` or ``all but NAME``."""
    if source == "capt_raw":
        return "none"
    return "all" if left_out is None else f"all but {left_out}"


def _cm(v: float | None) -> str:
    return "-" if v is None else f"{100 * v:.1f}"


def _state_cell(s: dict[str, Any], joint_type: str) -> str:
    """Mean state error in degrees (revolute) or centimetres (prismatic)."""
    v = s["state_error_mean"]
    return f"{np.degrees(v):.1f} deg" if joint_type == "revolute" else f"{100 * v:.1f} cm"


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from capt_env.env_factory import make_env
    from capt_env.wrappers.perception_sources import ground_truth_estimate
    from perception.checkpoints import default_checkpoint

    if args.episodes < 1:
        raise SystemExit(f"--episodes must be >= 1, got {args.episodes}")
    rows_of = variants(args.perception, args.without_refiner)
    seeds = list(range(args.first_seed, args.first_seed + args.episodes))
    task = task_overrides(args.task)
    header = ("| object | perception | refiners | direction (deg, mean) | direction (deg, median) | "
              "sign right | line (cm, mean) | line (cm, median) | state (mean) | grasp point (cm) | "
              "grasp > 10 cm | grasp point in view | resets |")
    table, results = [header, "|" + " --- |" * 13], []
    for target in object_targets(args):
        like = target.model_category()
        checkpoint = str(args.checkpoint or default_checkpoint(like))
        # the capt source with the wrapper's defaults: its look is what every row refines
        env = make_env(target.category, {"source": "capt", "every_k_steps": 1, "checkpoint": checkpoint},
                       task=target_task(target, task), obs_mode="pointcloud")
        per_row: list[list[dict[str, Any]]] = [[] for _ in rows_of]
        joint_type = "revolute"
        try:
            for seed in tqdm(seeds, desc=target.label, leave=False):
                env.source.last_look = None
                _, info = env.reset(seed=seed)
                truth = ground_truth_estimate(info)
                joint_type = truth.joint_type
                # a handle no camera sees cannot be perceived: said beside the grasp point's error
                in_view = any(bool(v.seen[0]) for v in env.unwrapped.grasp_point_views())
                seen = env.source.last_look
                for (source, left_out), rows in zip(rows_of, per_row, strict=True):
                    pipeline = _pipeline(source, left_out)
                    est = env.estimate if seen is None else pipeline.estimate(seen)  # None: too few points
                    fired = [] if pipeline.last_draft is None else list(pipeline.last_draft.fired)
                    rows.append({"seed": seed, **estimate_errors(est, truth), "grasp_seen": in_view,
                                 "fired": fired})
        finally:
            env.close()
        for (source, left_out), rows in zip(rows_of, per_row, strict=True):
            s, label = _summary(rows), refiners_label(source, left_out)
            results.append({"object": target.label, "category": target.category, "checkpoint": checkpoint,
                            "perception": source, "without_refiner": left_out,
                            "refiners": label, "joint_type": joint_type,
                            **s, "per_reset": rows})
            table.append(f"| {target.label.replace('_', ' ')} | {source} | {label} | "
                         f"{s['direction_deg_mean']:.1f} | {s['direction_deg_median']:.1f} | "
                         f"{s['sign_right']:.2f} | {_cm(s['line_m_mean'])} | {_cm(s['line_m_median'])} | "
                         f"{_state_cell(s, joint_type)} | {100 * s['grasp_m_mean']:.1f} | "
                         f"{s['grasp_far']:.2f} | {s['grasp_seen']:.2f} | {s['resets']} |")
    text = "\n".join(table)
    print(text)
    if args.markdown:
        with open(args.markdown, "w") as fh:
            fh.write(text + "\n")
    if args.json:
        # no "command" key of our own: write_json records the command line under it
        write_json(args.json, {"verb": "estimate-errors", "seeds": seeds, "task": args.task,
                               "perception": args.perception, "without_refiner": args.without_refiner,
                               "results": results})
    return 0

