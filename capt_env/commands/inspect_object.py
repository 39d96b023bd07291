"""``capt inspect-object PATH``: check a user's URDF/MJCF file in the task before running anything.

Prints the movable joints (type, limits, which limit is closed), each link's size and mass, the
front the task turns to the robot, the placement, the grasp target (and how far a handle stands off
the part's face, against the band CAPT's handle search looks in), whether the Panda can reach it
closed and opened to the success fraction and whether each task camera sees it (a handle outside
every camera's picture cannot be perceived); writes a PNG of the object seen from the task's first
camera with the target joint's axis drawn (red, arrow at the end that opens).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np

from capt_common.json_report import write_json
from capt_env.tasks.camera_view import pixels

PANDA_SHOULDER_HEIGHT = 0.333
"""m: height of the Panda's second joint above its base (the centre of its reach sphere)."""
PANDA_REACH = 0.80
"""m: distance from the shoulder a Panda's hand reaches with a grasp orientation to spare (its
arm's full stretch is about 0.855 m)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("path", help="URDF (.urdf) or MJCF (.xml/.mjcf) file")
    parser.add_argument("--joint", default=None, help="joint to open (default: the first movable one)")
    parser.add_argument("--front-yaw", default=None,
                        help="azimuth (rad) of the file's front normal, or +x/-x/+y/-y (default: guessed)")
    parser.add_argument("--scale", type=float, default=None, help="uniform scale of the file's lengths")
    parser.add_argument("--task", default=None, help="YAML of further TaskConfig keys (closed, handle, ...)")
    parser.add_argument("--png", default=None, help="where to write the picture (default: STEM_inspect.png)")


def _reach(point: np.ndarray) -> float:
    from capt_env.tasks.open_articulated import ROBOT_BASE_XY

    shoulder = np.array([*ROBOT_BASE_XY, PANDA_SHOULDER_HEIGHT])
    return float(np.linalg.norm(np.asarray(point, dtype=np.float64) - shoulder))


def _link_rows(env: Any) -> list[dict[str, Any]]:
    from capt_env.objects.link_geometry import link_vertices

    rows = []
    for link in env.unwrapped.articulation.links:
        verts = link_vertices(link)
        size = (verts.max(axis=0) - verts.min(axis=0)).tolist() if len(verts) else [0.0, 0.0, 0.0]
        rows.append({"link": link.name, "size_m": size, "mass_kg": float(link.mass.reshape(-1)[0])})
    return rows


def _picture(path: Path, env: Any, axis: np.ndarray, pivot: np.ndarray, grasp: np.ndarray,
             title: str) -> Path:
    """The first camera's RGB with the axis (world, 0.5 m long) and the grasp point drawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    obs = env.unwrapped.get_obs()
    cam = next(iter(obs["sensor_data"]))
    rgb = obs["sensor_data"][cam]["rgb"][0].cpu().numpy()
    params = obs["sensor_param"][cam]
    k = params["intrinsic_cv"][0].cpu().numpy()
    ext = params["extrinsic_cv"][0].cpu().numpy()
    ends = pixels(np.stack([pivot - 0.25 * axis, pivot + 0.25 * axis, grasp]), k, ext)
    fig, ax = plt.subplots(figsize=(5, 5))
    ax.imshow(rgb)
    ax.annotate("", xy=ends[1], xytext=ends[0], arrowprops={"arrowstyle": "->", "color": "red", "lw": 2})
    ax.plot(*ends[2], "o", color="yellow", markersize=6, markeredgecolor="black")
    ax.set_xlim(0, rgb.shape[1])
    ax.set_ylim(rgb.shape[0], 0)
    ax.set_title(title, fontsize=9)
    ax.axis("off")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return path


def handle_search_note(standoff: float) -> str:
    """What CAPT's handle search (the ``handle`` refiner's default bands) makes of a grip standing
    ``standoff`` m off its part's face: "" within the first band, else a note to print after it."""
    from capt_env.wrappers.refiners.handle import HandleConfig

    band = HandleConfig()
    far = max(band.max_standoff, band.far_standoff)
    if standoff > far:
        return (f": beyond the band CAPT's handle search looks in ({100 * band.min_standoff:.1f}-"
                f"{100 * far:.0f} cm off the face): with CAPT the grasp may fall back "
                "to another piece or the part's edge")
    if standoff > band.max_standoff:
        return (f": beyond CAPT's first handle search ({100 * band.min_standoff:.1f}-"
                f"{100 * band.max_standoff:.0f} cm off the face), found only when nothing stands "
                f"in that band (the second looks out to {100 * far:.0f} cm)")
    return ""


def run(args: argparse.Namespace) -> int:
    import gymnasium as gym
    import torch

    import capt_env
    from capt_env.commands.object_targets import parse_front_yaw
    from capt_env.commands.task_overrides import task_overrides

    path = Path(args.path)
    if not path.is_file():
        raise SystemExit(f"capt inspect-object: file not found: {path}")
    task: dict[str, Any] = {**task_overrides(args.task), "object": str(path), "yaw_noise": 0.0,
                            "object_xy_noise": [0.0, 0.0], "target_init_fraction": [0.0, 0.0],
                            "other_init_fraction": [0.0, 0.0]}
    given = {"joint": args.joint, "front_yaw": parse_front_yaw(args.front_yaw), "scale": args.scale}
    for key, value in given.items():
        if value is not None:
            task[key] = value
    task.setdefault("cameras", [{"width": 320, "height": 320}])
    env = gym.make(capt_env.registration.GENERIC_ID, obs_mode="rgb", task=task)
    try:
        env.reset(seed=0)
        base = env.unwrapped
        obj = base.object
        info = {k: v[0].cpu().numpy() if torch.is_tensor(v) else v for k, v in base.evaluate().items()}
        k = obj.target_joint
        joints = [{"joint": name, "type": "revolute" if t == 0 else "prismatic",
                   "limits": [float(obj.closed_qpos[i] + min(0, obj.open_sign[i]) * obj.limits[i, 1]),
                              float(obj.closed_qpos[i] + max(0, obj.open_sign[i]) * obj.limits[i, 1])],
                   "closed_at": "upper" if obj.open_sign[i] < 0 else "lower", "target": i == k}
                  for i, (name, t) in enumerate(zip(obj.joint_names, obj.joint_type_ids, strict=True))]
        grasp_closed = np.asarray(info["grasp_point"], dtype=np.float64)
        axis, pivot = info["joint_axis"][k].astype(np.float64), info["joint_pivot"][k].astype(np.float64)
        opened = obj.limits[k, 1] * base.task_config.success_fraction
        state = np.zeros(obj.dof)
        state[k] = opened
        base.articulation.set_qpos(torch.as_tensor(obj.sim_qpos(state), dtype=torch.float32).reshape(1, -1))
        grasp_open = base.grasp_point()[0].cpu().numpy().astype(np.float64)
        base.articulation.set_qpos(torch.as_tensor(obj.sim_qpos(np.zeros(obj.dof)),
                                                   dtype=torch.float32).reshape(1, -1))
        reach = {"closed_m": _reach(grasp_closed), "opened_m": _reach(grasp_open), "limit_m": PANDA_REACH}
        reach["ok"] = reach["closed_m"] <= PANDA_REACH and reach["opened_m"] <= PANDA_REACH
        cameras = [{"camera": v.camera, "sees_grasp_point": bool(v.seen[0]),
                    "step_back_m": round(float(v.step_back_m[0]), 3)} for v in base.grasp_point_views()]
        front_azimuth = math.pi - obj.front_yaw
        report = {
            "path": str(path), "joints": joints, "links": _link_rows(env),
            "front_azimuth_rad": front_azimuth,
            "front_from": "option" if task.get("front_yaw") is not None else "guessed from the moving part",
            "placement_xy_m": [round(float(v + d), 4) for v, d in zip(base.task_config.placement_xy(),
                                                                      obj.placement_shift, strict=True)],
            "placement_shift_m": [round(float(d), 4) for d in obj.placement_shift],
            "grasp_point_m": grasp_closed.tolist(),
            "grasp_from": obj.grasp_source, "grasp_standoff_m": obj.grasp_standoff,
            "reach": reach, "cameras": cameras, "warnings": list(obj.warnings),
        }
        png = Path(args.png or f"{path.stem}_inspect.png")
        report["png"] = str(_picture(png, env, axis, pivot, grasp_closed,
                                     f"{path.name}: {obj.joint_names[k]} (red: axis, opens at arrow)"))
    finally:
        env.close()
    print(f"{path}")
    print("movable joints:")
    for j in joints:
        lo, hi = j["limits"]
        mark = "  <- target" if j["target"] else ""
        print(f"  {j['joint']:<24} {j['type']:<9} limits [{lo:.3f}, {hi:.3f}] "
              f"closed at {j['closed_at']}{mark}")
    print("links:")
    for row in report["links"]:
        size = " x ".join(f"{100 * s:.1f}" for s in row["size_m"])
        print(f"  {row['link']:<24} {size} cm  {row['mass_kg']:.3f} kg")
    print(f"front: azimuth {math.degrees(front_azimuth):.0f} deg in the file's frame "
          f"({report['front_from']}), turned to face the robot")
    moved = (f" (moved {report['placement_shift_m']} m to bring the handle where the Panda reaches it)"
             if any(report["placement_shift_m"]) else "")
    print(f"placement: bounding-box centre at world xy {report['placement_xy_m']} m{moved}")
    print(f"grasp target ({obj.grasp_source}): {np.round(grasp_closed, 3).tolist()} m world")
    standoff = report["grasp_standoff_m"]
    if standoff is not None and obj.grasp_source != "edge":
        note = handle_search_note(standoff)
        print(f"handle: its grip stands {100 * standoff:.1f} cm off the part's face{note}")
    verdict = "in reach" if reach["ok"] else "OUT OF REACH: move it (object_xy) or scale it"
    print(f"reach from the Panda's shoulder: closed {reach['closed_m']:.2f} m, opened to "
          f"{base.task_config.success_fraction:.0%} {reach['opened_m']:.2f} m "
          f"(limit {PANDA_REACH} m): {verdict}")
    for cam in cameras:
        seen = ("sees the grasp target" if cam["sees_grasp_point"] else
                f"DOES NOT SEE the grasp target: move it {cam['step_back_m']:.2f} m back along its line of "
                "sight (the task's cameras: eye)")
        print(f"camera {cam['camera']}: {seen}")
    for warning in report["warnings"]:
        print(f"warning: {warning}")
    print(f"picture: {report['png']}")
    write_json(args.json, report)
    return 0
