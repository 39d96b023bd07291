"""Build the task's object (procedural instance or user file) and collect what the task needs about it.

Everything here is computed once per reconfiguration: the movable joints and their limits, which
joint to open, where to grasp it, the object's bounds in its own frame, the yaw that turns its front
to the robot, and the lookup table from simulator segmentation ids to part labels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from mani_skill.utils.structs import Articulation, ArticulationJoint, Link

from capt_env.objects.builder import build_articulated_object
from capt_env.objects.registry import make_object
from capt_env.objects.spec import ObjectSpec
from capt_env.objects.splits import instance_ids as split_instance_ids
from capt_env.objects.user_files import load_user_object
from capt_env.tasks.config import TaskConfig

# Revolute joints without finite limits (URDF "continuous") are treated as [-pi, pi].
_UNLIMITED_REVOLUTE = (-math.pi, math.pi)


@dataclass
class LoadedObject:
    """The built object plus the facts the task reads every step. Arrays are in the object frame."""

    articulation: Articulation
    name: str
    category: str  # a procedural category, or "user" for a URDF/MJCF file
    instance_id: int  # -1 for user files
    spec: ObjectSpec | None
    joints: list[ArticulationJoint]  # the movable joints, in qpos order
    joint_names: list[str]
    joint_type_ids: list[int]  # 0 revolute, 1 prismatic
    limits: np.ndarray  # (J, 2) radians or metres
    child_parts: list[int]  # part label (link index) moved by each joint
    target_joint: int
    grasp_link: Link
    grasp_local: np.ndarray  # (3,) grasp point in grasp_link's frame, metres
    aabb: tuple[np.ndarray, np.ndarray]  # object-frame bounds at qpos 0, metres
    front_yaw: float  # yaw (rad) that turns the object's front towards the robot (-x)
    segmentation_lut: torch.Tensor  # (1, max_id + 1) part label per segmentation id, -1 elsewhere

    @property
    def dof(self) -> int:
        return len(self.joints)

    @property
    def target_child_link(self) -> Link:
        return self.joints[self.target_joint].child_link


def choose_instance(cfg: TaskConfig, rng: np.random.RandomState, instance_id: int | None) -> int:
    """The procedural instance for this reconfiguration: ``instance_id`` if given, else a seeded draw."""
    if cfg.instance_ids is not None:
        allowed = list(cfg.instance_ids)
    elif cfg.split == "all":
        allowed = [i for s in ("train", "val", "test") for i in split_instance_ids(cfg.category, s)]
    else:
        allowed = split_instance_ids(cfg.category, cfg.split)
    if instance_id is not None:
        if instance_id not in allowed:
            raise ValueError(
                f"instance_id {instance_id} is not among the allowed instances of {cfg.category!r} "
                f"(split {cfg.split!r}, {len(allowed)} ids)"
            )
        return int(instance_id)
    return int(allowed[rng.randint(len(allowed))])


def load_object(
    scene: Any, cfg: TaskConfig, rng: np.random.RandomState, instance_id: int | None = None
) -> LoadedObject:
    """Build the configured object into ``scene`` (root at the origin, qpos 0) and describe it."""
    if cfg.category is not None:
        iid = choose_instance(cfg, rng, instance_id)
        spec = make_object(cfg.category, iid)
        art = build_articulated_object(scene, spec, name="object", fix_root=True, scale=cfg.scale)
        target_name = spec.target_joint
        grasp_link_name = spec.grasp_link
        grasp_local = np.asarray(spec.grasp_point, dtype=np.float64) * cfg.scale
        lo, hi = spec.aabb()
        aabb = (lo * cfg.scale, hi * cfg.scale)
        category = cfg.category
    else:
        if instance_id is not None:
            raise ValueError("instance_id applies to procedural categories, not to a user object file")
        art, info = load_user_object(scene, Path(cfg.object), joint=cfg.joint, scale=cfg.scale,
                                     name="object")
        iid, spec, category = -1, None, "user"
        target_name = info["joint"]
        grasp_link_name, grasp_local = None, None
        aabb = _articulation_aabb(art)

    joints = list(art.active_joints)
    names = [j.name for j in joints]
    target = _find_joint(names, target_name)
    links = list(art.links)
    link_names = [link.name for link in links]
    child_parts = [link_names.index(j.child_link.name) for j in joints]
    type_ids = [_joint_type_id(j) for j in joints]
    limits = np.array([_limits(j, t) for j, t in zip(joints, type_ids, strict=True)], dtype=np.float64)

    if grasp_link_name is None:
        grasp_link = joints[target].child_link
        grasp_local = _far_point_on_link(grasp_link, joints[target], type_ids[target])
    else:
        grasp_link = links[link_names.index(grasp_link_name)]

    if spec is not None:  # procedural objects state their front's outward normal (object frame)
        front_yaw = float(math.pi - math.atan2(spec.front[1], spec.front[0]))
    else:
        front_yaw = _front_yaw(aabb, grasp_link, grasp_local)
    return LoadedObject(
        articulation=art, name="object", category=category, instance_id=iid, spec=spec,
        joints=joints, joint_names=names, joint_type_ids=type_ids, limits=limits,
        child_parts=child_parts, target_joint=target, grasp_link=grasp_link,
        grasp_local=np.asarray(grasp_local, dtype=np.float64), aabb=aabb, front_yaw=front_yaw,
        segmentation_lut=_segmentation_lut(links),
    )


def _find_joint(names: list[str], wanted: str) -> int:
    for i, name in enumerate(names):
        if name == wanted or name.endswith(wanted):
            return i
    raise ValueError(f"joint {wanted!r} is not a movable joint of the object; movable joints: {names}")


def _joint_type_id(joint: ArticulationJoint) -> int:
    jtype = joint.type[0] if isinstance(joint.type, (list, tuple)) else joint.type
    if jtype.startswith("revolute") or jtype == "continuous":
        return 0
    if jtype == "prismatic":
        return 1
    raise ValueError(f"joint {joint.name!r} has unsupported type {jtype!r}")


def _limits(joint: ArticulationJoint, type_id: int) -> tuple[float, float]:
    lim = np.asarray(joint.limits[0].cpu() if hasattr(joint.limits, "cpu") else joint.limits)
    lo, hi = float(lim.reshape(-1)[0]), float(lim.reshape(-1)[1])
    if type_id == 0 and not (np.isfinite(lo) and np.isfinite(hi)):
        lo, hi = _UNLIMITED_REVOLUTE
    if not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo:
        raise ValueError(f"joint {joint.name!r} needs finite limits with lower < upper, got {(lo, hi)}")
    return lo, hi


def _segmentation_lut(links: list[Link]) -> torch.Tensor:
    ids = [int(link.per_scene_id.reshape(-1)[0]) for link in links]
    lut = torch.full((1, max(ids) + 1), -1, dtype=torch.long)
    for part, seg_id in enumerate(ids):
        lut[0, seg_id] = part
    return lut


def _link_vertices(link: Link) -> np.ndarray:
    """Vertices of a link's visual meshes in the link's own frame, metres."""
    mesh = link.generate_mesh(lambda _link, _shape: True, mesh_name="capt_all")[0]
    return np.asarray(mesh.vertices, dtype=np.float64)


def _articulation_aabb(art: Articulation) -> tuple[np.ndarray, np.ndarray]:
    pts = []
    for link in art.links:
        verts = _link_vertices(link)
        if len(verts) == 0:
            continue
        mat = link.pose.to_transformation_matrix()[0].cpu().numpy()
        pts.append(verts @ mat[:3, :3].T + mat[:3, 3])
    if not pts:
        raise ValueError("the object has no visual geometry to place it by")
    allp = np.concatenate(pts)
    return allp.min(axis=0), allp.max(axis=0)


def _far_point_on_link(link: Link, joint: ArticulationJoint, type_id: int) -> np.ndarray:
    """A graspable point of a user object's moving link: the vertex farthest from a revolute axis,
    or the vertex farthest along a prismatic axis (the front face), in the link frame."""
    verts = _link_vertices(link)
    if len(verts) == 0:
        return np.zeros(3)
    link_mat = link.pose.to_transformation_matrix()[0].cpu().numpy()
    joint_mat = joint.get_global_pose().to_transformation_matrix()[0].cpu().numpy()
    world = verts @ link_mat[:3, :3].T + link_mat[:3, 3]
    axis, pivot = joint_mat[:3, 0], joint_mat[:3, 3]
    rel = world - pivot
    if type_id == 0:
        score = np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1)
    else:
        score = rel @ axis
    return verts[int(np.argmax(score))]


def _front_yaw(aabb: tuple[np.ndarray, np.ndarray], grasp_link: Link, grasp_local: np.ndarray) -> float:
    """Yaw turning a user object's front face towards -x (the robot).

    The front is the side of the bounding box the grasp point lies on: the direction from the box
    centre to the grasp point (in units of the box's half extents), snapped to the nearest of the
    object frame's +-x / +-y axes (objects stand upright, so their faces are axis-aligned).
    """
    mat = grasp_link.pose.to_transformation_matrix()[0].cpu().numpy()
    grasp = mat[:3, :3] @ grasp_local + mat[:3, 3]
    centre = (aabb[0] + aabb[1]) / 2
    half = np.maximum((aabb[1][:2] - aabb[0][:2]) / 2, 1e-6)
    v = (grasp[:2] - centre[:2]) / half  # in box-relative units, so a wide box's front still wins
    if np.linalg.norm(v) < 1e-6:
        return 0.0
    angle = math.atan2(v[1], v[0])
    snapped = round(angle / (math.pi / 2)) * (math.pi / 2)
    return float(math.pi - snapped)
