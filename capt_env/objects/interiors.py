"""Inner structure of a base, seen when its door is open or its drawer pulled out
(``GeometryVariation.interiors``): shelves and a divider, oven racks, a washing-machine drum, frames
between drawers and dividers inside them.

Every function returns pieces in the base's (or drawer's) link frame, metres, inside the free space
its category leaves, so nothing touches a moving part at any state. Details are drawn from ``rng``
(the instance style's own generator).
"""

from __future__ import annotations

import math

import numpy as np

from capt_env.objects.geometry import quat_from_axis_angle
from capt_env.objects.parts import RGBA, box_from_bounds
from capt_env.objects.spec import Box, Cylinder

ROD = 0.006  # m, thickness of rack rods and drum slats


def _spread(rng: np.random.Generator, count: int, low: float, high: float, avoid: list[float],
            gap: float) -> list[float]:
    """Up to ``count`` values uniform in [low, high], each ``gap`` from the others and from ``avoid``."""
    out: list[float] = []
    for _ in range(20 * count):
        if len(out) == count:
            break
        z = float(rng.uniform(low, high))
        if all(abs(z - o) >= gap for o in out + avoid):
            out.append(z)
    return sorted(out)


def cabinet_interior(width: float, depth: float, height: float, wall: float, shelves_at: list[float],
                     color: RGBA, rng: np.random.Generator) -> list[Box]:
    """One or two more shelves (heights away from ``shelves_at`` by 8 cm) and, on half of the
    instances, a vertical divider from the bottom to the lowest shelf, set back 2 cm from the front
    of a carcass open at -x (see ``parts.open_carcass``)."""
    x0, x1 = -depth / 2 + 0.02, depth / 2 - wall
    y0, y1 = -width / 2 + wall, width / 2 - wall
    zs = _spread(rng, int(rng.integers(1, 3)), 0.2 * height, 0.8 * height, list(shelves_at), 0.08)
    boxes = [box_from_bounds((x0, y0, z - wall / 2), (x1, y1, z + wall / 2), color) for z in zs]
    if rng.random() < 0.5:
        y = float(rng.uniform(-0.25, 0.25)) * width
        top = min([*zs, *shelves_at], default=height - wall) - wall / 2
        boxes.append(box_from_bounds((x0, y - wall / 2, wall), (x1, y + wall / 2, top), color))
    return boxes


def oven_racks(width: float, depth: float, z_lo: float, z_hi: float, wall: float, color: RGBA,
               rng: np.random.Generator) -> list[Box]:
    """One or two wire racks (a frame and rods running front to back, ``ROD`` thick) at heights in
    the middle of the cavity ``z_lo``..``z_hi``, inside the walls of a carcass open at -x."""
    x0, x1 = -depth / 2 + wall + 0.02, depth / 2 - wall - 0.01
    y0, y1 = -width / 2 + wall + 0.005, width / 2 - wall - 0.005
    boxes = []
    for z in _spread(rng, int(rng.integers(1, 3)), z_lo + 0.3 * (z_hi - z_lo), z_lo + 0.75 * (z_hi - z_lo),
                     [], 0.05):
        for x in (x0, x1 - ROD):  # front and back bars
            boxes.append(box_from_bounds((x, y0, z), (x + ROD, y1, z + ROD), color))
        for y in np.linspace(y0, y1 - ROD, int(rng.integers(5, 9))):
            boxes.append(box_from_bounds((x0, y, z + ROD), (x1, y + ROD, z + 2 * ROD), color))
    return boxes


def drum(x0: float, x1: float, zc: float, radius: float, color: RGBA,
         rng: np.random.Generator) -> tuple[list[Box], list[Cylinder]]:
    """A washing machine's drum about the x-axis through (y, z) = (0, ``zc``): a ring of slats from
    ``x0`` to ``x1`` just inside ``radius``, two or three lifter ribs and a round back at ``x1``."""
    count = 14
    slat_w = 2 * radius * math.sin(math.pi / count) + 0.002
    xm, half_x = (x0 + x1) / 2, (x1 - x0) / 2
    boxes = []
    for k in range(count):
        t = 2 * math.pi * k / count
        r = radius - ROD / 2
        boxes.append(Box((half_x, ROD / 2, slat_w / 2), (xm, r * math.cos(t), zc + r * math.sin(t)),
                         tuple(float(v) for v in quat_from_axis_angle((1.0, 0.0, 0.0), t)), color))
    phase = float(rng.uniform(0, 2 * math.pi))
    ribs = int(rng.integers(2, 4))
    for k in range(ribs):
        t = phase + 2 * math.pi * k / ribs
        r = radius - ROD - 0.01
        boxes.append(Box((half_x, 0.01, 0.006), (xm, r * math.cos(t), zc + r * math.sin(t)),
                         tuple(float(v) for v in quat_from_axis_angle((1.0, 0.0, 0.0), t)), color))
    back = Cylinder(radius, 0.003, (x1 + 0.003, 0.0, zc), color=color)
    return boxes, [back]


def drawer_frames(count: int, slot: float, wall: float, width: float, x0: float, x1: float,
                  color: RGBA) -> list[Box]:
    """Horizontal frames between stacked drawer slots (each slot ``slot`` high above a bottom wall
    ``wall`` thick), from ``x0`` (behind the drawer fronts) to ``x1``: 1 cm below a slot boundary to
    1.5 mm above it, the room a drawer box leaves under the next drawer."""
    y0, y1 = -width / 2 + wall, width / 2 - wall
    return [box_from_bounds((x0, y0, wall + k * slot - 0.010), (x1, y1, wall + k * slot + 0.0015), color)
            for k in range(1, count)]


def drawer_divider(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, color: RGBA,
                   rng: np.random.Generator) -> list[Box]:
    """On half of the drawers, a divider running front to back inside a drawer box whose inner space
    is ``x0..x1``, ``y0..y1``, ``z0..z1`` (it moves with the drawer); none on the others."""
    if rng.random() >= 0.5:
        return []
    y = float(rng.uniform(0.3, 0.7)) * (y1 - y0) + y0
    top = z0 + float(rng.uniform(0.5, 0.9)) * (z1 - z0)
    return [box_from_bounds((x0, y - ROD / 2, z0), (x1, y + ROD / 2, top), color)]
