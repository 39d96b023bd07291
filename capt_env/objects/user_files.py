"""Load a user's URDF or MJCF articulated object, and write procedural objects as URDF.

Every user file goes through one path: :func:`prepare_object_file` checks it and writes a URDF that
SAPIEN's loader reads as intended (MJCF full models and included fragments converted by
:mod:`capt_env.objects.mjcf_to_urdf`; URDF mesh paths resolved, mimic tags dropped), then
:func:`load_user_object` builds it with ManiSkill's URDF loader, applies the joints' damping and
Coulomb friction in the URDF's units, and picks the joint to open by name (default: the first
movable joint). ``spec_to_urdf`` writes an ``ObjectSpec`` as URDF text (boxes only; URDF joints take an
explicit ``<axis>``, so each joint origin is the pivot without rotation and the axis is written as
is).
"""

from __future__ import annotations

import atexit
import dataclasses
import functools
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
import sapien
from lxml import etree
from mani_skill.utils.structs import Articulation

from capt_env.objects.errors import ObjectFileError
from capt_env.objects.spec import ObjectSpec
from capt_env.objects.urdf_text import format_floats as _fmt

URDF_SUFFIXES = (".urdf",)
MJCF_SUFFIXES = (".xml", ".mjcf")
MOVABLE_TYPES = ("revolute", "revolute_unwrapped", "prismatic", "continuous")
FRICTION_SATURATION_SPEED = 0.05
"""rad/s or m/s at which the Coulomb-friction drive reaches its full force (see ``apply_joint_dynamics``)."""
FRICTION_MAX_SPEED = 1.0
"""rad/s or m/s up to which a joint's viscous damping adds to its friction force."""


@dataclass(frozen=True)
class PreparedFile:
    """A user file rewritten as a URDF that SAPIEN's loader reads as intended.

    ``urdf_path`` has absolute mesh paths, no mimic tags and zero ``<dynamics friction>``;
    ``friction`` keeps the file's Coulomb friction per joint (N m or N) to apply as a drive;
    ``warnings`` lists what was ignored or approximated.
    """

    source: Path
    urdf_path: Path
    format: str  # "urdf" or "mjcf"
    friction: dict[str, float]
    warnings: tuple[str, ...]


def _joint_type(joint: Any) -> str:
    jtype = joint.type
    return jtype[0] if isinstance(jtype, (list, tuple)) else str(jtype)


def _cache_dir(path: Path) -> Path:
    """A fresh folder for this process's rewritten copy of ``path`` (removed at exit)."""
    out = Path(tempfile.mkdtemp(prefix=f"capt_{path.stem}_"))
    atexit.register(shutil.rmtree, out, True)
    return out


def parse_xml(path: Path) -> etree._ElementTree:
    """Parse an XML file; a malformed one raises :class:`ObjectFileError` naming the file and line."""
    try:
        return etree.parse(str(path), etree.XMLParser(remove_comments=True))
    except etree.XMLSyntaxError as exc:
        raise ObjectFileError(f"{path}: malformed XML at line {exc.lineno}: {exc.msg}") from None
    except OSError as exc:
        raise ObjectFileError(f"{path}: cannot read: {exc}") from None


def resolve_mesh_path(filename: str, urdf_path: Path) -> tuple[Path | None, list[Path]]:
    """Find a URDF mesh reference on disk: relative to the URDF's folder, ``file://`` absolute, or
    ``package://PKG/rest`` searched as ``PKG/rest`` and ``rest`` in the URDF's folder and each folder
    above it (a ROS package's layout without ROS). Returns the path (None if not found) and the
    folders searched."""
    base = urdf_path.resolve().parent
    if filename.startswith("file://"):
        filename = filename[len("file://"):]
    if filename.startswith("package://"):
        rest = filename[len("package://"):]
        tails = [Path(rest), Path(*Path(rest).parts[1:])] if len(Path(rest).parts) > 1 else [Path(rest)]
        folders = [base, *base.parents]
        for folder in folders:
            for tail in tails:
                if (folder / tail).is_file():
                    return folder / tail, folders
        return None, folders
    candidate = Path(filename)
    if not candidate.is_absolute():
        candidate = base / candidate
    return (candidate if candidate.is_file() else None), [candidate.parent]


def prepare_urdf(path: Path, out_dir: Path) -> PreparedFile:
    """Check and rewrite a URDF for SAPIEN: mesh paths made absolute (a missing one is an error
    naming the URDF, the link and the folders searched), mimic tags dropped with a warning (the
    task drives one joint; mimicked joints then move freely), ``<dynamics friction>`` moved out of
    the file (SAPIEN reads it as a friction coefficient; the URDF means a force or torque)."""
    tree = parse_xml(path)
    root = tree.getroot()
    if root.tag != "robot":
        raise ObjectFileError(f"{path}: the root element is <{root.tag}>, a URDF needs <robot>")
    warnings: list[str] = []
    links = {link.get("name") for link in root.iter("link")}
    for link in root.iter("link"):
        name = link.get("name")
        if not name:
            raise ObjectFileError(f"{path}: a <link> has no name")
        for mesh in link.iter("mesh"):
            ref = mesh.get("filename")
            if not ref:
                raise ObjectFileError(f"{path}: link {name!r}: a <mesh> has no filename")
            found, folders = resolve_mesh_path(ref, path)
            if found is None:
                where = ", ".join(str(f) for f in folders[:4]) + (", ..." if len(folders) > 4 else "")
                raise ObjectFileError(f"{path}: link {name!r}: mesh {ref!r} not found (looked in {where})")
            mesh.set("filename", str(found))
    friction: dict[str, float] = {}
    for joint in root.iter("joint"):
        name = joint.get("name") or "?"
        for tag in ("parent", "child"):
            elem = joint.find(tag)
            if elem is None or elem.get("link") not in links:
                ref = None if elem is None else elem.get("link")
                raise ObjectFileError(
                    f"{path}: joint {name!r}: {tag} link {ref!r} is not a <link> of the file")
        mimic = joint.find("mimic")
        if mimic is not None:
            joint.remove(mimic)
            warnings.append(f"joint {name!r}: <mimic> ignored (it moves on its own)")
        dyn = joint.find("dynamics")
        if dyn is not None and dyn.get("friction") is not None:
            try:
                friction[name] = float(dyn.get("friction"))
            except ValueError:
                raise ObjectFileError(
                    f"{path}: joint {name!r}: friction {dyn.get('friction')!r} is not a number") from None
            dyn.set("friction", "0")
    out_dir.mkdir(parents=True, exist_ok=True)
    out = out_dir / f"{path.stem}.urdf"
    tree.write(str(out), xml_declaration=True, encoding="utf-8")
    return PreparedFile(source=path, urdf_path=out, format="urdf", friction=friction,
                        warnings=tuple(warnings))


@functools.lru_cache(maxsize=64)
def _prepare_cached(path: str, mtime_ns: int, visual_groups: tuple[int, ...], mjcf_angle: str,
                    density: float | None) -> PreparedFile:
    src = Path(path)
    out_dir = _cache_dir(src)
    suffix = src.suffix.lower()
    if suffix in URDF_SUFFIXES:
        return prepare_urdf(src, out_dir)
    from capt_env.objects.mjcf_to_urdf import convert_mjcf

    conv = convert_mjcf(src, out_dir, visual_groups=visual_groups, angle=mjcf_angle,
                        **({} if density is None else {"density": density}))
    prepared = prepare_urdf(conv.urdf_path, out_dir / "prepared")
    return PreparedFile(source=src, urdf_path=prepared.urdf_path, format="mjcf", friction=prepared.friction,
                        warnings=tuple(conv.warnings) + prepared.warnings)


def prepare_object_file(path: str | Path, visual_groups: tuple[int, ...] = (0, 1, 2),
                        mjcf_angle: str = "auto", density: float | None = None) -> PreparedFile:
    """Check a URDF (``.urdf``) or MJCF (``.xml``/``.mjcf``, full model or included fragment) file
    and write the URDF the simulator loads (once per process, file version and options). ``density``
    (kg/m^3) is an MJCF file's density for geoms without a mass (a URDF's is set at loading).

    :raises FileNotFoundError: if ``path`` does not exist.
    :raises ObjectFileError: for an unsupported suffix or a file that cannot be loaded (the message
        names the file and the element at fault).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"object file not found: {path}")
    if path.suffix.lower() not in URDF_SUFFIXES + MJCF_SUFFIXES:
        raise ObjectFileError(
            f"unsupported object file {path}: suffix {path.suffix!r}; expected one of "
            f"{list(URDF_SUFFIXES + MJCF_SUFFIXES)}"
        )
    prepared = _prepare_cached(str(path.resolve()), path.stat().st_mtime_ns, tuple(visual_groups), mjcf_angle,
                               density)
    return dataclasses.replace(prepared, source=path)


def apply_joint_dynamics(joint: Any, damping: float, friction: float) -> None:
    """Give a joint viscous damping ``damping`` (N m s/rad or N s/m) and Coulomb friction
    ``friction`` (N m or N), the URDF's meanings.

    PhysX articulations have no Coulomb joint friction in these units (their joint friction is a
    coefficient on the joint's constraint force), so both go into one velocity drive towards 0:
    its damping is ``max(damping, friction / FRICTION_SATURATION_SPEED)`` and its force is capped at
    ``friction + damping * FRICTION_MAX_SPEED``. Below the saturation speed the joint resists like a
    stiff damper, above it with a nearly constant force, as a sticking then sliding joint does.
    """
    if friction <= 0:
        joint.set_drive_properties(stiffness=0.0, damping=float(damping))
        return
    drive_damping = max(float(damping), float(friction) / FRICTION_SATURATION_SPEED)
    joint.set_drive_properties(stiffness=0.0, damping=drive_damping,
                               force_limit=float(friction + damping * FRICTION_MAX_SPEED))
    joint.set_drive_velocity_target(0.0)


def load_user_object(
    scene: Any,
    path: str | Path,
    joint: str | None = None,
    scale: float = 1.0,
    name: str = "user_object",
    fix_root: bool = True,
    *,
    visual_groups: tuple[int, ...] = (0, 1, 2),
    mjcf_angle: str = "auto",
    density: float | None = None,
    joint_damping: float | None = None,
    joint_friction: float | None = None,
) -> tuple[Articulation, dict[str, Any]]:
    """Build a URDF or MJCF file into ``scene`` (see :func:`prepare_object_file`).

    :param joint: name of the joint to open (exact name as in the file); default: the first movable
        joint in the articulation's order.
    :param scale: uniform scale of all lengths.
    :param density: kg/m^3 for links whose file gives no inertial (default: SAPIEN's 1000).
    :param joint_damping: replaces every movable joint's damping (N m s/rad or N s/m).
    :param joint_friction: replaces every movable joint's Coulomb friction (N m or N).
    :returns: the articulation and ``info`` with keys ``joint`` (chosen joint name), ``joint_type``
        ("revolute"/"prismatic"/...), ``movable_joints`` (names, in qpos order), ``format``
        ("urdf"/"mjcf"), ``path`` and ``warnings``.
    :raises FileNotFoundError: if ``path`` does not exist.
    :raises ObjectFileError: for a file that cannot be loaded, a file without a movable joint, or an
        unknown ``joint`` (the message lists the movable joints).
    """
    path = Path(path)
    prepared = prepare_object_file(path, visual_groups=visual_groups, mjcf_angle=mjcf_angle, density=density)
    loader = scene.create_urdf_loader()
    loader.name = name
    loader.scale = scale
    loader.fix_root_link = fix_root
    if density is not None:
        loader.set_density(float(density))
    try:
        parsed = loader.parse(str(prepared.urdf_path))
    except Exception as exc:  # SAPIEN's parser raises bare errors without the file name
        raise ObjectFileError(f"{path}: {type(exc).__name__}: {exc}") from exc
    builders = parsed["articulation_builders"]
    if not builders:
        raise ObjectFileError(f"{path} contains no articulation (no links joined by joints)")
    builder = builders[0]
    builder.set_name(name)
    dampings = {lb.joint_record.name: float(lb.joint_record.damping) for lb in builder.link_builders}
    builder.initial_pose = sapien.Pose()
    try:
        art = builder.build(name=name, fix_root_link=fix_root)
    except Exception as exc:
        raise ObjectFileError(f"{path}: the simulator cannot build it: {type(exc).__name__}: {exc}") from exc
    if not scene.gpu_sim_enabled:  # CPU: place the links now, so poses are valid before a step
        art.set_root_pose(builder.initial_pose)

    movable = [j for j in art.active_joints if _joint_type(j) in MOVABLE_TYPES]
    names = [j.name for j in movable]
    if not movable:
        raise ObjectFileError(f"{path} has no movable (revolute/prismatic/continuous) joint")
    for sim_joint in movable:
        file_name = _file_joint_name(sim_joint.name, prepared.friction, dampings)
        damping = joint_damping if joint_damping is not None else dampings.get(file_name, 0.0)
        friction = joint_friction if joint_friction is not None else prepared.friction.get(file_name, 0.0)
        apply_joint_dynamics(sim_joint, damping, friction)
    if joint is None:
        chosen = movable[0]
    else:
        matches = [j for j in movable if j.name == joint or j.name.endswith(joint)]
        if not matches:
            raise ObjectFileError(
                f"joint {joint!r} is not a movable joint of {path}; movable joints: {names}")
        chosen = matches[0]
    info = {
        "joint": chosen.name,
        "joint_type": _joint_type(chosen),
        "movable_joints": names,
        "format": prepared.format,
        "path": str(path),
        "warnings": list(prepared.warnings),
    }
    return art, info


def _file_joint_name(sim_name: str, *tables: dict[str, float]) -> str:
    """The file's name of a built joint (ManiSkill may prefix names with the articulation's)."""
    for table in tables:
        for file_name in table:
            if sim_name == file_name or sim_name.endswith(file_name):
                return file_name
    return sim_name


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
    in the spec, limits, damping and friction). Link and joint names are the spec's.

    A spec's link frames all coincide at state 0, while a URDF child frame sits at its joint's
    origin, so each link's geometry is written relative to its own joint's pivot (object frame
    offsets; every frame keeps the object frame's orientation). Specs with varied geometry (cylinders,
    convex meshes) are refused."""
    if any(link.shapes for link in spec.links):
        raise ValueError(f"{spec.category} #{spec.instance_id} has non-box shapes (varied geometry); "
                         "spec_to_urdf writes boxes only")
    name = robot_name or f"{spec.category}_{spec.instance_id}"
    offset = {spec.links[0].name: np.zeros(3)}
    offset.update({j.child: np.asarray(j.origin, dtype=np.float64) for j in spec.joints})
    lines = ['<?xml version="1.0"?>', f"<robot name={quoteattr(name)}>"]
    for k, link in enumerate(spec.links):
        shift = offset.get(link.name, np.zeros(3))
        lines.append(f"  <link name={quoteattr(link.name)}>")
        mass, com, inertia = _link_inertial(link)
        lines.append("    <inertial>")
        lines.append(f'      <origin xyz="{_fmt(com - shift)}" rpy="0 0 0"/>')
        lines.append(f'      <mass value="{mass:.9g}"/>')
        lines.append(
            f'      <inertia ixx="{inertia[0, 0]:.9g}" ixy="{inertia[0, 1]:.9g}" ixz="{inertia[0, 2]:.9g}" '
            f'iyy="{inertia[1, 1]:.9g}" iyz="{inertia[1, 2]:.9g}" izz="{inertia[2, 2]:.9g}"/>'
        )
        lines.append("    </inertial>")
        for b_idx, box in enumerate(link.boxes):
            rpy = _fmt(_rpy_from_quat(box.quat))
            origin = f'<origin xyz="{_fmt(np.asarray(box.pos) - shift)}" rpy="{rpy}"/>'
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
        rel = offset[joint.child] - offset.get(joint.parent, np.zeros(3))
        lines.append(f'    <origin xyz="{_fmt(rel)}" rpy="0 0 0"/>')
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
