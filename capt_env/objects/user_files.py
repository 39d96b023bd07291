"""Load a user's URDF or MJCF articulated object, and write procedural objects as URDF.

``load_user_object`` builds the file through ManiSkill's URDF/MJCF loaders and picks the joint to
open by name (default: the first movable joint). Joint friction recorded in the file
(``<dynamics friction=...>``) is applied after building, because ManiSkill ignores it at build
time. ``spec_to_urdf`` writes an ``ObjectSpec`` as URDF text (boxes only; URDF joints take an
explicit ``<axis>``, so each joint origin is the pivot without rotation and the axis is written as
is).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
import sapien
from mani_skill.utils.structs import Articulation

from capt_env.objects.spec import ObjectSpec

URDF_SUFFIXES = (".urdf",)
MJCF_SUFFIXES = (".xml", ".mjcf")
MOVABLE_TYPES = ("revolute", "revolute_unwrapped", "prismatic", "continuous")


def _joint_type(joint: Any) -> str:
    jtype = joint.type
    return jtype[0] if isinstance(jtype, (list, tuple)) else str(jtype)


def load_user_object(
    scene: Any,
    path: str | Path,
    joint: str | None = None,
    scale: float = 1.0,
    name: str = "user_object",
    fix_root: bool = True,
) -> tuple[Articulation, dict[str, Any]]:
    """Build a URDF (``.urdf``) or MJCF (``.xml``/``.mjcf``) file into ``scene``.

    :param joint: name of the joint to open (exact name as in the file); default: the first movable
        joint in the articulation's order.
    :param scale: uniform scale of all lengths.
    :returns: the articulation and ``info`` with keys ``joint`` (chosen joint name), ``joint_type``
        ("revolute"/"prismatic"/...), ``movable_joints`` (names, in qpos order), ``format``
        ("urdf"/"mjcf") and ``path``.
    :raises FileNotFoundError: if ``path`` does not exist.
    :raises ValueError: for an unsupported suffix, a file without a movable joint, or an unknown
        ``joint`` (the message lists the movable joints).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"object file not found: {path}")
    suffix = path.suffix.lower()
    if suffix in URDF_SUFFIXES:
        fmt, loader = "urdf", scene.create_urdf_loader()
    elif suffix in MJCF_SUFFIXES:
        fmt, loader = "mjcf", scene.create_mjcf_loader()
    else:
        raise ValueError(
            f"unsupported object file {path}: suffix {path.suffix!r}; expected one of "
            f"{list(URDF_SUFFIXES + MJCF_SUFFIXES)}"
        )
    loader.name = name
    loader.scale = scale
    loader.fix_root_link = fix_root
    parsed = loader.parse(str(path))
    builders = parsed["articulation_builders"]
    if not builders:
        raise ValueError(f"{path} contains no articulation (no links joined by joints)")
    builder = builders[0]
    builder.set_name(name)
    frictions = {lb.joint_record.name: float(lb.joint_record.friction) for lb in builder.link_builders}
    builder.initial_pose = sapien.Pose()
    art = builder.build(name=name, fix_root_link=fix_root)
    if not scene.gpu_sim_enabled:  # CPU: place the links now, so poses are valid before a step
        art.set_root_pose(builder.initial_pose)

    movable = [j for j in art.active_joints if _joint_type(j) in MOVABLE_TYPES]
    names = [j.name for j in movable]
    if not movable:
        raise ValueError(f"{path} has no movable (revolute/prismatic/continuous) joint")
    for sim_joint in movable:
        friction = frictions.get(sim_joint.name, 0.0)
        if friction > 0:
            sim_joint.set_friction(friction)
    if joint is None:
        chosen = movable[0]
    else:
        matches = [j for j in movable if j.name == joint]
        if not matches:
            raise ValueError(f"joint {joint!r} is not a movable joint of {path}; movable joints: {names}")
        chosen = matches[0]
    info = {
        "joint": chosen.name,
        "joint_type": _joint_type(chosen),
        "movable_joints": names,
        "format": fmt,
        "path": str(path),
    }
    return art, info


def _fmt(values: Any) -> str:
    return " ".join(f"{float(v):.9g}" for v in np.asarray(values, dtype=np.float64).reshape(-1))


def _rpy_from_quat(quat: Any) -> np.ndarray:
    """URDF roll-pitch-yaw (fixed-axis x, y, z) of a (w, x, y, z) quaternion."""
    from capt_env.objects.geometry import quat_to_matrix

    m = quat_to_matrix(quat)
    pitch = np.arcsin(np.clip(-m[2, 0], -1.0, 1.0))
    if abs(np.cos(pitch)) > 1e-9:
        roll = np.arctan2(m[2, 1], m[2, 2])
        yaw = np.arctan2(m[1, 0], m[0, 0])
    else:  # gimbal lock: put everything into yaw
        roll = 0.0
        yaw = np.arctan2(-m[0, 1], m[1, 1])
    return np.array([roll, pitch, yaw])


def spec_to_urdf(spec: ObjectSpec, robot_name: str | None = None) -> str:
    """URDF text of ``spec``: one ``<link>`` per link (box visuals and collisions, inertia from the
    boxes at the link's density) and one ``<joint>`` per joint (origin at the pivot, ``<axis>`` as
    in the spec, limits, damping and friction). Link and joint names are the spec's."""
    name = robot_name or f"{spec.category}_{spec.instance_id}"
    lines = ['<?xml version="1.0"?>', f"<robot name={quoteattr(name)}>"]
    for k, link in enumerate(spec.links):
        lines.append(f"  <link name={quoteattr(link.name)}>")
        mass, com, inertia = _link_inertial(link)
        lines.append("    <inertial>")
        lines.append(f'      <origin xyz="{_fmt(com)}" rpy="0 0 0"/>')
        lines.append(f'      <mass value="{mass:.9g}"/>')
        lines.append(
            f'      <inertia ixx="{inertia[0, 0]:.9g}" ixy="{inertia[0, 1]:.9g}" ixz="{inertia[0, 2]:.9g}" '
            f'iyy="{inertia[1, 1]:.9g}" iyz="{inertia[1, 2]:.9g}" izz="{inertia[2, 2]:.9g}"/>'
        )
        lines.append("    </inertial>")
        for b_idx, box in enumerate(link.boxes):
            origin = f'<origin xyz="{_fmt(box.pos)}" rpy="{_fmt(_rpy_from_quat(box.quat))}"/>'
            size = f'<geometry><box size="{_fmt(np.asarray(box.half_size) * 2)}"/></geometry>'
            lines.append(
                f'    <visual name="{link.name}_box{b_idx}">{origin}{size}'
                f'<material name="m{k}_{b_idx}"><color rgba="{_fmt(box.color)}"/></material>'
                "</visual>"
            )
            lines.append(f'    <collision name="{link.name}_box{b_idx}">{origin}{size}</collision>')
        lines.append("  </link>")
    for joint in spec.joints:
        lines.append(f"  <joint name={quoteattr(joint.name)} type={quoteattr(joint.type)}>")
        lines.append(f"    <parent link={quoteattr(joint.parent)}/>")
        lines.append(f"    <child link={quoteattr(joint.child)}/>")
        lines.append(f'    <origin xyz="{_fmt(joint.origin)}" rpy="0 0 0"/>')
        lines.append(f'    <axis xyz="{_fmt(joint.axis)}"/>')
        lo, hi = joint.limits
        lines.append(f'    <limit lower="{lo:.9g}" upper="{hi:.9g}" effort="1000" velocity="10"/>')
        lines.append(f'    <dynamics damping="{joint.damping:.9g}" friction="{joint.friction:.9g}"/>')
        lines.append("  </joint>")
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def _link_inertial(link: Any) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass (kg), centre of mass (3,) and inertia (3, 3) about the COM of a link's boxes (overlaps
    counted twice, as the simulator does), in the link frame."""
    from capt_env.objects.geometry import quat_to_matrix

    masses, coms, inertias = [], [], []
    for box in link.boxes:
        size = 2 * np.asarray(box.half_size, dtype=np.float64)
        m = link.density * float(np.prod(size))
        local = (
            m
            / 12.0
            * np.diag([size[1] ** 2 + size[2] ** 2, size[0] ** 2 + size[2] ** 2, size[0] ** 2 + size[1] ** 2])
        )
        rot = quat_to_matrix(box.quat)
        masses.append(m)
        coms.append(np.asarray(box.pos, dtype=np.float64))
        inertias.append(rot @ local @ rot.T)
    total = float(sum(masses))
    com = sum(m * c for m, c in zip(masses, coms, strict=True)) / total
    inertia = np.zeros((3, 3))
    for m, c, i_c in zip(masses, coms, inertias, strict=True):
        d = c - com
        inertia += i_c + m * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return total, com, inertia
