"""Build the task's object (procedural instance or user file) and collect what the task needs about it.

Everything here is computed once per reconfiguration: the movable joints and their limits, which
limit of each is closed (so that task joint states are 0 closed and grow while opening), which
joint to open, where to grasp it, the object's bounds in its own frame at the closed state, the yaw
that turns its front to the robot, and the lookup table from simulator segmentation ids to part
labels. A :class:`LoadedObject` is one articulation, built into every sub-scene or into one
(``scene_idxs``); :mod:`capt_env.tasks.object_batch` holds one per sub-scene.
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
from capt_env.objects.errors import ObjectFileError
from capt_env.objects.link_geometry import ShapeMesh, link_shape_meshes, link_vertices, sample_surface
from capt_env.objects.registry import make_object
from capt_env.objects.spec import ObjectSpec
from capt_env.objects.splits import instance_ids as split_instance_ids
from capt_env.objects.user_files import load_user_object
from capt_env.tasks.config import USER_GRASP_MAX_Y, USER_GRASP_X, TaskConfig
from capt_env.tasks.grasp_target import GraspTarget, find_grasp_target

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
    limits: np.ndarray  # (J, 2) task-frame limits: (0, range), radians or metres; 0 = closed
    closed_qpos: np.ndarray  # (J,) simulator joint position of each joint's closed limit
    open_sign: np.ndarray  # (J,) +1 where opening raises the simulator position, -1 where it lowers it
    child_parts: list[int]  # part label moved by each joint: k + 1 for joint k (see link_parts)
    target_joint: int
    grasp_link: Link
    grasp_local: np.ndarray  # (3,) grasp point in grasp_link's frame, metres
    aabb: tuple[np.ndarray, np.ndarray]  # object-frame bounds at qpos 0, metres
    front_yaw: float  # yaw (rad) that turns the object's front towards the robot (-x)
    segmentation_lut: torch.Tensor  # (1, max_id + 1) part label per segmentation id, -1 elsewhere

    warnings: tuple[str, ...] = ()  # what loading a user file ignored or approximated
    grasp_source: str = "spec"  # how the grasp target was found (see grasp_target.py)
    placement_shift: tuple[float, float] = (0.0, 0.0)  # world metres added to the placement (user files)
    grasp_standoff: float | None = None  # m the grasp target stands off the part's face (user files)

    @property
    def dof(self) -> int:
        return len(self.joints)

    def sim_qpos(self, state: np.ndarray) -> np.ndarray:
        """Simulator joint positions (..., J) of task joint states (0 closed, growing while opening)."""
        return self.closed_qpos + self.open_sign * np.asarray(state)

    def task_state(self, qpos: torch.Tensor) -> torch.Tensor:
        """Task joint states (..., J) of simulator joint positions (the inverse of :meth:`sim_qpos`)."""
        closed = torch.as_tensor(self.closed_qpos, dtype=qpos.dtype, device=qpos.device)
        sign = torch.as_tensor(self.open_sign, dtype=qpos.dtype, device=qpos.device)
        return sign * (qpos - closed)

    @property
    def target_child_link(self) -> Link:
        return self.joints[self.target_joint].child_link


def allowed_instances(cfg: TaskConfig) -> list[int]:
    """The procedural instance ids the task draws from: ``instance_ids``, else the ``split``'s ids."""
    if cfg.instance_ids is not None:
        return list(cfg.instance_ids)
    if cfg.split == "all":
        return [i for s in ("train", "val", "test") for i in split_instance_ids(cfg.category, s)]
    return split_instance_ids(cfg.category, cfg.split)


def choose_instance(cfg: TaskConfig, rng: np.random.RandomState, instance_id: int | None) -> int:
    """The procedural instance for this reconfiguration: ``instance_id`` if given, else a seeded draw
    (one ``rng.randint`` call)."""
    allowed = allowed_instances(cfg)
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
    """Build the configured object into ``scene`` (root at the origin, every joint closed) and
    describe it."""
    if cfg.category is not None:
        return load_procedural(scene, cfg, choose_instance(cfg, rng, instance_id))
    if instance_id is not None:
        raise ValueError("instance_id applies to procedural categories, not to a user object file")
    return _load_user_file(scene, cfg)


JointTable = tuple[list[ArticulationJoint], list[str], list[int], np.ndarray, list[int]]


def _joint_table(art: Articulation) -> JointTable:
    """Movable joints, their names, type ids, simulator limits (J, 2) and child part labels."""
    joints = list(art.active_joints)
    names = [j.name for j in joints]
    child_parts = [k + 1 for k in range(len(joints))]  # see link_parts
    type_ids = [_joint_type_id(j) for j in joints]
    limits = np.array([_limits(j, t) for j, t in zip(joints, type_ids, strict=True)], dtype=np.float64)
    return joints, names, type_ids, limits, child_parts


def load_procedural(scene: Any, cfg: TaskConfig, instance_id: int, name: str = "object",
                    scene_idxs: list[int] | None = None, spec: ObjectSpec | None = None) -> LoadedObject:
    """Build instance ``instance_id`` of ``cfg.category`` as articulation ``name`` (unique in the
    scene) in the sub-scenes ``scene_idxs`` (default: all) and describe it. ``spec`` replaces the
    instance's own spec (one with varied geometry, see ``capt_env.objects.style``)."""
    iid = int(instance_id)
    spec = spec if spec is not None else make_object(cfg.category, iid)
    art = build_articulated_object(scene, spec, name=name, fix_root=True, scale=cfg.scale,
                                   scene_idxs=scene_idxs)
    joints, names, type_ids, sim_limits, child_parts = _joint_table(art)
    links = list(art.links)
    link_names = [link.name for link in links]
    lo, hi = spec.aabb()
    # Procedural joints are closed at their lower limit and open towards the upper one.
    return LoadedObject(
        articulation=art, name=name, category=cfg.category, instance_id=iid, spec=spec,
        joints=joints, joint_names=names, joint_type_ids=type_ids,
        limits=_task_limits(sim_limits), closed_qpos=sim_limits[:, 0].copy(), open_sign=np.ones(len(joints)),
        child_parts=child_parts, target_joint=_find_joint(names, spec.target_joint),
        grasp_link=links[link_names.index(spec.grasp_link)],
        grasp_local=np.asarray(spec.grasp_point, dtype=np.float64) * cfg.scale,
        aabb=(lo * cfg.scale, hi * cfg.scale),
        front_yaw=float(math.pi - math.atan2(spec.front[1], spec.front[0])),  # spec.front: outward normal
        segmentation_lut=_segmentation_lut(art, joints),
    )


def _load_user_file(scene: Any, cfg: TaskConfig) -> LoadedObject:
    art, info = load_user_object(
        scene, Path(cfg.object), joint=cfg.joint, scale=cfg.scale, name="object",
        visual_groups=tuple(cfg.visual_groups), mjcf_angle=cfg.mjcf_angle, density=cfg.density,
        joint_damping=cfg.joint_damping, joint_friction=cfg.joint_friction,
    )
    joints, names, type_ids, sim_limits, child_parts = _joint_table(art)
    target = _find_joint(names, info["joint"])
    closed_at_upper = [_closed_at_upper(art, sim_limits, k, cfg.closed) for k in range(len(joints))]
    open_sign = np.where(closed_at_upper, -1.0, 1.0)
    closed_qpos = np.where(closed_at_upper, sim_limits[:, 1], sim_limits[:, 0])
    _set_qpos(art, closed_qpos)
    warnings = list(info["warnings"])
    grasp_link = joints[target].child_link
    file_mass = float(grasp_link.mass.reshape(-1)[0])
    if cfg.part_mass is not None:
        set_link_mass(grasp_link, cfg.part_mass)
    elif file_mass < MIN_PART_MASS:
        warnings.append(f"the moving part {grasp_link.name!r} weighs {file_mass:.3g} kg; "
                        f"set to {MIN_PART_MASS} kg (MIN_PART_MASS; part_mass sets it)")
        set_link_mass(grasp_link, MIN_PART_MASS)
    aabb = _articulation_aabb(art)
    grasp = _user_grasp_target(art, joints, target, type_ids[target], float(open_sign[target]), aabb, cfg)
    front = cfg.front_yaw_radians()
    if front is None:
        front = _guess_front_azimuth(art, grasp_link, grasp, aabb)
    link_pose = _pose_matrix(grasp_link.pose)
    grasp_closed = link_pose[:3, :3] @ grasp.point + link_pose[:3, 3]
    shift = ((0.0, 0.0) if cfg.object_xy is not None
             else grasp_reach_shift(grasp_closed, aabb, float(math.pi - front), cfg.placement_xy()))
    return LoadedObject(
        articulation=art, name="object", category="user", instance_id=-1, spec=None,
        joints=joints, joint_names=names, joint_type_ids=type_ids, limits=_task_limits(sim_limits),
        closed_qpos=closed_qpos, open_sign=open_sign, child_parts=child_parts, target_joint=target,
        grasp_link=grasp_link, grasp_local=grasp.point, aabb=aabb, front_yaw=float(math.pi - front),
        segmentation_lut=_segmentation_lut(art, joints), warnings=tuple(warnings),
        grasp_source=grasp.source, placement_shift=shift, grasp_standoff=grasp.standoff,
    )


def grasp_reach_shift(grasp: np.ndarray, aabb: tuple[np.ndarray, np.ndarray], yaw: float,
                      placement_xy: tuple[float, float]) -> tuple[float, float]:
    """The world (dx, dy) metres that moves an object, its bounding-box centre placed at
    ``placement_xy`` and turned by ``yaw`` rad, the least distance that brings its closed grasp
    target ``grasp`` (3,) (object frame, like ``aabb``) into :data:`USER_GRASP_X` x
    [-:data:`USER_GRASP_MAX_Y`, :data:`USER_GRASP_MAX_Y`]; (0, 0) when it lies there already."""
    centre = (np.asarray(aabb[0], dtype=np.float64) + np.asarray(aabb[1], dtype=np.float64)) / 2
    c, s = math.cos(yaw), math.sin(yaw)
    off = np.asarray(grasp, dtype=np.float64)[:2] - centre[:2]
    x = placement_xy[0] + c * off[0] - s * off[1]
    y = placement_xy[1] + s * off[0] + c * off[1]
    dx = float(np.clip(x, *USER_GRASP_X) - x)
    dy = float(np.clip(y, -USER_GRASP_MAX_Y, USER_GRASP_MAX_Y) - y)
    return (dx, dy)


MIN_PART_MASS = 0.05
"""kg. A user file's moving part lighter than this is given this mass (with a warning): held in the
Panda's fingers, a part of a few grams is pushed about by the contact solver. Measured on Meta-World's
window, whose sash weighs 11 g: held open and still, its reported speed stayed at 0.15 m/s, so it
never counted as at rest (opened 20 of 20, success 18 of 20); at 50 g, 20 of 20."""


def _task_limits(sim_limits: np.ndarray) -> np.ndarray:
    return np.stack([np.zeros(len(sim_limits)), sim_limits[:, 1] - sim_limits[:, 0]], axis=-1)


def _set_qpos(art: Articulation, qpos: np.ndarray) -> None:
    art.set_qpos(torch.as_tensor(np.asarray(qpos, dtype=np.float32)).reshape(1, -1))


def _closed_at_upper(art: Articulation, sim_limits: np.ndarray, k: int, closed: str) -> bool:
    """Whether joint ``k`` is closed at its upper limit.

    ``auto``: closed is where the part the joint moves sits with the rest of the object: at each
    limit (other joints at their lower limits) the mean distance (m) of the part's surface from the
    rest's bounding box is measured, and the limit where it is smaller (by over 5 mm) is closed; a
    tie is the lower limit. A closed drawer is inside its cabinet, a closed door or lid lies on its
    frame, while an opened one stands out; unlike the whole object's size this holds for a door that
    swings back beside its cabinet.
    """
    if closed != "auto":
        return closed == "upper"
    moving = _subtree(art, art.active_joints[k].child_link)
    part = [link for link in art.links if link.name in moving]
    rest = [link for link in art.links if link.name not in moving]
    scores = []
    for side in (0, 1):
        q = sim_limits[:, 0].copy()
        q[k] = sim_limits[k, side]
        _set_qpos(art, q)
        pts = _world_surface(part)
        lo, hi = _links_aabb(rest)
        if len(pts) == 0 or lo is None:
            _set_qpos(art, sim_limits[:, 0])
            return False
        outside = np.maximum(lo - pts, 0) + np.maximum(pts - hi, 0)
        scores.append(float(np.linalg.norm(outside, axis=1).mean()))
    _set_qpos(art, sim_limits[:, 0])
    return scores[1] < scores[0] - 0.005


def _subtree(art: Articulation, root: Link) -> set[str]:
    """Names of ``root`` and every link below it."""
    names = {root.name}
    changed = True
    while changed:
        changed = False
        for link in art.links:
            parent = link.joint.parent_link
            if link.name not in names and parent is not None and parent.name in names:
                names.add(link.name)
                changed = True
    return names


def _world_surface(links: list[Link], count: int = 800) -> np.ndarray:
    """Points spread over the links' surfaces, world frame (deterministic)."""
    meshes = []
    for link in links:
        mat = _pose_matrix(link.pose)
        meshes += [ShapeMesh(m.name, m.vertices @ mat[:3, :3].T + mat[:3, 3], m.faces)
                   for m in link_shape_meshes(link)]
    return sample_surface(meshes, count)[0]


def _links_aabb(links: list[Link]) -> tuple[np.ndarray | None, np.ndarray | None]:
    """World-frame bounds (m) of the links' visual geometry; (None, None) if they have none."""
    pts = []
    for link in links:
        verts = link_vertices(link)
        if len(verts):
            mat = _pose_matrix(link.pose)
            pts.append(verts @ mat[:3, :3].T + mat[:3, 3])
    if not pts:
        return None, None
    allp = np.concatenate(pts)
    return allp.min(axis=0), allp.max(axis=0)


def set_link_mass(link: Link, mass: float) -> None:
    """Set a link's mass (kg), scaling its inertia by the same factor (its shape is unchanged)."""
    for body in link._objs:
        ratio = float(mass) / max(float(body.mass), 1e-9)
        body.set_mass(float(mass))
        body.set_inertia(np.asarray(body.inertia, dtype=np.float32) * ratio)


def _pose_matrix(entity_pose: Any) -> np.ndarray:
    return entity_pose.to_transformation_matrix()[0].cpu().numpy().astype(np.float64)


def _part_meshes(art: Articulation, joints: list[ArticulationJoint], k: int) -> tuple[list, list[str]]:
    """Meshes of the part movable joint ``k`` moves (its child link and every link fixed to it, as in
    :func:`link_parts`), in the child link's frame, with the link each came from."""
    part = joints[k].child_link
    inv = np.linalg.inv(_pose_matrix(part.pose))
    meshes, owners = [], []
    for link, label in zip(art.links, link_parts(art, joints), strict=True):
        if label != k + 1:
            continue
        rel = inv @ _pose_matrix(link.pose)
        for m in link_shape_meshes(link):
            meshes.append(ShapeMesh(m.name, m.vertices @ rel[:3, :3].T + rel[:3, 3], m.faces))
            owners.append(link.name)
    return meshes, owners


def _user_grasp_target(art: Articulation, joints: list[ArticulationJoint], k: int, type_id: int,
                       sign: float, aabb: tuple[np.ndarray, np.ndarray], cfg: TaskConfig) -> GraspTarget:
    """The grasp target of the part joint ``k`` moves (see :mod:`capt_env.tasks.grasp_target`), in
    its child link's frame."""
    joint = joints[k]
    part = joint.child_link
    inv = np.linalg.inv(_pose_matrix(part.pose))
    joint_mat = inv @ _pose_matrix(joint.get_global_pose())
    axis, pivot = sign * joint_mat[:3, 0], joint_mat[:3, 3]
    centre = inv[:3, :3] @ ((aabb[0] + aabb[1]) / 2) + inv[:3, 3]
    meshes, owners = _part_meshes(art, joints, k)
    found = find_grasp_target(meshes, owners, axis, pivot, type_id == 0, centre, handle=cfg.handle,
                              part_name=part.name)
    if cfg.grasp_point is None:
        return found
    point = inv[:3, :3] @ np.asarray(cfg.grasp_point, dtype=np.float64) + inv[:3, 3]
    return GraspTarget(point, found.outward, "option")


def _guess_front_azimuth(art: Articulation, part: Link, grasp: GraspTarget,
                         aabb: tuple[np.ndarray, np.ndarray]) -> float:
    """Azimuth (rad, object frame) of a user object's front normal, snapped to the nearest of the
    frame's +-x / +-y axes (objects stand upright with axis-aligned faces in nearly every file).

    The front is the moving part's outer face when that face is upright (a door, a drawer front); for
    a face looking up (a closed lid) it is the side of the bounding box the grasp point lies on, in
    units of the box's half extents so that a wide box's front still wins."""
    mat = _pose_matrix(part.pose)
    normal = mat[:3, :3] @ grasp.outward
    if np.linalg.norm(normal[:2]) > 0.7:
        v = normal[:2]
    else:
        point = mat[:3, :3] @ grasp.point + mat[:3, 3]
        centre = (aabb[0] + aabb[1]) / 2
        half = np.maximum((aabb[1][:2] - aabb[0][:2]) / 2, 1e-6)
        v = (point[:2] - centre[:2]) / half
        if np.linalg.norm(v) < 1e-6:
            return 0.0
    angle = math.atan2(v[1], v[0])
    return float(round(angle / (math.pi / 2)) * (math.pi / 2))


def _find_joint(names: list[str], wanted: str) -> int:
    for i, name in enumerate(names):
        if name == wanted or name.endswith(wanted):
            return i
    raise ValueError(f"joint {wanted!r} is not a movable joint of the object; movable joints: {names}")


def _joint_type_name(joint: ArticulationJoint) -> str:
    return str(joint.type[0] if isinstance(joint.type, (list, tuple)) else joint.type)


def _joint_type_id(joint: ArticulationJoint) -> int:
    jtype = _joint_type_name(joint)
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


def link_parts(art: Articulation, joints: list[ArticulationJoint]) -> list[int]:
    """The part label of every link (``art.links`` order): 0 for links fixed to the root, ``k + 1``
    for the links movable joint ``k`` moves and that are fixed to its child (links joined by fixed
    joints, such as a handle or a frame without geometry, are one part, as the eye sees them)."""
    part_of_child = {j.child_link.name: k + 1 for k, j in enumerate(joints)}
    parts = []
    for link in art.links:
        cur = link
        while cur is not None and cur.name not in part_of_child:
            cur = cur.joint.parent_link
        parts.append(0 if cur is None else part_of_child[cur.name])
    return parts


def _segmentation_lut(art: Articulation, joints: list[ArticulationJoint]) -> torch.Tensor:
    links = list(art.links)
    ids = [int(link.per_scene_id.reshape(-1)[0]) for link in links]
    lut = torch.full((1, max(ids) + 1), -1, dtype=torch.long)
    for part, seg_id in zip(link_parts(art, joints), ids, strict=True):
        lut[0, seg_id] = part
    return lut


def _articulation_aabb(art: Articulation) -> tuple[np.ndarray, np.ndarray]:
    """World-frame bounds (m) of all the object's visual geometry."""
    lo, hi = _links_aabb(list(art.links))
    if lo is None:
        raise ObjectFileError("the object has no visual geometry to place it by")
    return lo, hi
