"""Reusable box assemblies shared by the categories: panels, open carcasses and handles.

Every function returns ``Box`` objects in the caller's link frame (metres). Boxes are axis-aligned;
axes are named by index (0 = x, 1 = y, 2 = z) and a sign (+1 / -1) where a direction is needed.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from capt_env.objects.spec import Box

RGBA = tuple[float, float, float, float]

HANDLE_COLOR: RGBA = (0.75, 0.75, 0.78, 1.0)


def box_from_bounds(lo: Sequence[float], hi: Sequence[float], color: RGBA, is_handle: bool = False) -> Box:
    """The axis-aligned box spanning ``lo``..``hi`` (each (3,), metres)."""
    lo_a, hi_a = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    if np.any(hi_a <= lo_a):
        raise ValueError(f"degenerate box bounds {lo_a} .. {hi_a}")
    half = (hi_a - lo_a) / 2
    centre = (hi_a + lo_a) / 2
    return Box(
        half_size=tuple(float(v) for v in half),
        pos=tuple(float(v) for v in centre),
        color=color,
        is_handle=is_handle,
    )


def open_carcass(
    width: float, depth: float, height: float, wall: float, color: RGBA, z0: float = 0.0
) -> list[Box]:
    """Five panels (bottom, top, left, right, back) of a box body open at its front (-x).

    The body spans x in [-depth/2, depth/2], y in [-width/2, width/2], z in [z0, z0 + height].
    """
    x0, x1 = -depth / 2, depth / 2
    y0, y1 = -width / 2, width / 2
    z1 = z0 + height
    return [
        box_from_bounds((x0, y0, z0), (x1, y1, z0 + wall), color),  # bottom
        box_from_bounds((x0, y0, z1 - wall), (x1, y1, z1), color),  # top
        box_from_bounds((x0, y1 - wall, z0 + wall), (x1, y1, z1 - wall), color),  # left (+y)
        box_from_bounds((x0, y0, z0 + wall), (x1, y0 + wall, z1 - wall), color),  # right (-y)
        box_from_bounds((x1 - wall, y0 + wall, z0 + wall), (x1, y1 - wall, z1 - wall), color),  # back
    ]


def bar_handle(
    surface_point: Sequence[float],
    normal: int,
    normal_sign: float,
    along: int,
    length: float,
    thickness: float,
    standoff: float,
    color: RGBA = HANDLE_COLOR,
) -> tuple[list[Box], tuple[float, float, float]]:
    """A bar handle on two posts: the bar runs along axis ``along``; it stands ``standoff`` metres
    off the surface (gap between surface and bar) in direction ``normal_sign`` * e_``normal``.

    ``surface_point`` is the centre of the handle's footprint on the surface. Returns the boxes
    (bar first, all ``is_handle``) and the bar's centre (the grasp point).
    """
    if normal == along:
        raise ValueError("the bar must run parallel to the surface")
    p = np.asarray(surface_point, dtype=np.float64)
    e_n = np.eye(3)[normal] * normal_sign
    centre = p + e_n * (standoff + thickness / 2)
    half = np.full(3, thickness / 2)
    half[along] = length / 2
    bar = Box(
        half_size=tuple(float(v) for v in half),
        pos=tuple(float(v) for v in centre),
        color=color,
        is_handle=True,
    )
    post = 0.8 * thickness
    boxes = [bar]
    for side in (-1.0, 1.0):
        post_centre = p + e_n * (standoff / 2) + np.eye(3)[along] * side * (length / 2 - post / 2)
        post_half = np.full(3, post / 2)
        post_half[normal] = standoff / 2 + 1e-4  # reach just into the surface and the bar
        boxes.append(
            Box(
                half_size=tuple(float(v) for v in post_half),
                pos=tuple(float(v) for v in post_centre),
                color=color,
                is_handle=True,
            )
        )
    return boxes, tuple(float(v) for v in centre)


def knob_handle(
    surface_point: Sequence[float],
    normal: int,
    normal_sign: float,
    cap_size: float,
    cap_depth: float,
    standoff: float,
    color: RGBA = HANDLE_COLOR,
) -> tuple[list[Box], tuple[float, float, float]]:
    """A knob-like handle: a thin stem of length ``standoff`` and a square cap (``cap_size`` across,
    ``cap_depth`` thick along the normal) at its end. Returns the boxes and the cap centre."""
    p = np.asarray(surface_point, dtype=np.float64)
    e_n = np.eye(3)[normal] * normal_sign
    cap_centre = p + e_n * (standoff + cap_depth / 2)
    cap_half = np.full(3, cap_size / 2)
    cap_half[normal] = cap_depth / 2
    stem_half = np.full(3, 0.35 * cap_size)
    stem_half[normal] = standoff / 2 + 1e-4
    stem_centre = p + e_n * (standoff / 2)
    boxes = [
        Box(
            half_size=tuple(float(v) for v in cap_half),
            pos=tuple(float(v) for v in cap_centre),
            color=color,
            is_handle=True,
        ),
        Box(
            half_size=tuple(float(v) for v in stem_half),
            pos=tuple(float(v) for v in stem_centre),
            color=color,
            is_handle=True,
        ),
    ]
    return boxes, tuple(float(v) for v in cap_centre)


BODY_WHITES = ((0.92, 0.92, 0.9), (0.85, 0.86, 0.88), (0.8, 0.8, 0.78))
METALS = ((0.6, 0.62, 0.65), (0.3, 0.3, 0.32), (0.12, 0.12, 0.13), (0.72, 0.72, 0.74))
WOODS = ((0.55, 0.38, 0.22), (0.72, 0.55, 0.36), (0.4, 0.26, 0.15), (0.9, 0.88, 0.82))
GLASS = ((0.08, 0.1, 0.14), (0.15, 0.18, 0.25))
FRAMES = ((0.05, 0.05, 0.05), (0.35, 0.2, 0.1), (0.55, 0.55, 0.6), (0.6, 0.1, 0.1), (0.1, 0.15, 0.4))
