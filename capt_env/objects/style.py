"""Varied geometry of the procedural categories: which options are on (:class:`GeometryVariation`, the
``variation.geometry`` keys of ``capt generate``) and one instance's drawn choices (:class:`Style`).

An instance's style is a pure function of (category, instance_id), like its shape parameters, but it
is drawn from a generator of its own (:func:`draw_style`): turning variation on changes none of the
base parameters (sizes, hinge side, joint limits, colours), an instance stays in its split, and every
choice is drawn whatever the options, so turning one option on changes no other option's draws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from capt_env.objects.sampling import category_seed, check_instance_id

PanelShape = Literal["box", "rounded", "chamfered", "curved"]
HandleKind = Literal["bar", "knob", "recessed", "lever"]
PANEL_SHAPES: tuple[PanelShape, ...] = ("box", "rounded", "chamfered", "curved")
HANDLE_KINDS: tuple[HandleKind, ...] = ("bar", "knob", "recessed", "lever")
_STYLE_STREAM = 7_411  # keeps the style generator apart from the shape parameters' one
LEVER_MAX_STANDOFF = 0.13
"""Metres: the longest stem a varied lever stands on, off its panel's face (door levers and the
simulators' door files stand 6-13 cm off; cabinet bars 3-4.5 cm)."""
FRONT_FILL = (0.6, 0.9)
"""The share of its opening's height a drawer's front fills under ``openings`` (Meta-World's drawer:
its 10.4 cm front in a 16.8 cm opening, 0.62)."""


@dataclass(frozen=True)
class GeometryVariation:
    """Which geometry options vary per instance (all off: every instance as the category makes it).

    - ``panels``: the moving panel (door, drawer front, laptop lid, and a laptop's base) is a box,
      a rounded panel (corners rounded in the panel's plane, radius 10-40 % of half its smaller side),
      a chamfered one (outer edges bevelled at 45 degrees by 30-70 % of its thickness, at most
      1.5 cm) or a curved one (outer face bowed out along its longer side by 1-3 cm, at most 15 % of
      that side), a quarter of the instances each; half of the instances build round parts as
      cylinders (a washing machine's round door, bars, posts and knobs).
    - ``handles``: each instance's handle is a bar, a knob, a recessed pull (a pocket 2.8 cm high
      cut 60 % into a flat panel; the grasp point is the pocket's centre) or a lever (a stem and a
      bar to one side; on a side-hinged door, cabinet or washing machine, the stem uniform from
      the category's handle standoff to :data:`LEVER_MAX_STANDOFF`), a quarter each; bars and
      levers lie along one of the panel's two axes on half of the instances and at a uniform angle
      in (-pi/2, pi/2) radians on the others. A laptop with a recessed pull has no lip. Eyeglasses
      keep their ear pieces.
    - ``interiors``: inner structure of the base, seen when the part is open: one or two extra
      shelves and a divider in a cabinet, one or two wire racks in an oven, a drum of slats in a
      washing machine, frames between the drawers of a drawer cabinet and a divider in each drawer
      (that one moves with its drawer).
    - ``openings``: a drawer's front is lower than its opening (60-90 % of it, standing at the
      opening's foot, the drawer's box no taller than its front), so the carcass's inside shows
      above a closed drawer, as on a drawer whose front is its box's own wall (Meta-World's). The
      joint, its limits and the opening are unchanged; other categories ignore it.
    - ``proportions``: a drawer cabinet's proportions are drawn from ranges reaching beyond the
      category's own (``capt_env.objects.drawer_cabinet``): its carcass 0.18-0.50 m wide (against
      0.30-0.50) and 0.16-0.45 m deep (against 0.28-0.45), its drawers' boxes 60-100 % as tall as
      their fronts (against 60-80 %), so narrow and shallow cabinets with full-height drawer boxes
      appear, as Meta-World's drawer is (0.22 x 0.20 m, a box as tall as its front); the drawers,
      their travel (a share of the depth) and handles follow the carcass. A cabinet door's carcass
      (``capt_env.objects.cabinet_door``) is 0.20-0.75 m wide, 0.15-0.55 m deep and 0.22-0.85 m tall
      (against 0.28-0.48, 0.25-0.40 and 0.32-0.60), its door and handle following, as a microwave's
      deep body is (Franka Kitchen's: 0.52 m). Other categories ignore it.
    """

    panels: bool = False
    handles: bool = False
    interiors: bool = False
    openings: bool = False
    proportions: bool = False

    @property
    def enabled(self) -> bool:
        """True when any option is on."""
        return self.panels or self.handles or self.interiors or self.openings or self.proportions


@dataclass(frozen=True)
class Style:
    """One instance's geometry choices (see :class:`GeometryVariation`). ``panel_size`` in [0, 1)
    places the panel shape's size within its range; ``handle`` None keeps the category's own kind;
    ``handle_angle`` (radians) turns bars and levers in the panel plane from the category's bar
    direction; ``lever_stem`` in [0, 1) places a lever's stem between the category's standoff and
    :data:`LEVER_MAX_STANDOFF` (:func:`lever_standoff`); ``seed`` draws the interior's details
    (:meth:`rng`); ``front_fill`` is the share of its opening's height a drawer's front fills;
    ``proportions`` (three numbers in [0, 1)) places a drawer cabinet's width, depth and drawer-box
    height, or a cabinet door's width, depth and height, within the ``proportions`` ranges; None
    keeps the category's own draws."""

    panel: PanelShape = "box"
    panel_size: float = 0.0
    cylinders: bool = False
    handle: HandleKind | None = None
    handle_angle: float = 0.0
    interior: bool = False
    seed: int = 0
    lever_stem: float = 0.0
    front_fill: float = 1.0
    proportions: tuple[float, float, float] | None = None

    def rng(self) -> np.random.Generator:
        """A fresh generator for the interior's details (the same every call)."""
        return np.random.default_rng([self.seed, _STYLE_STREAM])


def draw_style(category: str, instance_id: int, variation: GeometryVariation) -> Style | None:
    """Instance ``instance_id``'s style under ``variation``; None when every option is off."""
    check_instance_id(category, instance_id)
    if not variation.enabled:
        return None
    rng = np.random.default_rng([category_seed(category), int(instance_id), _STYLE_STREAM])
    panel = PANEL_SHAPES[int(rng.integers(len(PANEL_SHAPES)))]
    size = float(rng.random())
    cylinders = bool(rng.random() < 0.5)
    kind = HANDLE_KINDS[int(rng.integers(len(HANDLE_KINDS)))]
    aligned = bool(rng.random() < 0.5)
    turned = float(rng.uniform(-math.pi / 2, math.pi / 2))
    angle = float(rng.choice([0.0, math.pi / 2])) if aligned else turned
    seed = int(rng.integers(2**31))
    lever_stem = float(rng.random())  # drawn after the others: the draws above are those of styles before it
    fill = float(rng.uniform(*FRONT_FILL))  # drawn after the others, for the same reason
    proportions = (float(rng.random()), float(rng.random()), float(rng.random()))  # drawn last, likewise
    return Style(
        panel=panel if variation.panels else "box",
        panel_size=size,
        cylinders=cylinders and variation.panels,
        handle=kind if variation.handles else None,
        handle_angle=angle if variation.handles else 0.0,
        interior=variation.interiors,
        seed=seed,
        lever_stem=lever_stem if variation.handles else 0.0,
        front_fill=fill if variation.openings else 1.0,
        proportions=proportions if variation.proportions else None,
    )


def lever_standoff(category_standoff: float, style: Style) -> float:
    """Metres a lever's bar stands off its panel's face: ``category_standoff`` (the category's bar
    standoff) at ``style.lever_stem`` 0, up to :data:`LEVER_MAX_STANDOFF` towards 1."""
    low = min(category_standoff, LEVER_MAX_STANDOFF)
    return low + style.lever_stem * (LEVER_MAX_STANDOFF - low)


def proportioned(style: Style | None, own: tuple[float, ...],
                 wider: tuple[tuple[float, float], ...]) -> tuple[float, ...]:
    """A category's own draws ``own`` (metres or shares), or under ``proportions`` the style's places
    within the ``wider`` (low, high) ranges, one range per value."""
    if style is None or style.proportions is None:
        return own
    return tuple(low + u * (high - low) for u, (low, high) in zip(style.proportions, wider, strict=True))
