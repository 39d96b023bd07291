"""Refiner ``handle``: the grasp point is the handle standing off the moving part's face.

Geometric reason: a handle is the part of a door, drawer front or lid that stands furthest out of
its flat face, 1.2-8 cm (``min_standoff``..``max_standoff``), within the face's extent (a sliding
part's within its own extent: beyond its edge it would catch the frame it slides in); the network's
fallback, the part's far edge, is a strip along the whole edge. The search runs on the draft's
``handle_cloud`` (all object points: a segmentation may miss thin handle points) against the
``panel``'s plane and extent, and takes the best-scored bar or knob among the grasp candidates
(:func:`~capt_env.wrappers.grasp_candidates.find_grasp_candidates`): points standing off the face are
split into linked clusters, so two handles of a double door are two candidates, not one centroid
between them, and stray points too few to be a handle, or a slab wider than a hand, are dropped. A
bar is centred across its thickness too (the cameras see one side of it), and its depth put half
its thickness behind its front (the posts that hold it off the face pull a centroid behind it),
except on a part swinging about a horizontal hinge (an oven door, a lid): measured, that moved an
oven's grasp point off its bar.
When the task names its target part (``Draft.target_hint``, the part's centre of mass) and the best
handle has a twin on another leaf (a double door segmented as one part), the handle nearest that
centre across the hinge is taken (:func:`target_leaf_handle`): the leaves look alike, and only the
task says which one it means.
When nothing stands in that band, the search runs again out to ``far_standoff`` (13 cm): a bar on
long posts stands farther out (Franka Kitchen's microwave: a 2 cm bar on 5.8 cm posts, seen 9-12 cm
off the plane fitted to its door, whose glass lies behind the door's front), and a second search only
where the first found nothing never lets something standing farther out (a frame, a neighbouring
part) outrank a handle in the usual band.
The face is the part's plane (:attr:`Draft.face`): a drawer's front, facing along its slide, or the
upright face a sash or sliding door slides across.
Must not fire: when a refiner already found the handle (``stacked_parts``), the part is not flat (or
a prismatic part's face neither faces along its slide nor stands upright holding it), or no cluster
of enough points standing off the face is a bar or knob no wider than ``max_width`` (the face's edge
is the draft's own fallback).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from capt_common.typed_yaml import require
from capt_env.wrappers.estimate import unit
from capt_env.wrappers.grasp_candidates import GraspCandidate, GraspCandidateConfig, find_grasp_candidates
from capt_env.wrappers.moving_part_geometry import LEAF_MIN_APART, PartPlane
from capt_env.wrappers.refiners.draft import Draft


@dataclass(frozen=True)
class HandleConfig:
    """``min_standoff``..``max_standoff`` (m): how far out of the face handle points stand;
    ``margin`` (m): the face's in-plane extent is grown by it; ``vertical_hinge_min_z``: a hinge whose
    unit direction has at least this |z| counts as vertical (its handle is centred across the bar);
    ``slide_margin`` (m): a sliding part's handle lies within its own extent grown by this;
    ``far_standoff`` (m): the band's outer end for a second search when the first finds nothing
    (at most ``max_standoff``: no second search)."""

    min_standoff: float = 0.012
    max_standoff: float = 0.08
    far_standoff: float = 0.13
    margin: float = 0.1
    vertical_hinge_min_z: float = 0.5
    slide_margin: float = 0.01

    def validate(self) -> None:
        require(0.0 <= self.min_standoff < self.max_standoff,
                "handle.min_standoff must be >= 0 and below handle.max_standoff (metres)")
        require(self.margin >= 0, "handle.margin must be >= 0 (metres)")
        require(0.0 <= self.vertical_hinge_min_z <= 1.0, "handle.vertical_hinge_min_z must be in [0, 1]")
        require(self.slide_margin >= 0, "handle.slide_margin must be >= 0 (metres)")
        require(self.far_standoff >= 0,
                "handle.far_standoff must be >= 0 (metres; at most max_standoff: no second search)")


class Handle:
    """Set the draft's grasp point to the centre of the handle on its moving part's face."""

    name: ClassVar[str] = "handle"

    def __init__(self, config: HandleConfig | None = None) -> None:
        self.config = config or HandleConfig()

    def refine(self, draft: Draft) -> bool:
        face = None if draft.grasp is not None or draft.settled else draft.face
        if face is None:
            return False
        c = self.config
        handles = self.handles(draft, face, c.max_standoff)
        if not handles and c.far_standoff > c.max_standoff:
            # nothing in the usual band: a bar on long posts, or a face fitted to a recessed panel
            # behind the part's front, stands farther out
            handles = self.handles(draft, face, c.far_standoff)
        if not handles:
            return False
        hinge = draft.direction if draft.joint_type == "revolute" else None
        chosen = target_leaf_handle(handles, face, draft.target_hint, hinge)
        draft.grasp, draft.from_handle = chosen.point, True
        draft.other_handles = [g.point for g in handles if g is not chosen and twin(g, chosen)]
        return True

    def handles(self, draft: Draft, face: PartPlane, max_standoff: float) -> list[GraspCandidate]:
        """The bar and knob candidates standing ``min_standoff``..``max_standoff`` m off ``face``, best
        first; a sliding part's only within its own extent."""
        c = self.config
        across = draft.joint_type == "prismatic" or abs(float(draft.direction[2])) >= c.vertical_hinge_min_z
        found = find_grasp_candidates(
            draft.handle_cloud, draft.panel, plane=face, centre_across=across,
            config=GraspCandidateConfig(min_standoff=c.min_standoff, max_standoff=max_standoff,
                                        margin=c.margin, min_points=draft.handle_min_points))
        handles = [g for g in found if g.kind in ("bar", "knob")]
        if draft.joint_type == "prismatic":
            # a sliding part carries its handle within its own face: one standing beyond its edge
            # would run into the frame or track it slides in (a bar beside a sash is the frame's, or a
            # plinth's). A hinged part's handle may overhang its free edge (a lever), swinging clear
            handles = [g for g in handles if over_part(g.point, draft.panel, face, c.slide_margin)]
        return handles


TWIN_BAR_ANGLE = np.radians(20.0)
"""rad: two bars this near parallel can be a double door's pair."""


def twin(other: GraspCandidate, handle: GraspCandidate) -> bool:
    """Whether ``other`` could be the twin of ``handle`` on the other leaf of a double door: the same
    kind, and for bars, bars near parallel (the two leaves of a double door carry the same handle,
    mirrored; a lock knob beside a lever, or a lever seen beside another piece of an open door, is not
    one)."""
    if other.kind != handle.kind:
        return False
    return other.kind != "bar" or abs(float(other.bar_axis @ handle.bar_axis)) >= np.cos(TWIN_BAR_ANGLE)


def target_leaf_handle(handles: list[GraspCandidate], face: PartPlane, target_hint: np.ndarray | None,
                       hinge: np.ndarray | None = None) -> GraspCandidate:
    """The handle to grasp among ``handles`` (best first): the best one, or, when the task names its
    target part by ``target_hint`` (3,) (its centre of mass) and twins of the best handle stand at
    least ``LEAF_MIN_APART`` from it on the face (a double door's two leaves), the one of the best and
    those twins nearest the hint across the ``hinge`` direction (3,) (in the face's plane when None):
    a double door's leaves lie side by side across their hinges, each with its handle on its own
    side of the seam, while a handle seen in part has its centre off the leaf's height. The hint
    picks a leaf, never a point. World frame, metres."""
    best = handles[0]
    if target_hint is None:
        return best
    axes = face.in_plane
    if hinge is not None:
        along = hinge - float(hinge @ face.outward) * face.outward
        if np.linalg.norm(along) > 0.5:  # a hinge lying in the face (within 60 deg of it)
            axes = unit(np.cross(face.outward, along))[None, :]

    def coords(p: np.ndarray) -> np.ndarray:
        return (np.asarray(p, dtype=np.float64) - face.centre) @ axes.T

    leaves = [best] + [g for g in handles[1:] if twin(g, best) and float(
        np.linalg.norm((g.point - best.point) @ face.in_plane.T)) >= LEAF_MIN_APART]
    hint = coords(target_hint)
    return min(leaves, key=lambda g: float(np.linalg.norm(coords(g.point) - hint)))


def over_part(point: np.ndarray, part_points: np.ndarray, plane: PartPlane, margin: float) -> bool:
    """Whether ``point`` (3,) lies over the part ``part_points`` (M, 3) seen along ``plane``'s normal:
    inside the part's in-plane extent grown by ``margin`` (m). World frame, metres."""
    uv = (np.asarray(point, dtype=np.float64) - plane.centre) @ plane.in_plane.T
    part_uv = (np.asarray(part_points, dtype=np.float64) - plane.centre) @ plane.in_plane.T
    return bool(np.all(uv >= part_uv.min(axis=0) - margin) and np.all(uv <= part_uv.max(axis=0) + margin))
