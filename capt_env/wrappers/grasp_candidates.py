"""Candidate grasps on a flat moving part (door, drawer front, lid) in an object's points, world frame.

Everything a parallel gripper can take on the part's face: bars standing off it (of any orientation,
levers included), compact knobs, pulls recessed into it, and, as the fallback, the part's free edge.
Each comes with the grasp point, the approach normal, the axis the fingers close across, its width
between the fingers, the free space around it and a geometric score. Which of them the arm can reach
is decided elsewhere (:mod:`agents.scripted.grasp_reachability`). Metres, world frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, QhullError, cKDTree

from capt_common.typed_yaml import require
from capt_env.wrappers.estimate import unit
from capt_env.wrappers.moving_part_geometry import (
    PartPlane,
    bar_centre,
    outer_layer,
    part_plane,
    standing_off,
)

GraspKind = Literal["bar", "knob", "recess", "edge"]
KIND_PRIOR: dict[str, float] = {"bar": 3.0, "knob": 2.0, "recess": 1.0, "edge": 0.0}
"""The score each kind starts from: a bar is the surest grip (fingers close around it whatever its
orientation), a knob can slip under a pull, a recess takes only the fingertips, an edge is a pinch."""


@dataclass(frozen=True)
class GraspCandidateConfig:
    """Thresholds of :func:`find_grasp_candidates`, each with its geometric reason.

    ``min_standoff`` (m): handle points stand at least this far out of the face (above its surface
    noise and the plane fit's 1 cm band). ``max_standoff`` (m): and at most this far (levers stand
    10-12.5 cm off a panel; farther is another body in front of it). ``margin`` (m): the face's
    in-plane extent is grown by it (a view may show only some of the part, a handle may overhang);
    ``mount_tolerance`` (m): a candidate within it of the part's own extent lies over the part
    (scores higher: see :func:`_score`).
    ``link_radius`` (m): points of one handle are linked when this close (the gaps of a sparse view,
    ~1.5 cm, are smaller; two handles of a double door, >= 10 cm apart, are not linked).
    ``min_points``: a cluster needs this many points (fewer are stray points, not a handle).
    ``grip_share``: a standing cluster's grip is its points at least this share of its 90th-percentile
    standoff out (the bar or the knob's cap, not the posts that hold it to the face).
    ``min_bar_aspect``: a grip is a bar when its in-plane length is at least this many times its width,
    else a knob. ``min_bar_length`` (m): and at least this long (shorter is a knob however thin).
    ``max_width`` (m): a cluster wider than this across its narrow in-plane axis is a slab of the face
    (a moulding, a raised panel, the part's back), not something a hand grips; a bit more than the
    Panda's 8 cm opening, so callers see near misses and reject them themselves.
    ``face_band`` (m): points within it of the plane are the face itself.
    ``min_recess_depth``..``max_recess_depth`` (m): a recessed pull's pocket lies this far behind the
    face (shallower is surface noise, deeper is the body seen past the part).
    ``min_recess_width`` (m): a pocket is at least this wide (a fingertip goes in; a wall seen behind
    the face is a line in the plane). ``rim`` (m): a pocket's points lie at least this far inside
    the convex outline of the part's face (a pocket has face all round it; the body seen past the
    face's outline does not). ``surround`` (m): a pocket is surrounded by its face: on each of its
    four in-plane sides there are face points within this distance beyond it (a gap at the part's
    edge, or the body's wall there, has face on one side only).
    ``corridor_radius`` (m): clearance is looked for up to this far from the approach line (half the
    open gripper's span and a finger's width); ``corridor_length`` (m): and this far out of the face
    (the hand's length along the approach). ``edge_quantile``: a face's edge is at this quantile of its
    points' coordinates (a few stray points do not move it); ``edge_inset`` (m): an edge grasp is this
    far in from the edge (the fingertips need face to press on).
    """

    min_standoff: float = 0.01
    max_standoff: float = 0.15
    margin: float = 0.05
    mount_tolerance: float = 0.01
    link_radius: float = 0.03
    min_points: int = 3
    grip_share: float = 0.5
    min_bar_aspect: float = 2.0
    min_bar_length: float = 0.04
    max_width: float = 0.1
    face_band: float = 0.01
    min_recess_depth: float = 0.005
    max_recess_depth: float = 0.05
    min_recess_width: float = 0.015
    rim: float = 0.01
    surround: float = 0.04
    corridor_radius: float = 0.06
    corridor_length: float = 0.15
    edge_quantile: float = 0.02
    edge_inset: float = 0.02

    def validate(self) -> None:
        require(0.0 <= self.min_standoff < self.max_standoff,
                "grasp_candidates.min_standoff must be >= 0 and below max_standoff (metres)")
        require(self.margin >= 0 and self.mount_tolerance >= 0,
                "grasp_candidates.margin and mount_tolerance must be >= 0 (metres)")
        require(self.link_radius > 0, "grasp_candidates.link_radius must be > 0 (metres)")
        require(self.min_points >= 1, "grasp_candidates.min_points must be >= 1")
        require(0.0 <= self.grip_share <= 1.0, "grasp_candidates.grip_share must be in [0, 1]")
        require(self.min_bar_aspect >= 1.0, "grasp_candidates.min_bar_aspect must be >= 1")
        require(self.min_bar_length >= 0, "grasp_candidates.min_bar_length must be >= 0 (metres)")
        require(self.max_width > 0, "grasp_candidates.max_width must be > 0 (metres)")
        require(self.face_band > 0, "grasp_candidates.face_band must be > 0 (metres)")
        require(0.0 < self.min_recess_depth < self.max_recess_depth,
                "grasp_candidates.min_recess_depth must be > 0 and below max_recess_depth (metres)")
        require(0.0 <= self.min_recess_width <= self.max_width,
                "grasp_candidates.min_recess_width must be in [0, max_width] (metres)")
        require(self.rim >= 0 and self.surround > 0,
                "grasp_candidates.rim must be >= 0 and surround > 0 (metres)")
        require(self.corridor_radius > 0 and self.corridor_length > 0,
                "grasp_candidates.corridor_radius and corridor_length must be > 0 (metres)")
        require(0.0 <= self.edge_quantile < 0.5, "grasp_candidates.edge_quantile must be in [0, 0.5)")
        require(self.edge_inset >= 0, "grasp_candidates.edge_inset must be >= 0 (metres)")


@dataclass(frozen=True)
class GraspCandidate:
    """One place to grip a flat part, world frame, metres.

    ``kind``: ``"bar"``, ``"knob"``, ``"recess"`` or ``"edge"``. ``point`` (3,): the grasp centre
    (the TCP goes there). ``outward`` (3,): unit normal out of the part's face; the hand approaches
    along ``-outward``. ``bar_axis`` (3,): unit in-plane long axis of what is gripped; the fingers
    close across it, along ``outward x bar_axis`` (for a knob or recess its longer in-plane extent, so
    they close across the narrower one; for an edge, the edge's line). ``width`` (m): the extent
    between the fingers, along the closing direction (0 for an edge: nothing is closed around).
    ``clearance`` (m): distance from the approach line through ``point`` to the nearest object point
    in front of the face that is not the candidate's, within the approach corridor (the config's
    ``corridor_radius`` when none). ``score``: geometric rank, higher better (the kind's prior plus
    up to 0.5 for the share of the corridor that is free). ``points``: how many points the candidate has.
    """

    kind: GraspKind
    point: np.ndarray
    outward: np.ndarray
    bar_axis: np.ndarray
    width: float
    clearance: float
    score: float
    points: int = 0

    @property
    def closing(self) -> np.ndarray:
        """Unit direction (3,) the fingers close along: in the face's plane, across ``bar_axis``."""
        return unit(np.cross(self.outward, self.bar_axis))


def _bar_depth(point: np.ndarray, grip_standoff: np.ndarray, width: float, plane: PartPlane) -> np.ndarray:
    """``point`` (3,) moved along ``plane.outward`` to half the bar's thickness behind its front (the
    outermost of its points' standoffs ``grip_standoff`` (M,), m): a round or square bar is as deep as
    its in-plane ``width`` (m). The centroid of its outer points lies deeper: the posts holding the bar
    off the face run back to the face, and a bar standing far out leaves more of them in that layer
    (a 1.6 cm window bar 8 cm out: its centroid 5 mm behind the bar's axis, the fingers closing behind
    it). Never behind the grip's own deepest points (a flat plate of a handle is wider than deep)."""
    back, front = np.quantile(grip_standoff, [0.05, 0.95])
    depth = float((point - plane.centre) @ plane.outward)
    return point + (max(float(front) - 0.5 * width, float(back)) - depth) * plane.outward


def find_grasp_candidates(object_points: np.ndarray, part_points: np.ndarray, plane: PartPlane | None = None,
                          config: GraspCandidateConfig | None = None, *,
                          hinge_direction: np.ndarray | None = None, hinge_pivot: np.ndarray | None = None,
                          centre_across: bool = True) -> list[GraspCandidate]:
    """Candidate grasps on the flat part ``part_points`` (M, 3) among ``object_points`` (N, 3) (all
    the object's points: a segmentation may miss thin handle points), world frame, metres; best first
    (bars, knobs and recesses by score, the edge always last). Empty when the part is not flat.

    The part's plane is ``plane`` or :func:`part_plane`. Standing off it (``min_standoff`` ..
    ``max_standoff``, inside the face's in-plane extent grown by ``margin``), object points are split
    into clusters of linked points (:func:`clusters`); each cluster's grip (its outermost points,
    ``grip_share``) is a bar when elongated in the plane (any orientation), else a knob. Behind the
    face (``min_recess_depth`` .. ``max_recess_depth``) and surrounded by it, clusters are recessed
    pulls. Clusters wider than ``max_width`` are dropped. Several handles stay separate candidates.
    The edge candidate is on the face's edge farthest from the hinge (``hinge_direction`` (3,) through
    ``hinge_pivot`` (3,)) when one is given, else at the end of the face's longest in-plane axis farther
    from the object's centroid. With ``centre_across`` a bar's point is centred across its thickness
    too (:func:`~capt_env.wrappers.moving_part_geometry.bar_centre`) and put half its thickness behind
    its front (:func:`_bar_depth`).
    """
    c = config or GraspCandidateConfig()
    obj = np.asarray(object_points, dtype=np.float64)
    part = np.asarray(part_points, dtype=np.float64)
    plane = plane or part_plane(obj, part)
    if plane is None or len(obj) == 0:
        return []
    standoff = (obj - plane.centre) @ plane.outward
    uv = (obj - plane.centre) @ plane.in_plane.T
    part_uv = (part - plane.centre) @ plane.in_plane.T
    lo, hi = part_uv.min(axis=0), part_uv.max(axis=0)
    part_standoff = (part - plane.centre) @ plane.outward
    face_uv = part_uv[np.abs(part_standoff) <= c.face_band]  # the part's own face, in the plane
    found: list[tuple[GraspKind, np.ndarray, np.ndarray, np.ndarray, float, np.ndarray]] = []

    out = standing_off(obj, plane, lo - c.margin, hi + c.margin, c.min_standoff, c.max_standoff)
    for members in clusters(obj, out, c.link_radius, c.min_points):
        grip = members[outer_layer(obj[members], plane, c.grip_share)]
        if len(grip) < c.min_points:
            continue
        axis, length, width = _in_plane_extent(uv[grip], plane)
        if width > c.max_width:
            continue
        kind: GraspKind = "bar" if length >= max(c.min_bar_aspect * width, c.min_bar_length) else "knob"
        point = bar_centre(obj[grip], plane.outward if centre_across else None)
        if kind == "bar" and centre_across:
            point = _bar_depth(point, standoff[grip], width, plane)
        found.append((kind, point, axis, members, width, grip))

    behind = (-standoff >= c.min_recess_depth) & (-standoff <= c.max_recess_depth)
    behind[behind] = _inside(face_uv, uv[behind], c.rim)
    for members in clusters(obj, behind, c.link_radius, c.min_points):
        axis, length, width = _in_plane_extent(uv[members], plane)
        if (not c.min_recess_width <= width <= c.max_width
                or not _surrounded(face_uv, uv[members], axis, plane, c.surround)):
            continue
        mid_uv = _middle(uv[members])
        depth = float(np.quantile(-standoff[members], 0.9))
        point = plane.centre + mid_uv @ plane.in_plane - 0.5 * depth * plane.outward
        found.append(("recess", point, axis, members, width, members))

    candidates = []
    for kind, point, axis, members, width, grip in found:
        clearance = _clearance(obj, standoff, members, point, plane.outward, c)
        point_uv = (point - plane.centre) @ plane.in_plane.T
        mounted = bool(np.all((point_uv >= lo - c.mount_tolerance) & (point_uv <= hi + c.mount_tolerance)))
        candidates.append(GraspCandidate(kind, point, plane.outward.copy(), axis, float(width), clearance,
                                         _score(kind, clearance, mounted, c), len(grip)))
    candidates.sort(key=lambda g: -g.score)
    edge = _edge_candidate(obj, part, plane, c, hinge_direction, hinge_pivot)
    return candidates if edge is None else [*candidates, edge]


def _score(kind: GraspKind, clearance: float, mounted: bool, c: GraspCandidateConfig) -> float:
    """A candidate's geometric score: its kind's prior (:data:`KIND_PRIOR`, one apart), plus up to 0.5
    for the share of the approach corridor's radius that is free, plus 0.5 when it lies over the part
    itself (``mounted``): a handle is fixed to its part, while the margin around the part also takes in
    the edge of a body standing out beside it (a window's plinth under its sash)."""
    return KIND_PRIOR[kind] + 0.5 * min(clearance / c.corridor_radius, 1.0) + 0.5 * float(mounted)


def clusters(points: np.ndarray, mask: np.ndarray, link_radius: float, min_points: int) -> list[np.ndarray]:
    """Connected groups of the ``points`` (N, 3) selected by ``mask`` (N,): indices into ``points`` of
    each group of points linked through neighbours at most ``link_radius`` m apart, groups of fewer
    than ``min_points`` dropped, in ascending order of their first index (each group's indices
    ascending, so a single group is ``np.flatnonzero(mask)`` itself)."""
    idx = np.flatnonzero(mask)
    if len(idx) < min_points:
        return []
    pairs = cKDTree(points[idx]).query_pairs(link_radius, output_type="ndarray")
    n = len(idx)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    groups = [idx[labels == k] for k in np.unique(labels)]
    return sorted((g for g in groups if len(g) >= min_points), key=lambda g: int(g[0]))


def _in_plane_extent(uv: np.ndarray, plane: PartPlane) -> tuple[np.ndarray, float, float]:
    """(unit main in-plane axis (3,), length along it, width across it) of in-plane coordinates
    ``uv`` (K, 2): principal directions, extents between the 2nd and 98th percentiles (a stray point
    does not stretch them)."""
    centred = uv - uv.mean(axis=0)
    if len(uv) < 2:
        return plane.in_plane[0].copy(), 0.0, 0.0
    vt = np.linalg.svd(centred, full_matrices=False)[2]
    spans = [float(np.subtract(*np.quantile(centred @ d, [0.98, 0.02]))) for d in vt]
    axis = unit(vt[0] @ plane.in_plane)
    return axis, spans[0], spans[1] if len(spans) > 1 else 0.0


def _middle(uv: np.ndarray) -> np.ndarray:
    """Middle (2,) of in-plane coordinates ``uv`` (K, 2) along their principal directions."""
    mean = uv.mean(axis=0)
    if len(uv) < 2:
        return mean
    for d in np.linalg.svd(uv - mean, full_matrices=False)[2]:
        t = np.quantile((uv - mean) @ d, [0.02, 0.98])
        mean = mean + d * float(t.mean())
    return mean


def _inside(face_uv: np.ndarray, uv: np.ndarray, inset: float) -> np.ndarray:
    """(K,) mask of in-plane points ``uv`` (K, 2) at least ``inset`` m inside the convex outline of
    the face's in-plane points ``face_uv`` (F, 2); all False when the face has no area."""
    if len(face_uv) < 3 or len(uv) == 0:
        return np.zeros(len(uv), dtype=bool)
    try:
        hull = ConvexHull(face_uv)
    except QhullError:  # collinear points: no area
        return np.zeros(len(uv), dtype=bool)
    # equations: unit outward normal n and offset b per side, n . x + b <= 0 inside
    return np.max(uv @ hull.equations[:, :2].T + hull.equations[:, 2], axis=1) <= -inset


def _surrounded(face_uv: np.ndarray, pocket_uv: np.ndarray, axis: np.ndarray, plane: PartPlane,
                band: float) -> bool:
    """Whether the face's points ``face_uv`` (F, 2) lie on all four in-plane sides of a pocket's
    points ``pocket_uv`` (K, 2), within ``band`` m beyond its extent, along its main ``axis`` (3,) and
    across it."""
    if len(face_uv) == 0:
        return False
    a = np.array([float(axis @ plane.in_plane[0]), float(axis @ plane.in_plane[1])])
    for d in (a, np.array([-a[1], a[0]])):
        other = np.array([-d[1], d[0]])
        t, s = pocket_uv @ d, pocket_uv @ other
        ft, fs = face_uv @ d, face_uv @ other
        beside = (fs >= s.min()) & (fs <= s.max())  # in the pocket's shadow along d
        if not (np.any(beside & (ft > t.max()) & (ft <= t.max() + band))
                and np.any(beside & (ft < t.min()) & (ft >= t.min() - band))):
            return False
    return True


def _clearance(obj: np.ndarray, standoff: np.ndarray, own: np.ndarray, point: np.ndarray,
               outward: np.ndarray, c: GraspCandidateConfig) -> float:
    """Distance (m) from the approach line (through ``point`` (3,) along ``outward`` (3,)) to the
    nearest of ``obj`` (N, 3) standing at least ``min_standoff`` out of the face (``standoff`` (N,)),
    not among the candidate's own indices ``own``, within ``corridor_length`` out of the face and
    ``corridor_radius`` of the line; ``corridor_radius`` when there is none."""
    rel = obj - point
    along = rel @ outward
    radial = np.linalg.norm(rel - np.outer(along, outward), axis=1)
    near = ((standoff >= c.min_standoff) & (standoff <= c.corridor_length) & (radial < c.corridor_radius))
    near[own] = False
    return float(radial[near].min()) if near.any() else float(c.corridor_radius)


def _edge_candidate(obj: np.ndarray, part: np.ndarray, plane: PartPlane, c: GraspCandidateConfig,
                    hinge_direction: np.ndarray | None,
                    hinge_pivot: np.ndarray | None) -> GraspCandidate | None:
    """The grasp on the part's free edge: ``edge_inset`` m in from the edge farthest from the hinge
    (or from the object's centroid along the face's longest in-plane axis), midway along it, on the
    face. None when fewer than ``min_points`` of ``part`` (M, 3) lie on the face."""
    on_face = part[np.abs((part - plane.centre) @ plane.outward) <= c.face_band]
    if len(on_face) < max(c.min_points, 2):
        return None
    uv = (on_face - plane.centre) @ plane.in_plane.T
    edge_line = None
    if hinge_direction is not None:
        d = np.asarray(hinge_direction, dtype=np.float64)
        d = d - float(d @ plane.outward) * plane.outward
        if np.linalg.norm(d) > 0.5 * np.linalg.norm(hinge_direction):  # the hinge lies in the face
            edge_line = unit(d)
    if edge_line is None:
        longest = np.linalg.svd(uv - uv.mean(axis=0), full_matrices=False)[2][0]
        edge_line = unit(np.cross(plane.outward, unit(longest @ plane.in_plane)))
    across = unit(np.cross(plane.outward, edge_line))
    s = (on_face - plane.centre) @ across
    s_lo, s_hi = np.quantile(s, [c.edge_quantile, 1.0 - c.edge_quantile])
    if hinge_pivot is not None and hinge_direction is not None:
        ref = float((np.asarray(hinge_pivot, dtype=np.float64) - plane.centre) @ across)
    else:
        ref = float((obj.mean(axis=0) - plane.centre) @ across)
    far_hi = abs(s_hi - ref) >= abs(s_lo - ref)
    s_edge = float(s_hi - c.edge_inset) if far_hi else float(s_lo + c.edge_inset)
    t = (on_face - plane.centre) @ edge_line
    t_mid = float(np.mean(np.quantile(t, [c.edge_quantile, 1.0 - c.edge_quantile])))
    point = plane.centre + across * s_edge + edge_line * t_mid
    standoff = (obj - plane.centre) @ plane.outward
    clearance = _clearance(obj, standoff, np.zeros(0, dtype=np.int64), point, plane.outward, c)
    return GraspCandidate("edge", point, plane.outward.copy(), edge_line, 0.0, clearance,
                          _score("edge", clearance, True, c), len(on_face))
