"""Where a hand should grasp the moving part of a user's object file: its handle.

All computations are in the moving link's own frame (metres), on points spread over the part's
surface by area. Order of preference:

1. A ``handle`` the user names (a link or geom name on the moving part).
2. Geometry named like a handle (``handle``, ``knob``, ``pull``, ``grip``, ``lever``).
3. Geometry standing off the part's outer face by more than ``STANDOFF`` (bar handles of any
   orientation, knobs, levers however far they stand off): of its connected pieces, the one that
   stands farthest off (:func:`_proudest_piece`).
4. No handle: the middle of the free edge of the outer face (a hinged part), or the middle of the
   outer face (a sliding part), where a hand can hook or pinch.

For a named or found handle the target is the middle of its outermost layer (``GRIP_DEPTH`` deep
along the outward normal: the bar a hand closes on rather than the posts that hold it), half the
bar's thickness behind its front (:func:`_grip_centre`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from capt_env.objects.errors import ObjectFileError
from capt_env.objects.link_geometry import ShapeMesh, sample_surface

HANDLE_NAME = re.compile(r"handle|knob|pull|grip|lever", re.IGNORECASE)
STANDOFF = 0.01
"""m: geometry this far beyond the outer face counts as standing off it (a handle)."""
GRIP_DEPTH = 0.015
"""m: depth of a handle's outermost layer, about a Panda fingertip's width."""
CLUSTER_RADIUS = 0.02
"""m: surface points closer than this belong to the same piece of a handle."""
MIN_PIECE_SHARE = 0.05
"""A piece standing off the face with fewer than this share of the standing points is a speck."""
FACE_BIN = 0.002
"""m: histogram bin for finding the outer face's level."""
SAMPLES = 20000
FACING_SHARE = 0.08
"""A sliding part with at least this share of its surface in one 4 mm slab across the slide has a
face across it (a drawer front); below, it is a panel sliding within its plane (a window)."""


@dataclass(frozen=True)
class GraspTarget:
    """The grasp point and the outer face's outward normal, moving-link frame."""

    point: np.ndarray  # (3,) metres
    outward: np.ndarray  # (3,) unit
    source: str  # "option", "name", "geometry" or "edge"
    standoff: float | None = None  # metres the point stands off the outer face along ``outward``


def _unit(v: np.ndarray) -> np.ndarray:
    return v / max(float(np.linalg.norm(v)), 1e-12)


def outward_normal(points: np.ndarray, axis: np.ndarray, pivot: np.ndarray, revolute: bool,
                   object_centre: np.ndarray) -> np.ndarray:
    """Outward normal of a moving part's outer face (unit, link frame).

    Hinged part: the face is the plane of least spread about the hinge (the panel), and its outer
    side is the one the free edge moves towards while opening (``axis`` is the opening direction),
    since a door or lid swings out towards whoever opens it. Sliding part: a part that slides along
    its own face's normal (a drawer) faces along the opening direction; a thin panel sliding within
    its plane (a window, a sliding door) faces the side of its panel that something stands off by
    over ``STANDOFF`` (its handle), else away from the whole object's centre.
    """
    axis = _unit(np.asarray(axis, dtype=np.float64))
    centred = points - points.mean(axis=0)
    if revolute:
        flat = centred - np.outer(centred @ axis, axis)
        _, vecs = np.linalg.eigh(flat.T @ flat)
        normal = vecs[:, 1] if abs(vecs[:, 0] @ axis) > 0.9 else vecs[:, 0]
        normal = _unit(normal - (normal @ axis) * axis)
        lever = points.mean(axis=0) - pivot
        lever = lever - (lever @ axis) * axis
        motion = np.cross(axis, lever)
        return normal if motion @ normal >= 0 else -normal
    along = centred @ axis
    if _largest_layer_share(along) >= FACING_SHARE:  # a face across the slide: a drawer front
        return axis
    flat = centred - np.outer(along, axis)  # a panel sliding within its own plane
    _, vecs = np.linalg.eigh(flat.T @ flat)
    thin = vecs[:, 1] if abs(vecs[:, 0] @ axis) > 0.9 else vecs[:, 0]
    thin = _unit(thin - (thin @ axis) * axis)
    h = centred @ thin
    mid = float(np.median(h))
    front, back = float(h.max()) - mid, mid - float(h.min())
    if abs(front - back) > STANDOFF:  # a handle stands off the outer face only
        return thin if front > back else -thin
    offset = (points.mean(axis=0) - object_centre) @ thin
    return thin if offset >= 0 else -thin


def _largest_layer_share(heights: np.ndarray, layer: float = 0.004) -> float:
    """Share of points in the most populated ``layer``-thick slab across a direction: large where a
    flat face lies across it, about layer / extent where the surface only runs along it."""
    span = float(heights.max() - heights.min())
    if span < layer:
        return 1.0
    counts, _ = np.histogram(heights, bins=int(np.ceil(span / layer)))
    return float(counts.max()) / len(heights)


def face_level(heights: np.ndarray) -> float:
    """Height of the outer face along the outward normal: the most populated level in the upper half
    of the part (a panel's face is a flat spike in the height histogram; walls spread out)."""
    upper = heights[heights >= np.median(heights)]
    lo, hi = float(upper.min()), float(upper.max())
    if hi - lo < FACE_BIN:
        return hi
    counts, edges = np.histogram(upper, bins=max(1, int(np.ceil((hi - lo) / FACE_BIN))))
    k = int(np.argmax(counts))
    return float(edges[k + 1])


def _grip_centre(points: np.ndarray, outward: np.ndarray) -> np.ndarray:
    """The point (3,) a closing hand centres on, of a handle's surface points (N, 3), link frame.

    Across the face: the middle of the handle's outermost layer (``GRIP_DEPTH`` deep), the bar a
    hand closes on rather than the posts that hold it. Along the unit ``outward`` normal: half the
    handle's thickness behind its front, so that the fingers close round the bar's middle. A bar or
    knob is about as deep as it is wide, and its outermost layer spans about its width across its
    narrower direction in the face's plane; the layer's own mean depth (under a centimetre) is the
    middle of a thin bar but the front of a thick one (a 4.6 cm lever closed on there squeezes out
    of the fingers). Never deeper than the handle's points reach."""
    h = points @ outward
    front = float(h.max())
    layer = points[h >= front - GRIP_DEPTH]
    centre = layer.mean(axis=0)
    flat = layer - np.outer(layer @ outward, outward)
    flat = flat - flat.mean(axis=0)
    _, vecs = np.linalg.eigh(flat.T @ flat)  # ascending; outward itself has no spread in `flat`
    in_plane = [v for v in vecs.T if abs(float(v @ outward)) < 0.5]
    narrow = in_plane[0] if in_plane else vecs[:, 0]
    across = flat @ narrow
    width = float(np.percentile(across, 98) - np.percentile(across, 2)) if len(across) > 1 else 0.0
    depth = min(max(0.5 * width, front - float(centre @ outward)), front - float(h.min()))
    return centre - (float(centre @ outward) - (front - depth)) * outward


def _proudest_piece(points: np.ndarray, outward: np.ndarray) -> np.ndarray:
    """Of the connected pieces (``CLUSTER_RADIUS``) of the points (N, 3) standing off a part's face,
    the one that stands farthest along ``outward``, among pieces of at least ``MIN_PIECE_SHARE`` of
    the points. A handle stands proud of everything else on a face; a panel whose face normal leans
    a few degrees towards a handle at one end (the least spread of a door with a thick bar at its
    free edge: Franka Kitchen's microwave, 3 deg) rises off that normal's face level at its far end
    too, in a larger piece that stands off only a couple of centimetres."""
    if len(points) < 2:
        return points
    pairs = cKDTree(points).query_pairs(CLUSTER_RADIUS, output_type="ndarray")
    from scipy.sparse import coo_matrix

    n = len(points)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    sizes = np.bincount(labels)
    heights = points @ outward
    big = [k for k in range(len(sizes)) if sizes[k] >= max(5, MIN_PIECE_SHARE * n)]
    best = max(big, key=lambda k: float(heights[labels == k].max())) if big else int(sizes.argmax())
    return points[labels == best]


def find_grasp_target(meshes: list[ShapeMesh], mesh_links: list[str], axis: np.ndarray, pivot: np.ndarray,
                      revolute: bool, object_centre: np.ndarray, handle: str | None = None,
                      part_name: str = "", seed: int = 0) -> GraspTarget:
    """Grasp target of a moving part given as ``meshes`` (link frame) with the link name each came
    from. ``axis`` is the opening direction and ``pivot`` a point on the joint axis, link frame;
    ``object_centre`` the whole object's bounding-box centre in the same frame; ``part_name`` the
    moving link's own name.

    :raises ObjectFileError: if ``handle`` names nothing on the part, or the part has no geometry.
    """
    points, owner = sample_surface(meshes, SAMPLES, seed=seed)
    if len(points) == 0:
        raise ObjectFileError("the moving part has no visual geometry to grasp")
    outward = outward_normal(points, axis, pivot, revolute, object_centre)
    heights = points @ outward
    face = face_level(heights)

    def target(point: np.ndarray, source: str) -> GraspTarget:
        return GraspTarget(point, outward, source, float(point @ outward - face))

    names = [(m.name, link) for m, link in zip(meshes, mesh_links, strict=True)]
    if handle is not None:
        picked = [k for k, (geom, link) in enumerate(names) if handle in (geom, link)]
        if not picked:
            known = sorted({n for pair in names for n in pair if n})
            raise ObjectFileError(
                f"handle {handle!r} is not a link or geom of the moving part; it has {known}")
        return target(_grip_centre(points[np.isin(owner, picked)], outward), "option")
    # A handle is a geom named like one, or a link named like one fixed to the part (not the part
    # itself: a "pull-out tray" link is the whole part).
    named = [k for k, (geom, link) in enumerate(names)
             if HANDLE_NAME.search(geom) or (link != part_name and HANDLE_NAME.search(link))]
    if named and np.isin(owner, named).any():
        return target(_grip_centre(points[np.isin(owner, named)], outward), "name")
    standing = points[heights > face + STANDOFF]
    if len(standing) >= 5:
        return target(_grip_centre(_proudest_piece(standing, outward), outward), "geometry")
    on_face = points[np.abs(heights - face) <= 0.005]
    if len(on_face) == 0:
        on_face = points
    if revolute:
        a = _unit(np.asarray(axis, dtype=np.float64))
        rel = on_face - pivot
        dist = np.linalg.norm(rel - np.outer(rel @ a, a), axis=1)
        edge = on_face[dist >= dist.max() - 0.02]
        return target(edge.mean(axis=0), "edge")
    return target(on_face.mean(axis=0), "edge")
