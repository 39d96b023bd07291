"""Geometry of a flat moving part (door, drawer front, lid) seen in an object's points, world frame.

Its plane (robust to a segmentation's mislabelled points), the handle standing off that plane, and
the sign of a joint axis that opens the part (moves it away from its body).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, QhullError, cKDTree

from capt_env.wrappers.estimate import unit
from capt_env.wrappers.plane_fit import ransac_plane


@dataclass(frozen=True)
class PartPlane:
    """The plane of a flat moving part (a door, drawer front or lid), world frame, metres.

    ``centre`` (3,) lies on it, ``in_plane`` (2, 3) are two orthonormal in-plane directions and
    ``outward`` (3,) is its unit normal turned away from the rest of the object: a closed part lies
    on the outside of its body, so opening it moves it along ``outward``.
    """

    centre: np.ndarray
    in_plane: np.ndarray
    outward: np.ndarray


BODILESS_DEPTH = 0.03
"""A part whose object's points centre within this (m) of its plane has no body behind it."""


def part_plane(object_points: np.ndarray, part_points: np.ndarray,
               viewpoint: np.ndarray | None = None) -> PartPlane | None:
    """The plane through most of ``part_points`` (M, 3) (seeded RANSAC, 1 cm band, refitted by PCA to
    those inliers: a segmentation's mislabelled body points would tilt a plain fit), its normal turned
    away from the centroid of ``object_points`` (N, 3): a part's outer face looks away from its body.
    When that centroid lies within :data:`BODILESS_DEPTH` of the plane and ``viewpoint`` (3,) is
    given, the normal is turned towards the viewpoint instead: a door in a bare frame has no body
    behind it, its handle standing out in front pulls the centroid forwards, and the face the cameras
    see is its outer one. None when no plane holds half of the part's points (the part is not flat)
    or there are fewer than 10 of them. World frame, metres."""
    if len(part_points) < 10 or len(object_points) < 1:
        return None
    near, _ = ransac_plane(part_points, iterations=64, threshold=0.01, seed=0)
    if int(near.sum()) < max(10, len(part_points) // 2):
        return None
    centre = part_points[near].mean(axis=0)
    vt = np.linalg.svd(part_points[near] - centre, full_matrices=False)[2]
    normal = vt[2]
    behind = float((object_points.mean(axis=0) - centre) @ normal)
    if viewpoint is not None and abs(behind) < BODILESS_DEPTH:
        behind = -float((np.asarray(viewpoint, dtype=np.float64) - centre) @ normal)
    if behind > 0.0:
        normal = -normal
    return PartPlane(centre, vt[:2], normal)


def faces_along(plane: PartPlane | None, direction: np.ndarray, max_angle: float = 0.6) -> bool:
    """Whether ``plane``'s normal is within ``max_angle`` rad of the line of ``direction`` (3,): a
    drawer's front faces along its slide. False for no plane."""
    if plane is None:
        return False
    return abs(float(plane.outward @ unit(direction))) >= float(np.cos(max_angle))


def facing(plane: PartPlane, viewpoint: np.ndarray) -> PartPlane:
    """``plane`` with its outward normal turned towards ``viewpoint`` (3,), world frame."""
    if float((np.asarray(viewpoint, dtype=np.float64) - plane.centre) @ plane.outward) >= 0.0:
        return plane
    return PartPlane(plane.centre, plane.in_plane, -plane.outward)


def slides_across(plane: PartPlane | None, direction: np.ndarray, max_angle: float = np.pi / 2 - 0.6,
                  max_tilt: float = 0.5) -> bool:
    """Whether a part sliding along ``direction`` (3,) slides across ``plane`` (a window sash, a
    sliding cabinet door): the slide's line lies within ``max_angle`` rad of the plane (by default
    wherever :func:`faces_along` does not hold: a sliding part either comes out of its face or runs
    across it) and the plane stands upright, its normal within ``max_tilt`` rad of horizontal (an
    open drawer's bottom holds its slide too, but it looks up). False for no plane."""
    if plane is None:
        return False
    along_normal = abs(float(plane.outward @ unit(direction)))
    upright = abs(float(plane.outward[2])) <= float(np.sin(max_tilt))
    return along_normal <= float(np.sin(max_angle)) and upright


def coplanar_panel(object_points: np.ndarray, part_points: np.ndarray, plane: PartPlane,
                   band: float = 0.01, link_radius: float = 0.03) -> np.ndarray:
    """The flat panel a segmented part lies on: the points (K, 3) of ``object_points`` (N, 3) within
    ``band`` m of ``plane`` and linked to ``part_points`` (M, 3) through in-plane neighbours at most
    ``link_radius`` m apart, with ``part_points`` themselves. World frame, metres.

    A segmentation can label only the handle's half of a closed door as moving (cabinet door seed 150:
    16 of its 40 cm); the rest of the door is still in its plane and touches that half, so the
    panel gives the door's full extent, whose edge away from the handle is the hinge. Only for a
    closed part: an open door is coplanar with whatever it happens to align with (at 90 deg a
    cabinet's side wall, joined at the hinge).
    """
    obj = np.asarray(object_points, dtype=np.float64)
    part = np.asarray(part_points, dtype=np.float64)
    in_band = np.abs((obj - plane.centre) @ plane.outward) <= band
    if not in_band.any():
        return part
    candidates = obj[in_band]
    uv = (np.concatenate([part, candidates]) - plane.centre) @ plane.in_plane.T
    pairs = cKDTree(uv).query_pairs(link_radius, output_type="ndarray")
    if len(pairs) == 0:
        return part
    n = len(uv)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    linked = np.isin(labels[len(part):], np.unique(labels[:len(part)]))
    return np.unique(np.concatenate([part, candidates[linked]]), axis=0)


def handle_point(object_points: np.ndarray, part_points: np.ndarray, min_standoff: float = 0.012,
                 max_standoff: float = 0.08, margin: float = 0.1, min_points: int = 3,
                 plane: PartPlane | None = None, centre_across: bool = False) -> np.ndarray | None:
    """Centre (3,) of a handle standing off a flat moving part, or None; world frame, metres.

    The part's plane is ``plane`` when the caller has it, else ``part_plane(object_points,
    part_points)``. The handle is the
    ``object_points`` (N, 3) (all of the object's points: a segmentation may miss thin handle points)
    between ``min_standoff`` and ``max_standoff`` m outside that plane and within the part's
    in-plane extent grown by ``margin`` m (a view may show only some of the part), keeping those
    standing at least half as far out as the outermost ones (a bar, not the part's own surface
    noise); the point returned is their centroid moved, along their main direction, to the middle
    of their extent (with ``centre_across`` also across the bar in the part's plane, see
    :func:`bar_centre`). None when the part is not flat or fewer than ``min_points`` qualify.
    """
    plane = plane or part_plane(object_points, part_points)
    if plane is None or len(object_points) < min_points:
        return None
    in_plane = (part_points - plane.centre) @ plane.in_plane.T
    keep = standing_off(object_points, plane, in_plane.min(axis=0) - margin,
                        in_plane.max(axis=0) + margin, min_standoff, max_standoff)
    if int(keep.sum()) < min_points:
        return None
    keep[keep] = outer_layer(object_points[keep], plane)
    if int(keep.sum()) < min_points:
        return None
    return bar_centre(object_points[keep], plane.outward if centre_across else None)


def outer_layer(handle: np.ndarray, plane: PartPlane, share: float = 0.5) -> np.ndarray:
    """(M,) mask of a handle's points (M, 3) standing at least ``share`` as far out of ``plane`` as its
    outermost ones (the 0.9 quantile): the bar a hand closes on. Surface bumps and noise sit just
    above the search band's floor, and the posts that hold a bar off the face run from the face to
    the bar: their points would pull a centroid towards the face, behind the bar."""
    standoff = (handle - plane.centre) @ plane.outward
    return standoff >= share * float(np.quantile(standoff, 0.9))


def standing_off(points: np.ndarray, plane: PartPlane, lo: np.ndarray, hi: np.ndarray,
                 min_standoff: float, max_standoff: float) -> np.ndarray:
    """(N,) mask of ``points`` (N, 3) between ``min_standoff`` and ``max_standoff`` m outside
    ``plane`` whose in-plane coordinates (along ``plane.in_plane``) lie within ``lo``..``hi`` (2,)."""
    standoff = (points - plane.centre) @ plane.outward
    uv = (points - plane.centre) @ plane.in_plane.T
    return ((standoff > min_standoff) & (standoff < max_standoff)
            & np.all(uv >= lo, axis=1) & np.all(uv <= hi, axis=1))


def bar_centre(handle: np.ndarray, outward: np.ndarray | None = None) -> np.ndarray:
    """Centre (3,) of a handle's points (M, 3): their centroid moved, along their main direction, to
    the middle of their extent (the visible points of a bar are denser at one end). Given the unit
    normal ``outward`` (3,) of the face the handle stands on, it is also moved to the middle of their
    extent across the bar in that face's plane: a camera sees one side of a bar and its front, so the
    centroid sits on the seen side (a drawer's bar seen from above: half its thickness high)."""
    centre = handle.mean(axis=0)
    if len(handle) < 2:
        return centre
    along = np.linalg.svd(handle - centre, full_matrices=False)[2][0]
    # (direction, share of points trimmed at each end of the extent): along a bar its ends are
    # sparse; across it the extent is the bar's thickness and every point counts
    extents = [(along, 0.05)]
    if outward is not None:
        across = np.cross(along, outward)
        if np.linalg.norm(across) > 0.5:  # the bar lies in the face's plane, not along its normal
            extents.append((across / np.linalg.norm(across), 0.01))
    for d, trim in extents:
        t = np.quantile((handle - centre) @ d, [trim, 1.0 - trim])
        centre = centre + d * float(t.mean())
    return centre


def opening_direction(joint_type: str, direction: np.ndarray, pivot: np.ndarray, grasp: np.ndarray,
                      outward: np.ndarray) -> np.ndarray:
    """``direction`` (3,) or its negation, whichever opens the part: increasing the state moves the
    grasp point (3,) along the part's ``outward`` normal (3,). Revolute: the grasp point's velocity
    ``direction x (grasp - pivot)``; prismatic: the direction itself. World frame.

    The sign of a hinge's axis is a global property of the shape (which side the hinge is on), the
    one thing a single-view estimate most often gets wrong while the line itself is right.
    """
    u = unit(direction)
    motion = np.cross(u, np.asarray(grasp, dtype=np.float64) - pivot) if joint_type == "revolute" else u
    return -u if float(motion @ outward) < 0.0 else u


LEAF_MIN_APART = 0.06
"""m: two like handles at least this far apart on one flat panel are on two leaves of a double door
(one handle's cluster spans less)."""


def double_door_seam(grasp: np.ndarray, other_handles: Sequence[np.ndarray], centre: np.ndarray,
                     across: np.ndarray, along: np.ndarray, min_apart: float = LEAF_MIN_APART,
                     max_height: float = 0.1, beside_slope: float = 0.75) -> float | None:
    """Where (m across, unit ``across`` (3,) from ``centre`` (3,)) two doors meet, when one of
    ``other_handles`` (each (3,)) stands beside the ``grasp`` (3,) handle: at least ``min_apart`` m
    from it across, and off its height along ``along`` (3,) by at most ``max_height`` m or by at most
    ``beside_slope`` times what it stands across (the two doors of a double door carry their handles
    side by side near where they meet; a long bar seen in part has its centre off its twin's height,
    and still stands clearly more beside it than above it: within 37 deg of level, clear of the
    45-deg diagonal where neither holds): half-way between them; None when none does. World frame,
    metres."""
    s_grasp = float((grasp - centre) @ across)
    h_grasp = float((grasp - centre) @ along)
    beside = []
    for other in other_handles:
        d = np.asarray(other, dtype=np.float64) - centre
        s_other, h_other = float(d @ across), float(d @ along)
        apart, off_height = abs(s_other - s_grasp), abs(h_other - h_grasp)
        if apart >= min_apart and off_height <= max(max_height, beside_slope * apart):
            beside.append(s_other)
    if not beside:
        return None
    nearest = min(beside, key=lambda s_other: abs(s_other - s_grasp))
    return (s_grasp + nearest) / 2.0


def edge_aligned_direction(direction: np.ndarray, plane: PartPlane, part_points: np.ndarray,
                           max_turn: float = 0.6, min_fill: float = 0.85,
                           band: float = 0.01, min_aspect: float = 0.25) -> np.ndarray:
    """``direction`` (3,) turned onto the nearer edge of a rectangular part: unit (3,), world frame.

    A door's or lid's hinge runs along one of its edges. The part's points within ``band`` m of its
    plane are fitted with their minimum-area bounding rectangle (in the plane); when their convex
    hull fills at least ``min_fill`` of it (a rectangle, not a round washing-machine door) and the
    rectangle's edge nearest to ``direction``'s in-plane component is at most ``max_turn`` rad away,
    that edge's direction is returned, with ``direction``'s sign. Otherwise (or when ``direction``
    is more than 60 deg out of the plane, or there are fewer than 10 such points) ``direction`` is
    returned unchanged, as it is for a bar (points spreading less than ``min_aspect`` as much across
    their main in-plane direction as along it: an eyeglasses temple). A single view's estimate of a
    lid's hinge often errs within the lid's plane by 5-25 deg, which moves the lid's far edge, where
    the grasp point is looked for, to a corner.
    """
    u = unit(direction)
    along = u - float(u @ plane.outward) * plane.outward
    if np.linalg.norm(along) < np.sin(np.radians(30.0)):
        return u
    near = np.abs((part_points - plane.centre) @ plane.outward) <= band
    uv = (part_points[near] - plane.centre) @ plane.in_plane.T
    if len(uv) < 10:
        return u
    spread = np.linalg.svd(uv - uv.mean(axis=0), compute_uv=False)
    if spread[1] < min_aspect * spread[0]:
        return u
    try:
        hull = ConvexHull(uv)
    except QhullError:  # collinear points: no area
        return u
    corners = uv[hull.vertices]
    best_area, best_angle = np.inf, 0.0
    for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        angle = float(np.arctan2(b[1] - a[1], b[0] - a[0]))
        c, s = np.cos(angle), np.sin(angle)
        rotated = corners @ np.array([[c, -s], [s, c]])
        area = float(np.prod(rotated.max(axis=0) - rotated.min(axis=0)))
        if area < best_area:
            best_area, best_angle = area, angle
    if best_area <= 0.0 or hull.volume < min_fill * best_area:  # hull.volume is its area in 2-D
        return u
    target = np.array([float(along @ plane.in_plane[0]), float(along @ plane.in_plane[1])])
    best: np.ndarray | None = None
    for angle in (best_angle, best_angle + np.pi / 2):
        edge = np.array([np.cos(angle), np.sin(angle)])
        edge = edge if float(edge @ target) >= 0 else -edge
        turn = float(np.arccos(np.clip(edge @ unit(target), -1.0, 1.0)))
        if turn <= max_turn:
            best = edge
    if best is None:
        return u
    return unit(best[0] * plane.in_plane[0] + best[1] * plane.in_plane[1])


def hinge_on_edge(direction: np.ndarray, grasp: np.ndarray, plane: PartPlane, part_points: np.ndarray,
                  pivot: np.ndarray | None = None, tolerance: float = 0.06,
                  edge_quantile: float = 0.02, min_aspect: float = 0.25,
                  panel_points: np.ndarray | None = None,
                  other_handles: Sequence[np.ndarray] = (),
                  pair_doors: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """A flat part's hinge line checked against its points: (unit direction (3,), pivot (3,)), world
    frame, metres.

    A closed door, lid or oven door turns about a line in (or just behind) its own plane along its
    edge farthest from the handle. The estimated ``direction`` is projected into the part's plane
    (its in-plane component is kept, so the estimate still decides which edge). The estimated
    ``pivot`` is kept when it lies within ``tolerance`` of that edge of ``part_points`` (M, 3) (the
    edge at the ``edge_quantile`` of the points' coordinates across the axis, on the side away from
    ``grasp`` (3,)) and of the plane; otherwise (or when ``pivot`` is None) the line is put on that
    edge, in the plane. The returned pivot is the line's point closest to ``grasp``, the sign of the
    direction is kept. A direction more than 60 deg out of the plane is not a hinge of this part,
    and a part whose points spread less than ``min_aspect`` as much across their main in-plane
    direction as along it is a bar (an eyeglasses temple), not a flat panel: then the direction is returned
    unchanged, with ``pivot`` (or the plane's centre) moved along it. ``panel_points`` (K, 3), when
    given, replace ``part_points`` for finding the edges (the whole panel the part lies on:
    :func:`coplanar_panel`); the bar test stays on ``part_points``. ``other_handles`` (each (3,))
    holds the panel's other handles: one beside the grasp's, at its
    height (:func:`double_door_seam`), makes the panel two doors meeting between their handles (a
    double door, flush and coplanar, segmented as one part), and the grasp's door is hinged on the
    panel's edge on its side of that seam, not on the far edge, the other door's hinge
    (``pair_doors``; off: the far edge always).
    """
    g = np.asarray(grasp, dtype=np.float64)
    u = unit(direction)
    along = u - float(u @ plane.outward) * plane.outward
    uv = (part_points - plane.centre) @ plane.in_plane.T
    spread = np.linalg.svd(uv - uv.mean(axis=0), compute_uv=False)  # along its two main directions
    if np.linalg.norm(along) < np.sin(np.radians(30.0)) or spread[1] < min_aspect * spread[0]:
        base = plane.centre if pivot is None else np.asarray(pivot, dtype=np.float64)
        return u, base + u * float((g - base) @ u)
    along = unit(along)
    across = unit(np.cross(plane.outward, along))
    edges_of = part_points if panel_points is None else panel_points
    s = (edges_of - plane.centre) @ across
    s_grasp = float((g - plane.centre) @ across)
    lo, hi = np.quantile(s, [edge_quantile, 1.0 - edge_quantile])
    far_lo = abs(s_grasp - lo) > abs(s_grasp - hi)
    seam = double_door_seam(g, other_handles, plane.centre, across, along) if pair_doors else None
    if seam is not None:
        far_lo = s_grasp < seam  # two doors meet between the handles: the edge on the grasp's side
    edge = float(lo if far_lo else hi)
    line_point = plane.centre + across * edge
    if pivot is not None:
        p = np.asarray(pivot, dtype=np.float64)
        if (abs(float((p - plane.centre) @ across) - edge) <= tolerance
                and abs(float((p - plane.centre) @ plane.outward)) <= tolerance):
            line_point = p
    return along, line_point + along * float((g - line_point) @ along)
