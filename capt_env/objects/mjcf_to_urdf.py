"""Convert a MuJoCo MJCF articulated object (full model or included fragment) into a URDF.

Written by hand because ManiSkill's MJCF loader covers only part of MJCF's semantics (it needs a
``worldbody``, named bodies, draws only geom group 0 and reads ``compiler angle`` as degrees when a
fragment meant for a radian scene omits it), and because no maintained MJCF-to-URDF converter is a
dependency here. What is converted:

- ``<include>`` (recursively, relative to the including file) and, for a fragment (no ``<mujoco>``
  root or no ``<worldbody>``), its sibling ``X_dependencies.xml`` (Meta-World) or ``X_asset.xml``
  (Franka Kitchen) whose ``X`` is the longest prefix of the fragment's stem (assets, materials,
  default classes, compiler; :func:`dependencies_file`);
- ``<compiler angle meshdir eulerseq autolimits>``; ``<default>`` classes with nesting, ``class``
  and ``childclass`` inheritance;
- body and geom frames (``pos``, ``quat``, ``euler``, ``axisangle``, ``xyaxes``, ``zaxis``, geom
  ``fromto``); hinge -> revolute (continuous when unlimited), slide -> prismatic, several joints in
  one body -> a chain of frame links; free and ball joints are dropped (the root is fixed);
- geoms box/sphere/cylinder/capsule/mesh as they are (mesh ``scale`` too), ellipsoids as meshes
  (approximated), planes dropped; a geom is visual when its ``group`` is in ``visual_groups``
  and collides when its ``contype`` or ``conaffinity`` is non-zero;
- inertia from ``<inertial>``, else from the collision geoms (their ``mass``, else ``density``);
  joint ``damping`` and ``frictionloss`` (written as URDF ``friction``, a force or torque).

A mesh geom is drawn where its file's vertices lie in the geom frame: MuJoCo re-centres meshes on
their inertial frame internally but moves the geom by the same amount, so the result is unchanged.
Every failure is an :class:`ObjectFileError` naming the file and the element.
"""

from __future__ import annotations

import copy
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
import trimesh
from lxml import etree
from scipy.spatial.transform import Rotation

from capt_env.objects.errors import ObjectFileError
from capt_env.objects.urdf_text import format_floats as _fmt

DEFAULT_DENSITY = 1000.0
MIN_MASS = 1e-3  # kg, for a body without geometry (a frame for a latch or a handle)
MIN_INERTIA = 1e-6  # kg m^2
_INERTIA_TERMS = {"xx": (0, 0), "xy": (0, 1), "xz": (0, 2), "yy": (1, 1), "yz": (1, 2), "zz": (2, 2)}


@dataclass(frozen=True)
class MjcfConversion:
    """A written URDF and what the conversion approximated or ignored."""

    urdf_path: Path
    warnings: list[str]
    joint_names: list[str]  # movable joints written, in file order
    angle: str  # "radian" or "degree": the unit used for hinge ranges and Euler angles


@dataclass
class _Model:
    """The merged MJCF: bodies, assets, defaults and compiler settings."""

    path: Path
    compiler: dict[str, str] = field(default_factory=dict)
    defaults: dict[str, dict[str, dict[str, str]]] = field(default_factory=dict)
    meshes: dict[str, tuple[Path, np.ndarray]] = field(default_factory=dict)
    materials: dict[str, str] = field(default_factory=dict)  # name -> rgba
    roots: list[etree._Element] = field(default_factory=list)  # worldbody-level elements
    is_fragment: bool = False
    angle: str = "degree"
    warnings: list[str] = field(default_factory=list)


def _parse(path: Path) -> etree._Element:
    from capt_env.objects.user_files import parse_xml

    return parse_xml(path).getroot()


def _floats(text: str | None, where: str, n: int | None = None) -> np.ndarray:
    try:
        values = np.array([float(v) for v in (text or "").split()], dtype=np.float64)
    except ValueError:
        raise ObjectFileError(f"{where}: {text!r} is not a list of numbers") from None
    if n is not None and len(values) < n:
        raise ObjectFileError(f"{where}: needs {n} numbers, got {text!r}")
    return values


def _expand_includes(elem: etree._Element, base: Path, source: Path, seen: tuple[Path, ...]) -> None:
    """Replace every ``<include file>`` under ``elem`` by the included file's children, in place."""
    for inc in list(elem.iter("include")):
        ref = inc.get("file")
        target = (base / ref).resolve() if ref else None
        if target is None or not target.is_file():
            raise ObjectFileError(f"{source}: <include file={ref!r}> not found (looked in {base})")
        if target in seen:
            raise ObjectFileError(f"{source}: <include file={ref!r}> includes itself")
        sub = _parse(target)
        _expand_includes(sub, target.parent, target, (*seen, target))
        _tag_sources(sub, target)
        parent = inc.getparent()
        index = parent.index(inc)
        parent.remove(inc)
        for k, child in enumerate(list(sub)):
            parent.insert(index + k, child)


def _tag_sources(elem: etree._Element, source: Path) -> None:
    for node in elem.iter():
        if isinstance(node.tag, str) and node.get("_source") is None:
            node.set("_source", str(source))


DEFINITION_SUFFIXES = ("dependencies", "asset", "assets", "deps", "defaults")
"""Last name parts of a sibling file that holds a fragment's definitions: Meta-World's
``drawer_dependencies.xml`` beside ``drawer.xml``, Franka Kitchen's (adept_models)
``microwave_asset.xml`` beside ``microwave_chain.xml``."""


def dependencies_file(fragment: Path) -> Path | None:
    """The sibling that holds a fragment's assets and classes: ``X_<suffix>.xml`` (a suffix of
    :data:`DEFINITION_SUFFIXES`) whose ``X`` is the longest prefix of the fragment's stem, or None.
    A fragment's bodies name classes and meshes its project defines once per object in such a file
    and includes both into one scene; the file is found by the object's name they share."""
    best, best_len = None, 0
    for cand in fragment.parent.glob("*_*.xml"):
        prefix, _, suffix = cand.stem.rpartition("_")
        if suffix.lower() not in DEFINITION_SUFFIXES or cand == fragment:
            continue
        if prefix and fragment.stem.startswith(prefix) and len(prefix) > best_len:
            best, best_len = cand, len(prefix)
    return best


def _read_defaults(elem: etree._Element, parent: str | None, out: dict) -> None:
    name = elem.get("class") or ("main" if parent is None else None)
    if name is None:
        raise ObjectFileError(
            f"{elem.get('_source')}: a nested <default> needs a class (line {elem.sourceline})")
    inherited = copy.deepcopy(out.get(parent, {})) if parent else {}
    for child in elem:
        if not isinstance(child.tag, str):
            continue
        if child.tag == "default":
            continue
        inherited.setdefault(child.tag, {}).update({k: v for k, v in child.attrib.items() if k != "_source"})
    out[name] = inherited
    for child in elem:
        if isinstance(child.tag, str) and child.tag == "default":
            _read_defaults(child, name, out)


def _load_model(path: Path) -> _Model:
    root = _parse(path)
    _tag_sources(root, path)
    _expand_includes(root, path.parent, path, (path.resolve(),))
    model = _Model(path=path)
    sections = [root]
    worldbodies = root.findall("worldbody")
    if root.tag != "mujoco" or not worldbodies:
        model.is_fragment = True
        deps = dependencies_file(path)
        if deps is not None:
            dep_root = _parse(deps)
            _tag_sources(dep_root, deps)
            _expand_includes(dep_root, deps.parent, deps, (deps.resolve(),))
            sections.insert(0, dep_root)
    for section in sections:
        for comp in section.findall("compiler"):
            model.compiler.update({k: v for k, v in comp.attrib.items() if k != "_source"})
        for default in section.findall("default"):
            _read_defaults(default, None, model.defaults)
    for section in sections:
        for asset in section.findall("asset"):
            _read_assets(asset, model)
    if worldbodies:
        model.roots = [child for wb in worldbodies for child in wb]
    else:
        model.roots = [c for c in root if isinstance(c.tag, str) and c.tag in ("body", "geom")]
    if not model.roots:
        raise ObjectFileError(f"{path}: no <worldbody> and no top-level <body> to convert")
    return model


def _mesh_dirs(model: _Model, source: Path) -> list[Path]:
    meshdir = model.compiler.get("meshdir", "")
    bases = [model.path.parent, source.parent]
    dirs = []
    for base in bases:
        for up in (base, *list(base.parents)[:3]):
            dirs.append(up / meshdir if meshdir else up)
    return list(dict.fromkeys(dirs))


def _read_assets(asset: etree._Element, model: _Model) -> None:
    for mesh in asset.findall("mesh"):
        source = Path(mesh.get("_source") or model.path)
        file = mesh.get("file")
        if not file:
            raise ObjectFileError(
                f"{source}: <mesh name={mesh.get('name')!r}> has no file (line {mesh.sourceline})")
        name = mesh.get("name") or Path(file).stem
        attrs = {**model.defaults.get(mesh.get("class") or "main", {}).get("mesh", {}), **mesh.attrib}
        scale = _floats(attrs.get("scale", "1 1 1"), f"{source}: mesh {name!r} scale", 3)[:3]
        found = next((d / file for d in _mesh_dirs(model, source) if (d / file).is_file()), None)
        if found is None:
            looked = ", ".join(str(d) for d in _mesh_dirs(model, source)[:4])
            raise ObjectFileError(
                f"{source}: mesh {name!r}: file {file!r} not found (looked in {looked}, ...)")
        model.meshes[name] = (found.resolve(), scale)
    for material in asset.findall("material"):
        if material.get("name"):
            model.materials[material.get("name")] = material.get("rgba", "0.7 0.7 0.7 1")


def _angle_unit(model: _Model, requested: str) -> str:
    """The unit of the model's hinge ranges and Euler angles: ``requested`` unless ``auto``, else the
    compiler's. Without one, MuJoCo reads a full model in degrees; but a hinge whose range lies within
    +-2 pi would then turn under 6.3 deg, which opens nothing: such files come from scenes that set
    radians (Meta-World's fragments, robosuite's objects), so every hinge range within +-2 pi reads
    as radians (a fragment with no ranges too), with a warning."""
    if requested in ("radian", "degree"):
        return requested
    if "angle" in model.compiler:
        return model.compiler["angle"]
    ranges = [_floats(j.get("range"), "range") for r in model.roots for j in r.iter("joint")
              if j.get("range") and j.get("type", "hinge") == "hinge"]
    small = all(np.all(np.abs(r) <= 2 * np.pi + 1e-6) for r in ranges)
    if not model.is_fragment and (not ranges or not small):
        return "degree"  # MuJoCo's default for a full model
    unit = "radian" if small else "degree"
    scene = "an included fragment of a radian scene" if model.is_fragment else (
        "a full model whose hinge ranges, in degrees, would open nothing: written for a radian scene")
    model.warnings.append(f"{model.path.name} sets no compiler angle; assumed {unit}s ({scene}); set "
                          "mjcf_angle to override")
    return unit


class _Converter:
    def __init__(self, model: _Model, out_dir: Path, visual_groups: tuple[int, ...], density: float) -> None:
        self.m = model
        self.out_dir = out_dir
        self.visual_groups = set(visual_groups)
        self.density = density
        self.names: set[str] = set()
        self.movable: list[str] = []
        self.counter = 0
        self.unnamed = 0

    # ---------------------------------------------------------------- helpers
    def attrs(self, elem: etree._Element, childclass: str | None) -> dict[str, str]:
        cls = elem.get("class") or childclass or "main"
        if cls not in self.m.defaults and cls != "main":
            raise ObjectFileError(f"{elem.get('_source')}: <{elem.tag}> uses unknown class {cls!r} "
                                  f"(line {elem.sourceline})")
        base = self.m.defaults.get(cls, {}).get(elem.tag, {})
        return {**base, **{k: v for k, v in elem.attrib.items() if k not in ("_source", "class")}}

    def where(self, elem: etree._Element) -> str:
        name = elem.get("name")
        label = f" name={name!r}" if name else ""
        return f"{elem.get('_source')}: <{elem.tag}{label}> (line {elem.sourceline})"

    def rotation(self, a: dict[str, str], where: str) -> np.ndarray:
        """The rotation matrix of an element's orientation attributes."""
        deg = self.m.angle == "degree"
        if "quat" in a:
            w, x, y, z = _floats(a["quat"], where, 4)[:4]
            return Rotation.from_quat([x, y, z, w]).as_matrix()
        if "euler" in a:
            seq = self.m.compiler.get("eulerseq", "xyz")
            scipy_seq = seq.swapcase()  # MuJoCo: lower case rotates with the frame; scipy: upper case
            return Rotation.from_euler(scipy_seq, _floats(a["euler"], where, 3)[:3], degrees=deg).as_matrix()
        if "axisangle" in a:
            v = _floats(a["axisangle"], where, 4)
            angle = np.radians(v[3]) if deg else v[3]
            return Rotation.from_rotvec(v[:3] / max(np.linalg.norm(v[:3]), 1e-12) * angle).as_matrix()
        if "xyaxes" in a:
            v = _floats(a["xyaxes"], where, 6)
            x = v[:3] / np.linalg.norm(v[:3])
            y = v[3:6] - (v[3:6] @ x) * x
            y /= np.linalg.norm(y)
            return np.stack([x, y, np.cross(x, y)], axis=1)
        if "zaxis" in a:
            return _rotation_z_to(_floats(a["zaxis"], where, 3)[:3])
        return np.eye(3)

    def frame(self, a: dict[str, str], where: str) -> np.ndarray:
        mat = np.eye(4)
        mat[:3, :3] = self.rotation(a, where)
        mat[:3, 3] = _floats(a.get("pos", "0 0 0"), where, 3)[:3]
        return mat

    def unique(self, name: str) -> str:
        out, k = name, 1
        while out in self.names:
            out, k = f"{name}_{k}", k + 1
        self.names.add(out)
        return out

    # ---------------------------------------------------------------- geoms
    def geom(self, elem: etree._Element, childclass: str | None, to_link: np.ndarray,
             body_mass: list) -> tuple[list[str], list[str]]:
        """URDF ``<visual>``/``<collision>`` lines of one geom; its mass record goes to ``body_mass``."""
        a = self.attrs(elem, childclass)
        where = self.where(elem)
        gtype = a.get("type", "sphere")
        local = self.frame(a, where)
        size = _floats(a.get("size", "0.005"), where)
        if "fromto" in a and gtype in ("capsule", "cylinder", "box", "ellipsoid"):
            ft = _floats(a["fromto"], where, 6)
            start, end = ft[:3], ft[3:6]
            local = np.eye(4)
            local[:3, :3] = _rotation_z_to(end - start)
            local[:3, 3] = (start + end) / 2
            size = np.array([size[0], np.linalg.norm(end - start) / 2, *size[1:2]])
        pose = to_link @ local
        shape = self.shape(gtype, size, a, where)
        if shape is None:
            return [], []
        name = elem.get("name") or ""
        vis, col = [], []
        origin = _origin(pose)
        group = int(float(a.get("group", "0")))
        if group in self.visual_groups:
            rgba = a.get("rgba") or self.m.materials.get(a.get("material", ""), "0.7 0.7 0.7 1")
            mat = self.unique(f"mat_{name or 'geom'}")
            vis.append(f"    <visual name={quoteattr(name)}>{origin}<geometry>{shape[0]}</geometry>"
                       f"<material name={quoteattr(mat)}><color rgba={quoteattr(rgba)}/></material></visual>")
        if int(float(a.get("contype", "1"))) or int(float(a.get("conaffinity", "1"))):
            col.append(f"    <collision name={quoteattr(name)}>{origin}<geometry>{shape[0]}</geometry>"
                       "</collision>")
            volume, inertia_unit = shape[1], shape[2]
            mass = float(a["mass"]) if "mass" in a else float(a.get("density", self.density)) * volume
            body_mass.append((mass, pose, inertia_unit))
        return vis, col

    def shape(self, gtype: str, size: np.ndarray, a: dict[str, str],
              where: str) -> tuple[str, float, np.ndarray] | None:
        """URDF geometry text, volume (m^3) and inertia per unit mass about the geom frame (3x3)."""
        if gtype == "box":
            half = np.resize(size, 3)
            mesh = trimesh.creation.box(extents=2 * half)
            return f'<box size="{_fmt(2 * half)}"/>', float(np.prod(2 * half)), _unit_inertia(mesh)
        if gtype == "sphere":
            mesh = trimesh.creation.icosphere(radius=size[0], subdivisions=2)
            return f'<sphere radius="{size[0]:.9g}"/>', 4 / 3 * np.pi * size[0] ** 3, _unit_inertia(mesh)
        if gtype in ("cylinder", "capsule"):
            radius, half = size[0], (size[1] if len(size) > 1 else size[0])
            if gtype == "cylinder":
                mesh = trimesh.creation.cylinder(radius=radius, height=2 * half)
                text = f'<cylinder radius="{radius:.9g}" length="{2 * half:.9g}"/>'
            else:
                mesh = trimesh.creation.capsule(radius=radius, height=2 * half)
                text = f'<capsule radius="{radius:.9g}" length="{2 * half:.9g}"/>'
            return text, float(mesh.volume), _unit_inertia(mesh)
        if gtype == "ellipsoid":
            radii = np.resize(size, 3)
            mesh = trimesh.creation.icosphere(subdivisions=3)
            mesh.apply_scale(radii)
            path = self.out_dir / f"ellipsoid_{self.counter}.obj"
            self.counter += 1
            mesh.export(path)
            self.m.warnings.append(f"{where}: ellipsoid written as a triangle mesh (SAPIEN has no ellipsoid)")
            return f'<mesh filename={quoteattr(str(path))}/>', float(mesh.volume), _unit_inertia(mesh)
        if gtype == "mesh":
            name = a.get("mesh")
            if name not in self.m.meshes:
                raise ObjectFileError(f"{where}: mesh {name!r} is not an <asset> <mesh> of the file")
            file, scale = self.m.meshes[name]
            mesh = trimesh.load(file, force="mesh")
            mesh.apply_scale(scale)
            hull = mesh if mesh.is_volume else mesh.convex_hull
            return (f'<mesh filename={quoteattr(str(file))} scale="{_fmt(scale)}"/>', float(abs(hull.volume)),
                    _unit_inertia(hull))
        if gtype in ("plane", "hfield", "sdf"):
            self.m.warnings.append(f"{where}: {gtype} geom dropped")
            return None
        raise ObjectFileError(f"{where}: unknown geom type {gtype!r}")

    # ---------------------------------------------------------------- bodies
    def body(self, elem: etree._Element, parent_link: str, parent_abs: np.ndarray,
             body_abs_parent: np.ndarray, childclass: str | None, lines: list[str]) -> None:
        """Write one body (its links and joints), then its children. ``parent_abs`` is the parent
        link's frame and ``body_abs_parent`` the parent body's frame, both in the root frame."""
        a = self.attrs(elem, childclass)
        where = self.where(elem)
        cls = elem.get("childclass") or childclass
        body_abs = body_abs_parent @ self.frame(a, where)
        if elem.get("name"):
            base_name = elem.get("name")
        else:
            base_name, self.unnamed = f"body{self.unnamed}", self.unnamed + 1
        joints = [j for j in elem if isinstance(j.tag, str) and j.tag in ("joint", "freejoint")]
        link_abs, link_name, prev = body_abs, None, parent_link
        prev_abs = parent_abs
        movable = []
        for joint in joints:
            ja = self.attrs(joint, cls)
            jtype = "free" if joint.tag == "freejoint" else ja.get("type", "hinge")
            if jtype in ("free", "ball"):
                self.m.warnings.append(f"{self.where(joint)}: {jtype} joint dropped (the root is fixed)")
                continue
            movable.append((joint, ja, jtype))
        if not movable:
            link_name = self.unique(base_name)
            self.write_joint(lines, self.unique(f"{link_name}_fixed"), "fixed", prev, link_name,
                             np.linalg.inv(prev_abs) @ body_abs)
        for k, (joint, ja, jtype) in enumerate(movable):
            jpos = _floats(ja.get("pos", "0 0 0"), self.where(joint), 3)[:3]
            shift = np.eye(4)
            shift[:3, 3] = jpos
            link_abs = body_abs @ shift
            last = k == len(movable) - 1
            link_name = self.unique(base_name if last else f"{base_name}_frame{k}")
            if not last:
                self.write_link(lines, link_name, [], [], [])
            jname = self.unique(joint.get("name") or f"{base_name}_joint{k}")
            self.write_movable(lines, joint, ja, jtype, jname, prev, link_name,
                               np.linalg.inv(prev_abs) @ link_abs)
            prev, prev_abs = link_name, link_abs
        to_link = np.linalg.inv(link_abs) @ body_abs
        vis, col, masses = [], [], []
        for child in elem:
            if isinstance(child.tag, str) and child.tag == "geom":
                v, c = self.geom(child, cls, to_link, masses)
                vis += v
                col += c
        inertial = next((c for c in elem if isinstance(c.tag, str) and c.tag == "inertial"), None)
        self.write_link(lines, link_name, vis, col, masses, inertial, to_link)
        for child in elem:
            if isinstance(child.tag, str) and child.tag == "body":
                self.body(child, link_name, link_abs, body_abs, cls, lines)

    def write_joint(self, lines: list[str], name: str, jtype: str, parent: str, child: str,
                    origin: np.ndarray, extra: str = "") -> None:
        lines.append(f"  <joint name={quoteattr(name)} type={quoteattr(jtype)}>"
                     f"<parent link={quoteattr(parent)}/><child link={quoteattr(child)}/>"
                     f"{_origin(origin)}{extra}</joint>")

    def write_movable(self, lines: list[str], joint: etree._Element, ja: dict[str, str], jtype: str,
                      name: str, parent: str, child: str, origin: np.ndarray) -> None:
        where = self.where(joint)
        axis = _floats(ja.get("axis", "0 0 1"), where, 3)[:3]
        if np.linalg.norm(axis) < 1e-9:
            raise ObjectFileError(f"{where}: zero axis")
        axis = axis / np.linalg.norm(axis)
        limited = ja.get("limited", "auto")
        has_range = "range" in ja
        if limited == "auto":
            limited = "true" if has_range and self.m.compiler.get("autolimits", "true") == "true" else "false"
        urdf_type = "revolute" if jtype == "hinge" else "prismatic"
        extra = f'<axis xyz="{_fmt(axis)}"/>'
        if limited == "true" and has_range:
            lo, hi = _floats(ja["range"], where, 2)[:2]
            if jtype == "hinge" and self.m.angle == "degree":
                lo, hi = np.radians(lo), np.radians(hi)
            extra += f'<limit lower="{lo:.9g}" upper="{hi:.9g}" effort="1000" velocity="10"/>'
        elif jtype == "hinge":
            urdf_type = "continuous"
            extra += '<limit effort="1000" velocity="10"/>'
        else:
            raise ObjectFileError(f"{where}: a slide joint needs a range")
        damping = float(ja.get("damping", "0"))
        friction = float(ja.get("frictionloss", "0"))
        extra += f'<dynamics damping="{damping:.9g}" friction="{friction:.9g}"/>'
        self.movable.append(name)
        self.write_joint(lines, name, urdf_type, parent, child, origin, extra)

    def write_link(self, lines: list[str], name: str, vis: list[str], col: list[str], masses: list,
                   inertial: etree._Element | None = None, to_link: np.ndarray | None = None) -> None:
        mass, com, inertia = _inertial(masses, inertial, to_link, self)
        lines.append(f"  <link name={quoteattr(name)}>")
        terms = " ".join(f'i{a}="{inertia[i, j]:.9g}"' for a, (i, j) in _INERTIA_TERMS.items())
        lines.append(f'    <inertial>{_origin_xyz(com)}<mass value="{mass:.9g}"/>'
                     f"<inertia {terms}/></inertial>")
        lines += vis + col
        lines.append("  </link>")


def _rotation_z_to(direction: np.ndarray) -> np.ndarray:
    """A rotation taking +z onto ``direction`` (the shortest one)."""
    z = np.asarray(direction, dtype=np.float64)
    z = z / max(np.linalg.norm(z), 1e-12)
    rot, _ = Rotation.align_vectors([z], [[0.0, 0.0, 1.0]])
    return rot.as_matrix()


def _unit_inertia(mesh: trimesh.Trimesh) -> np.ndarray:
    """Inertia (3x3) per unit mass about the mesh frame's origin."""
    volume = abs(float(mesh.volume))
    if volume < 1e-12:
        return np.eye(3) * MIN_INERTIA
    return np.asarray(mesh.moment_inertia_frame(np.eye(4)), dtype=np.float64) / volume * np.sign(mesh.volume)


def _inertial(masses: list, inertial: etree._Element | None, to_link: np.ndarray | None,
              conv: _Converter) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass (kg), centre of mass and inertia (about it), link frame."""
    if inertial is not None and to_link is not None:
        a = dict(inertial.attrib)
        where = conv.where(inertial)
        mass = float(a.get("mass", MIN_MASS))
        frame = to_link @ conv.frame(a, where)
        if "fullinertia" in a:
            f = _floats(a["fullinertia"], where, 6)
            local = np.array([[f[0], f[3], f[4]], [f[3], f[1], f[5]], [f[4], f[5], f[2]]])
        else:
            diag = a.get("diaginertia", f"{MIN_INERTIA} {MIN_INERTIA} {MIN_INERTIA}")
            local = np.diag(_floats(diag, where, 3)[:3])
        rot = frame[:3, :3]
        return mass, frame[:3, 3], rot @ local @ rot.T
    if not masses:
        return MIN_MASS, np.zeros(3), np.eye(3) * MIN_INERTIA
    total = sum(m for m, _, _ in masses)
    if total <= 0:
        return MIN_MASS, np.zeros(3), np.eye(3) * MIN_INERTIA
    origin_inertia = np.zeros((3, 3))
    first = np.zeros(3)
    for m, pose, unit in masses:  # inertia about the link origin, then shifted to the COM
        rot, p = pose[:3, :3], pose[:3, 3]
        about_geom = rot @ (unit * m) @ rot.T
        origin_inertia += about_geom + m * (float(p @ p) * np.eye(3) - np.outer(p, p))
        first += m * p
    com = first / total
    inertia = origin_inertia - total * (float(com @ com) * np.eye(3) - np.outer(com, com))
    inertia = (inertia + inertia.T) / 2
    vals = np.linalg.eigvalsh(inertia)
    if vals.min() < MIN_INERTIA:
        inertia = inertia + np.eye(3) * (MIN_INERTIA - min(vals.min(), 0.0))
    return total, com, inertia


def _origin(mat: np.ndarray) -> str:
    with warnings.catch_warnings():  # at gimbal lock scipy folds the roll into the yaw, still exact
        warnings.simplefilter("ignore", UserWarning)
        rpy = Rotation.from_matrix(mat[:3, :3]).as_euler("xyz")  # URDF rpy: fixed axes x, y, z
    return f'<origin xyz="{_fmt(mat[:3, 3])}" rpy="{_fmt(rpy)}"/>'


def _origin_xyz(p: np.ndarray) -> str:
    return f'<origin xyz="{_fmt(p)}" rpy="0 0 0"/>'


def convert_mjcf(path: str | Path, out_dir: str | Path, *, visual_groups: tuple[int, ...] = (0, 1, 2),
                 angle: str = "auto", density: float = DEFAULT_DENSITY) -> MjcfConversion:
    """Write ``out_dir/STEM.urdf`` from the MJCF file ``path`` (see the module docstring).

    :param visual_groups: geom groups the cameras see (MuJoCo's default group is 0; Meta-World and
        similar projects draw group 1 and keep collision geoms in group 3 or 4).
    :param angle: ``auto`` (the compiler's, else radians for a fragment whose hinge ranges are
        within +-2 pi), ``radian`` or ``degree``.
    :param density: kg/m^3 for collision geoms without a ``mass`` or ``density``.
    :raises ObjectFileError: naming the file and element at fault.
    """
    path = Path(path)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    if angle not in ("auto", "radian", "degree"):
        raise ValueError(f"angle must be auto, radian or degree, got {angle!r}")
    model = _load_model(path)
    model.angle = _angle_unit(model, angle)
    conv = _Converter(model, out_dir, tuple(visual_groups), density)
    lines: list[str] = []
    base = conv.unique("base")
    vis, col, masses = [], [], []
    for elem in model.roots:
        if elem.tag == "geom":
            v, c = conv.geom(elem, None, np.eye(4), masses)
            vis += v
            col += c
    conv.write_link(lines, base, vis, col, masses)
    for elem in model.roots:
        if elem.tag == "body":
            conv.body(elem, base, np.eye(4), np.eye(4), None, lines)
    if not conv.movable:
        raise ObjectFileError(f"{path}: no hinge or slide joint to open")
    name = path.stem
    text = "\n".join(['<?xml version="1.0"?>', f"<robot name={quoteattr(name)}>", *lines, "</robot>", ""])
    urdf = out_dir / f"{name}.urdf"
    urdf.write_text(text)
    return MjcfConversion(urdf_path=urdf, warnings=list(model.warnings), joint_names=list(conv.movable),
                          angle=model.angle)
