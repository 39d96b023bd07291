"""The front of a moving part with varied geometry: its panel (box, rounded, chamfered or curved) and
its handle (bar at any angle, knob, recessed pull, lever), made together because a recessed pull cuts
into its panel and a handle stands on the panel's (possibly curved) face.

Frames and units: the caller's link frame, metres, radians. A panel is the axis-aligned slab
``lo``..``hi``; its outer face looks along ``normal_sign * e_normal`` and "height" is measured from
the slab's flat outer plane along that direction. With no style (``None``) the functions make exactly
the boxes the categories always made.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from capt_env.objects.geometry import quat_from_axis_angle, quat_from_x_to
from capt_env.objects.parts import HANDLE_COLOR, RGBA, bar_handle, box_from_bounds, knob_handle
from capt_env.objects.spec import Box, ConvexMesh, Cylinder, Shape
from capt_env.objects.style import Style, lever_standoff

Vec3 = tuple[float, float, float]
ARC_POINTS = 6  # per rounded corner
BOW_POINTS = 11  # across a curved face
POCKET_HEIGHT = 0.028  # m, finger room of a recessed pull
MIN_HALF = 0.025  # m, the shortest half-length a bar or pull is cut to before it is moved inwards


@dataclass(frozen=True)
class Panel:
    """A built panel: its pieces and the height (m) of its outer face above the flat outer plane at
    an in-plane point (a function of the link-frame point projected on that plane), and the margin
    (m) a handle's footprint keeps from the panel's edges."""

    boxes: list[Box]
    shapes: list[Shape]
    height: Callable[[np.ndarray], float]
    margin: float


def _axes(normal: int) -> tuple[int, int]:
    a, b = (k for k in range(3) if k != normal)
    return a, b


def _point(values: dict[int, float]) -> Vec3:
    return (float(values[0]), float(values[1]), float(values[2]))


def panel_pieces(lo: Sequence[float], hi: Sequence[float], normal: int, normal_sign: float, color: RGBA,
                 style: Style | None, max_radius: float = math.inf, curved: bool = True) -> Panel:
    """The panel ``lo``..``hi`` shaped by ``style.panel`` (see :class:`GeometryVariation`); a box
    without a style. ``max_radius`` caps a rounded corner's radius (m); without ``curved`` a curved
    style gives a rounded panel (a laptop)."""
    lo_a, hi_a = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    shape = "box" if style is None else style.panel
    if shape == "curved" and not curved:
        shape = "rounded"
    size = 0.0 if style is None else style.panel_size
    a, b = _axes(normal)
    outer = hi_a[normal] if normal_sign > 0 else lo_a[normal]
    inner = lo_a[normal] if normal_sign > 0 else hi_a[normal]
    thick = hi_a[normal] - lo_a[normal]
    flat: Callable[[np.ndarray], float] = lambda p: 0.0  # noqa: E731
    if shape == "box":
        return Panel([box_from_bounds(lo_a, hi_a, color)], [], flat, 0.005)
    if shape == "rounded":
        r = min((0.1 + 0.3 * size) * 0.5 * min(hi_a[a] - lo_a[a], hi_a[b] - lo_a[b]), max_radius)
        pts = []
        for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1)):  # corners; each arc spans its quadrant
            ca = (lo_a[a] + r) if sa < 0 else (hi_a[a] - r)
            cb = (lo_a[b] + r) if sb < 0 else (hi_a[b] - r)
            mid_angle = math.atan2(sb, sa)
            for t in np.linspace(mid_angle - math.pi / 4, mid_angle + math.pi / 4, ARC_POINTS):
                for n in (lo_a[normal], hi_a[normal]):
                    pts.append(_point({a: ca + r * math.cos(t), b: cb + r * math.sin(t), normal: n}))
        return Panel([], [ConvexMesh(tuple(pts), color)], flat, 0.3 * r + 0.005)
    if shape == "chamfered":
        c = min((0.3 + 0.4 * size) * thick, 0.015)
        pts = []
        for n, inset in ((inner, 0.0), (outer - normal_sign * c, 0.0), (outer, c)):
            for ua in (lo_a[a] + inset, hi_a[a] - inset):
                for ub in (lo_a[b] + inset, hi_a[b] - inset):
                    pts.append(_point({a: ua, b: ub, normal: n}))
        return Panel([], [ConvexMesh(tuple(pts), color)], flat, c + 0.005)
    if shape != "curved":
        raise ValueError(f"unknown panel shape {shape!r}")
    bow, across = (a, b) if hi_a[a] - lo_a[a] >= hi_a[b] - lo_a[b] else (b, a)
    half = (hi_a[bow] - lo_a[bow]) / 2
    mid = (hi_a[bow] + lo_a[bow]) / 2
    sag = min(0.01 + 0.02 * size, 0.15 * 2 * half)
    radius = (half**2 + sag**2) / (2 * sag)

    def height(p: np.ndarray) -> float:
        u = min(abs(float(p[bow]) - mid), half)
        return math.sqrt(radius**2 - u**2) - (radius - sag)

    pts = []
    for u in np.linspace(-half, half, BOW_POINTS):
        h = math.sqrt(max(radius**2 - u**2, 0.0)) - (radius - sag)
        for uc in (lo_a[across], hi_a[across]):
            pts.append(_point({bow: mid + u, across: uc, normal: outer + normal_sign * h}))
    for ua in (lo_a[a], hi_a[a]):
        for ub in (lo_a[b], hi_a[b]):
            pts.append(_point({a: ua, b: ub, normal: inner}))
    return Panel([], [ConvexMesh(tuple(pts), color)], height, 0.005)


@dataclass(frozen=True)
class Front:
    """A moving part's front as a category describes it: the panel slab ``lo``..``hi`` (outer face
    along ``normal_sign * e_normal``), the handle's footprint centre ``handle_at`` on the outer plane,
    the category's handle (``default_handle``; a bar along axis ``along`` of ``handle_length`` by
    ``handle_thickness`` standing ``standoff`` off the face; a knob's cap ``knob_size`` across and
    ``knob_depth`` deep on a stem ``standoff - 0.01`` long). ``round`` marks a round door (a disc
    inscribed in the slab's square, its axis along the normal). ``long_levers``: a varied lever may
    stand up to :data:`~capt_env.objects.style.LEVER_MAX_STANDOFF` off (a side-hinged door, whose
    lever swings clear of the table and the body). Metres."""

    lo: Vec3
    hi: Vec3
    normal: int
    normal_sign: float
    color: RGBA
    handle_at: Vec3
    along: int
    handle_length: float
    handle_thickness: float
    standoff: float
    handle_color: RGBA = HANDLE_COLOR
    default_handle: Literal["bar", "knob"] = "bar"
    knob_size: float = 0.028
    knob_depth: float = 0.02
    round: bool = False
    long_levers: bool = False


@dataclass
class BuiltFront:
    """The front's pieces: panel boxes, handle boxes, all non-box shapes, and the grasp point (m)."""

    panel_boxes: list[Box]
    handle_boxes: list[Box]
    shapes: list[Shape] = field(default_factory=list)
    grasp: Vec3 = (0.0, 0.0, 0.0)


def build_front(front: Front, style: Style | None, panel: Panel | None = None) -> BuiltFront:
    """The panel and handle of ``front`` under ``style`` (the category's own boxes without one, or
    with one that varies neither panel nor handle). ``panel`` replaces the shaped panel (a
    category's own outline); a recessed pull always cuts a flat slab."""
    f = front
    if style is None or (style.panel == "box" and not style.cylinders and style.handle is None):
        boxes = panel.boxes if panel is not None else [box_from_bounds(f.lo, f.hi, f.color)]
        if f.default_handle == "bar":
            handle, grasp = bar_handle(f.handle_at, normal=f.normal, normal_sign=f.normal_sign, along=f.along,
                                       length=f.handle_length, thickness=f.handle_thickness,
                                       standoff=f.standoff, color=f.handle_color)
        else:
            handle, grasp = knob_handle(f.handle_at, normal=f.normal, normal_sign=f.normal_sign,
                                        cap_size=f.knob_size, cap_depth=f.knob_depth,
                                        standoff=f.standoff - 0.01, color=f.handle_color)
        return BuiltFront(boxes, handle, [], grasp)
    kind = style.handle or f.default_handle
    if kind == "recessed":
        return _recessed(f, style)
    if panel is not None:
        pass
    elif f.round and style.cylinders:
        centre = (np.asarray(f.lo) + np.asarray(f.hi)) / 2
        half = (f.hi[f.normal] - f.lo[f.normal]) / 2
        radius = min(f.hi[k] - f.lo[k] for k in _axes(f.normal)) / 2
        disc = Cylinder(radius, half, tuple(float(v) for v in centre),
                        tuple(float(v) for v in quat_from_x_to(np.eye(3)[f.normal])), f.color)
        panel = Panel([], [disc], lambda p: 0.0, 0.005)
    else:
        panel = panel_pieces(f.lo, f.hi, f.normal, f.normal_sign, f.color, style)
    maker = {"bar": _bar, "knob": _knob, "lever": _lever}[kind]
    handle_boxes, handle_shapes, grasp = maker(f, style, panel)
    return BuiltFront(panel.boxes, handle_boxes, panel.shapes + handle_shapes, grasp)


# ----------------------------------------------------------------------------- handle placement
def _inside_fn(f: Front, margin: float) -> Callable[[np.ndarray], bool]:
    """Whether an in-plane point (link frame, 3-vector on the outer plane) is on the panel's face
    at least ``margin`` from its edges."""
    a, b = _axes(f.normal)
    lo, hi = np.asarray(f.lo), np.asarray(f.hi)
    centre = (lo + hi) / 2
    radius = min(hi[a] - lo[a], hi[b] - lo[b]) / 2

    def inside(p: np.ndarray) -> bool:
        ok = all(lo[k] + margin <= p[k] <= hi[k] - margin for k in (a, b))
        if f.round:
            ok = ok and math.hypot(p[a] - centre[a], p[b] - centre[b]) <= radius - margin
        return ok

    return inside


def _direction(f: Front, angle: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit vectors: outward normal, the bar direction (``along`` turned by ``angle`` about the
    normal) and the in-plane direction across it."""
    e_n = np.eye(3)[f.normal]
    e_along = np.eye(3)[f.along]
    d = math.cos(angle) * e_along + math.sin(angle) * np.cross(e_n, e_along)
    return e_n * f.normal_sign, d, np.cross(e_n, d)


def _fit(f: Front, inside: Callable[[np.ndarray], bool], d: np.ndarray, across: np.ndarray,
         reach: tuple[float, float], width: float) -> tuple[np.ndarray, float]:
    """Where a footprint reaching ``reach = (back, forward)`` metres along ``d`` and ``width / 2``
    across it fits: (centre on the outer plane, scale in (0, 1] applied to the reach). The reach is
    cut down to at least ``MIN_HALF`` first, then the centre is moved towards the panel's centre."""
    p0 = np.asarray(f.handle_at, dtype=np.float64)
    centre = (np.asarray(f.lo) + np.asarray(f.hi)) / 2
    centre[f.normal] = p0[f.normal]

    def fits(p: np.ndarray, s: float) -> bool:
        return all(inside(p + d * along + across * w) for along in (-s * reach[0], s * reach[1])
                   for w in (-width / 2, width / 2))

    floor = min(1.0, MIN_HALF / max(max(reach), 1e-9))
    for t in np.linspace(0.0, 1.0, 21):
        p = p0 + t * (centre - p0)
        if fits(p, floor):
            lo_s, hi_s = floor, 1.0
            if fits(p, 1.0):
                return p, 1.0
            for _ in range(20):
                mid = (lo_s + hi_s) / 2
                lo_s, hi_s = (mid, hi_s) if fits(p, mid) else (lo_s, mid)
            return p, lo_s
    return centre, floor


def _block(centre: np.ndarray, long_dir: np.ndarray, half_long: float, half_side: float, half_up: float,
           up: np.ndarray, f: Front, color: RGBA, cylinder: bool, is_handle: bool = True) -> Box | Cylinder:
    """A handle piece: a box (``half_long`` along ``long_dir``, ``half_side`` across, ``half_up``
    along ``up``) or a cylinder of radius ``half_side`` along ``long_dir``."""
    pos = tuple(float(v) for v in centre)
    if cylinder:
        return Cylinder(half_side, half_long, pos, tuple(float(v) for v in quat_from_x_to(long_dir)), color,
                        is_handle)
    # a box along the category's axes, turned about the normal onto long_dir
    e_n, e_along = np.eye(3)[f.normal], np.eye(3)[f.along]
    half = np.full(3, half_side)
    half[f.normal] = half_up
    if abs(float(long_dir @ e_n)) >= 0.5:  # standing along the normal: square across, not turned
        half[f.normal] = half_long
        quat = (1.0, 0.0, 0.0, 0.0)
    else:
        half[f.along] = half_long
        angle = math.atan2(float(np.cross(e_along, long_dir) @ e_n), float(e_along @ long_dir))
        quat = tuple(float(v) for v in quat_from_axis_angle(e_n, angle))
    return Box(tuple(float(v) for v in half), pos, quat, color, is_handle)


def _split(pieces: list[Box | Cylinder]) -> tuple[list[Box], list[Shape]]:
    return [p for p in pieces if isinstance(p, Box)], [p for p in pieces if not isinstance(p, Box)]


def _post(f: Front, panel: Panel, foot: np.ndarray, top: float, half_side: float, up: np.ndarray,
          cylinder: bool) -> Box | Cylinder:
    """A post from just inside the face at ``foot`` (outer plane) up to height ``top`` (m)."""
    bottom = panel.height(foot) - 0.002
    half_up = (top - bottom) / 2
    return _block(foot + up * (bottom + half_up), up, half_up, half_side, half_up, up, f, f.handle_color,
                  cylinder)


def _bar(f: Front, style: Style, panel: Panel) -> tuple[list[Box], list[Shape], Vec3]:
    up, d, across = _direction(f, style.handle_angle)
    t = f.handle_thickness
    half = f.handle_length / 2
    p, s = _fit(f, _inside_fn(f, panel.margin), d, across, (half, half), t)
    half *= s
    ends = [p + d * k * (half - 0.4 * t) for k in (-1.0, 1.0)]
    face = max(panel.height(q) for q in [p, *ends])
    bar_bottom = face + f.standoff
    centre = p + up * (bar_bottom + t / 2)
    pieces = [_block(centre, d, half, t / 2, t / 2, up, f, f.handle_color, style.cylinders)]
    pieces += [_post(f, panel, q, bar_bottom + 1e-4, 0.4 * t, up, style.cylinders) for q in ends]
    boxes, shapes = _split(pieces)
    return boxes, shapes, tuple(float(v) for v in centre)


def _knob(f: Front, style: Style, panel: Panel) -> tuple[list[Box], list[Shape], Vec3]:
    up, d, across = _direction(f, 0.0)
    r = f.knob_size / 2
    p, _ = _fit(f, _inside_fn(f, panel.margin), d, across, (r, r), f.knob_size)
    stem_top = panel.height(p) + f.standoff - 0.01
    centre = p + up * (stem_top + f.knob_depth / 2)
    cap = _block(centre, up, f.knob_depth / 2, r, f.knob_depth / 2, up, f, f.handle_color, style.cylinders)
    stem = _post(f, panel, p, stem_top + 1e-4, 0.35 * f.knob_size, up, style.cylinders)
    boxes, shapes = _split([cap, stem])
    return boxes, shapes, tuple(float(v) for v in centre)


def _lever(f: Front, style: Style, panel: Panel) -> tuple[list[Box], list[Shape], Vec3]:
    """A stem on a round or square rose and a bar reaching from the stem's top to one side."""
    up, d, across = _direction(f, style.handle_angle)
    t = f.handle_thickness
    length = min(max(0.6 * f.handle_length, 0.08), 0.13)
    inside = _inside_fn(f, panel.margin)
    # reach away from the panel's nearest edge: try both sides, keep the one needing less cutting
    options = [(sign, *_fit(f, inside, sign * d, across, (t, length), max(t, 0.03))) for sign in (1.0, -1.0)]
    sign, p, s = max(options, key=lambda o: o[2])
    d = sign * d
    length = max(length * s, 2 * t)
    face = max(panel.height(p), panel.height(p + d * length))
    top = face + (lever_standoff(f.standoff, style) if f.long_levers else f.standoff)
    rose = _block(p + up * (panel.height(p) + 0.002), up, 0.004, 0.018, 0.004, up, f, f.handle_color,
                  style.cylinders)
    stem = _post(f, panel, p, top + 1e-4, 0.45 * t, up, style.cylinders)
    centre = p + d * (length / 2 - t / 2) + up * (top + t / 2)
    bar = _block(centre, d, length / 2, t / 2, t / 2, up, f, f.handle_color, style.cylinders)
    boxes, shapes = _split([rose, stem, bar])
    return boxes, shapes, tuple(float(v) for v in centre)


def _recessed(f: Front, style: Style) -> BuiltFront:
    """A flat panel cut around a pocket (four rim boxes and a thinner back box behind the pocket)."""
    a, b = _axes(f.normal)
    lo, hi = np.asarray(f.lo, dtype=np.float64), np.asarray(f.hi, dtype=np.float64)
    thick = hi[f.normal] - lo[f.normal]
    up, d, across = _direction(f, style.handle_angle)
    long_axis = a if abs(d[a]) >= abs(d[b]) else b
    short_axis = b if long_axis == a else a
    e_long = np.eye(3)[long_axis]
    half = min(max(f.handle_length / 2, 0.03), 0.07)
    inside = _inside_fn(f, 0.015)
    p, s = _fit(f, inside, e_long, np.eye(3)[short_axis], (half, half), POCKET_HEIGHT)
    half *= s
    depth = 0.6 * thick
    pocket_lo, pocket_hi = p.copy(), p.copy()
    pocket_lo[long_axis] -= half
    pocket_hi[long_axis] += half
    pocket_lo[short_axis] -= POCKET_HEIGHT / 2
    pocket_hi[short_axis] += POCKET_HEIGHT / 2
    outer = hi[f.normal] if f.normal_sign > 0 else lo[f.normal]
    cut = outer - f.normal_sign * depth  # the pocket's floor
    pocket_lo[f.normal], pocket_hi[f.normal] = sorted((outer, cut))
    boxes = []
    for lo_k, hi_k in ((lo[short_axis], pocket_lo[short_axis]), (pocket_hi[short_axis], hi[short_axis])):
        r_lo, r_hi = lo.copy(), hi.copy()  # rims across the whole panel, above and below the pocket
        r_lo[short_axis], r_hi[short_axis] = lo_k, hi_k
        boxes.append(box_from_bounds(r_lo, r_hi, f.color))
    for lo_k, hi_k in ((lo[long_axis], pocket_lo[long_axis]), (pocket_hi[long_axis], hi[long_axis])):
        r_lo, r_hi = lo.copy(), hi.copy()
        r_lo[short_axis], r_hi[short_axis] = pocket_lo[short_axis], pocket_hi[short_axis]
        r_lo[long_axis], r_hi[long_axis] = lo_k, hi_k
        boxes.append(box_from_bounds(r_lo, r_hi, f.color))
    back_lo, back_hi = pocket_lo.copy(), pocket_hi.copy()
    back_lo[f.normal], back_hi[f.normal] = sorted((cut, lo[f.normal] if f.normal_sign > 0 else hi[f.normal]))
    boxes.append(box_from_bounds(back_lo, back_hi, f.handle_color, is_handle=True))  # the pocket's floor
    grasp = (pocket_lo + pocket_hi) / 2
    return BuiltFront(boxes, [], [], tuple(float(v) for v in grasp))
