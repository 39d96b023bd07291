"""Which of several stacked parts (a cabinet's drawers) is the k-th from the bottom, by their handles.

A drawer cabinet's joints are numbered from the bottom drawer up (``drawer_0`` is the lowest). CAPT
segments drawers from the body well but often gives a drawer its neighbour's label, so the target
drawer is found geometrically instead: the handles standing off the drawers' common front plane are
grouped by height, one group per drawer, and the k-th group from the bottom is the target's handle.
World frame, metres; the stacking direction is world up.
"""

from __future__ import annotations

import numpy as np

from capt_env.wrappers.moving_part_geometry import (
    PartPlane,
    bar_centre,
    outer_layer,
    part_plane,
    standing_off,
)

_UP = np.array([0.0, 0.0, 1.0])


def handle_groups(object_points: np.ndarray, front_points: np.ndarray, plane: PartPlane | None = None,
                  min_standoff: float = 0.012, max_standoff: float = 0.08, margin: float = 0.05,
                  min_gap: float = 0.04, min_points: int = 3,
                  face_band: float = 0.015) -> list[np.ndarray]:
    """Handles on a stack's front, bottom up: one (M_i, 3) array of ``object_points`` per handle.

    ``front_points`` (K, 3) are points of the stacked parts (CAPT's union of them); the front plane
    is ``plane`` or fitted to them. The front's extent is that of all ``object_points`` within
    ``face_band`` m of the plane (so a drawer CAPT missed still counts), grown by ``margin`` m;
    handle points stand ``min_standoff``..``max_standoff`` m outside the plane, inside that extent.
    Sorted by height, they are split wherever consecutive heights differ by more than ``min_gap`` m
    (handles of stacked drawers are a drawer's height apart, >= 0.1 m here); groups of fewer than
    ``min_points`` points are noise and dropped. Empty when the front is not flat.
    """
    plane = plane or part_plane(object_points, front_points)
    if plane is None:
        return []
    standoff = (object_points - plane.centre) @ plane.outward
    face = np.abs(standoff) < face_band  # the whole front: every drawer's and the carcass's
    if int(face.sum()) < min_points:
        return []
    uv = (object_points[face] - plane.centre) @ plane.in_plane.T
    keep = standing_off(object_points, plane, uv.min(axis=0) - margin, uv.max(axis=0) + margin,
                        min_standoff, max_standoff)
    if int(keep.sum()) < min_points:
        return []
    candidates = object_points[keep]
    height = candidates @ _UP
    order = np.argsort(height)
    splits = np.flatnonzero(np.diff(height[order]) > min_gap) + 1
    groups = [candidates[idx] for idx in np.split(order, splits)]
    return [g for g in groups if len(g) >= min_points]


def kth_handle_from_bottom(object_points: np.ndarray, front_points: np.ndarray, k: int,
                           plane: PartPlane | None = None, min_points: int = 3,
                           target_height: float | None = None) -> np.ndarray | None:
    """Centre (3,) of the ``k``-th handle from the bottom on a stack's front (see
    :func:`handle_groups`), world frame, metres; None when fewer than ``k + 1`` handles are seen.
    With ``target_height`` (m, world z of the target part's centre, when the task names it) the
    handle nearest that height instead, whatever ``k`` (a user file numbers its drawers in any order;
    a drawer's handle sits on its front, within half a drawer's height of its centre); None when no
    handle is seen.
    The centre is the middle of the handle's extent along its main direction (a bar's visible
    points are denser at one end) and across it in the front's plane (a camera sees one side of a
    bar), over the handle's outer layer only (:func:`~capt_env.wrappers.moving_part_geometry.outer_layer`:
    the bar, not the posts holding it off the front). ``min_points``: the fewest points of a handle."""
    if k < 0:
        raise ValueError(f"k must be >= 0, got {k}")
    plane = plane or part_plane(object_points, front_points)
    if plane is None:
        return None
    groups = handle_groups(object_points, front_points, plane=plane, min_points=min_points)
    if target_height is not None and groups:
        handle = min(groups, key=lambda g: abs(float(np.mean(g @ _UP)) - target_height))
    elif len(groups) <= k:
        return None
    else:
        handle = groups[k]
    return bar_centre(handle[outer_layer(handle, plane)], plane.outward)
