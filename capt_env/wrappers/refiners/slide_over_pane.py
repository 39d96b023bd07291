"""Refiner ``slide_over_pane``: a sash slides along its track over the pane behind it.

Geometric reason: a window sash or a sliding cabinet door runs in a track parallel to its face, in
front of a fixed pane that fills the rest of the opening; closed, it covers its own half and the pane
shows beside it, one track (1-3 cm) behind. It can only slide over that pane (the frame stops it on
every other side), along its track, which is level or plumb (a sash window rises, a sliding door
runs level). Of the four level and plumb directions in the sash's face, the slide is the one whose
side of the sash holds the most points not labelled as the moving part in one ``slab`` thick layer
``min_depth``..``max_depth`` behind the sash's face (a pane parallel to it; a cabinet's side running
back spreads over every depth), in a strip beside the sash as long as the sash (at most ``reach``)
and as wide as its middle ``across_share``: the pane on its side, a frame bar flush with the face or
nothing on the others. A single view's network estimate of a sash mixes up and sideways slides;
which side the pane is on is plain in the cloud (with the true segmentation of 100 unseen
procedural test clouds: 65 right, 3 wrong, 32 left to the network).
When no side holds enough of them (or not ``dominance`` times the next side's), the network's
direction is only turned onto the nearest level or plumb direction in the face: a few degrees off
the track over a sash's 20 cm of travel carry the hand off its bar.
Must not fire: on a revolute joint; on a part without an upright flat face, or one the
network does not see sliding across that face (:func:`slides_across`: a drawer slides out of its
front).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.spatial import cKDTree

from capt_common.typed_yaml import require
from capt_env.wrappers.estimate import unit
from capt_env.wrappers.moving_part_geometry import PartPlane, slides_across
from capt_env.wrappers.refiners.draft import Draft


@dataclass(frozen=True)
class SlideOverPaneConfig:
    """Metres: ``min_depth``..``max_depth`` how far behind the sash's face pane points lie, counted
    in the densest ``slab`` thick layer parallel to the face, which must spread over ``min_spread`` of
    the strip's length (a surface running back from the face, a plinth's top or a cabinet's side, is
    a line in the face's plane); ``reach`` the longest strip looked at beside the sash;
    ``across_share`` the share of the sash's width the strip spans (its middle, clear of a frame's
    reveals); ``min_points`` and ``dominance`` how many pane points the best side needs, alone and
    against the next side."""

    min_depth: float = 0.005
    max_depth: float = 0.05
    slab: float = 0.01
    min_spread: float = 0.3
    reach: float = 0.3
    across_share: float = 0.8
    min_points: int = 10
    dominance: float = 2.0

    def validate(self) -> None:
        require(0.0 <= self.min_depth < self.max_depth,
                "slide_over_pane.min_depth must be >= 0 and below max_depth (metres)")
        require(self.reach > 0 and self.slab > 0, "slide_over_pane.reach and slab must be > 0 (metres)")
        require(0.0 <= self.min_spread <= 1.0, "slide_over_pane.min_spread must be in [0, 1]")
        require(0.0 < self.across_share <= 1.0, "slide_over_pane.across_share must be in (0, 1]")
        require(self.min_points >= 1 and self.dominance >= 1.0,
                "slide_over_pane.min_points must be >= 1 and dominance >= 1")


class SlideOverPane:
    """Point a sash's direction along its level or plumb track, towards the pane behind it."""

    name: ClassVar[str] = "slide_over_pane"

    def __init__(self, config: SlideOverPaneConfig | None = None) -> None:
        self.config = config or SlideOverPaneConfig()

    def refine(self, draft: Draft) -> bool:
        if draft.joint_type != "prismatic" or len(draft.moving) == len(draft.points):
            return False
        c = self.config
        face = draft.sliding_face()
        before = unit(draft.direction)
        if not slides_across(face, before):
            return False
        assert face is not None
        towards = pane_side(draft.points, draft.moving, face, c)
        if towards is None:  # no pane seen: the track is still level or plumb
            towards = max(track_directions(face), key=lambda d: float(d @ before))
        draft.direction = towards
        return float(np.linalg.norm(draft.direction - before)) > 1e-9


def track_directions(face: PartPlane) -> tuple[np.ndarray, ...]:
    """The four unit directions (3,) a sash's track may run along in the upright ``face``: straight
    up, down, and both ways level across the face (world frame, +z up; the face's fitted normal,
    tilted a few degrees by a handle's points, does not tilt them)."""
    up = np.array([0.0, 0.0, 1.0])
    level = unit(np.cross(face.outward, up))
    return up, -up, level, -level


def pane_side(points: np.ndarray, moving: np.ndarray, face: PartPlane,
              config: SlideOverPaneConfig) -> np.ndarray | None:
    """The unit direction (3,), plumb or level in ``face``, from the sash ``moving`` (M, 3) towards
    the side holding the pane behind it (see the module docstring), or None. ``points`` (N, 3) are
    the whole cloud; world frame (+z up), metres."""
    c = config
    first, _, second, _ = track_directions(face)
    others = points[cKDTree(moving).query(points)[0] > 0.0]  # moving is a subset of points
    depth = (face.centre - others) @ face.outward  # > 0 behind the face
    behind = (depth >= c.min_depth) & (depth <= c.max_depth)
    others, depth = others[behind], depth[behind]
    counts = []
    for along, across in ((first, second), (-first, second), (second, first), (-second, first)):
        s_sash, t_sash = moving @ along, moving @ across
        s, t = others @ along, others @ across
        length = min(float(s_sash.max() - s_sash.min()), c.reach)
        t_mid, t_half = float(t_sash.max() + t_sash.min()) / 2, c.across_share * float(np.ptp(t_sash)) / 2
        in_strip = (s > s_sash.max()) & (s <= s_sash.max() + length) & (np.abs(t - t_mid) <= t_half)
        layer = _densest_layer(depth[in_strip], c.slab)
        spread = float(np.ptp(s[in_strip][layer])) if layer.any() else 0.0
        counts.append((int(layer.sum()) if spread >= c.min_spread * length else 0, along))
    counts.sort(key=lambda x: -x[0])
    best, runner_up = counts[0][0], counts[1][0]
    if best < c.min_points or best < c.dominance * runner_up:
        return None
    return unit(counts[0][1])


def _densest_layer(depth: np.ndarray, slab: float) -> np.ndarray:
    """Mask of the most ``depth`` values (m) within one ``slab`` thick layer: a pane parallel to the
    face packs its points into one layer; a surface running back from the face (a cabinet's side)
    spreads them over every depth."""
    if len(depth) == 0:
        return np.zeros(0, dtype=bool)
    d = np.sort(depth)
    counts = np.searchsorted(d, d + slab, side="right") - np.arange(len(d))
    start = d[int(np.argmax(counts))]
    return (depth >= start) & (depth <= start + slab)
