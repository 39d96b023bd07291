"""Distractor primitives on the table (``variation.distractors``): drawn once per scene build, placed
per view around the object's footprint without touching it.

World frame, metres, radians; the table top is the plane z = 0. Distractors are kinematic actors (the
generator never steps the simulation); one that is not placed waits far below the table, where no
camera sees it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from capt_env.dataset.variation import Distractors

Kind = Literal["box", "cylinder", "sphere"]
TABLE_XY = ((-0.4, 0.75), (-0.7, 0.7))
"""The part of the table top (x range, y range, metres) distractors stand on: clear of the robot's
base at x = -0.615 and inside the table's edges."""
SPACING = 0.01  # m, between two distractors
TRIES = 60


@dataclass(frozen=True)
class Primitive:
    """One distractor's shape: a box (``size`` = half sizes), an upright cylinder (radius, radius,
    half height) or a sphere (radius three times). Metres."""

    kind: Kind
    size: tuple[float, float, float]

    @property
    def half_height(self) -> float:
        return self.size[2]

    @property
    def radius(self) -> float:
        """Radius (m) of the circle holding its footprint at any yaw."""
        return math.hypot(self.size[0], self.size[1]) if self.kind == "box" else self.size[0]


def draw_primitives(cfg: Distractors, rng: np.random.RandomState) -> list[Primitive]:
    """``cfg.count[1]`` shapes (as many as a view may show), each ``cfg.size`` across its largest side."""
    out = []
    for _ in range(cfg.count[1]):
        kind = ("box", "cylinder", "sphere")[int(rng.randint(3))]
        extent = float(rng.uniform(*cfg.size)) / 2
        if kind == "box":
            half = extent * rng.uniform(0.4, 1.0, size=3)
            half[int(rng.randint(3))] = extent
            size = tuple(float(v) for v in half)
        elif kind == "cylinder":
            r, h = extent * float(rng.uniform(0.4, 1.0)), extent * float(rng.uniform(0.4, 1.0))
            size = (r, r, h) if rng.rand() < 0.5 else (min(r, h), min(r, h), extent)
        else:
            size = (extent, extent, extent)
        out.append(Primitive(kind, size))  # type: ignore[arg-type]
    return out


def build_primitive(scene: Any, prim: Primitive, name: str, color: tuple[float, float, float]) -> Any:
    """A kinematic ManiSkill actor of ``prim`` (collision and visual), parked below the table."""
    import sapien

    from capt_env.objects.geometry import quat_from_x_to

    builder = scene.create_actor_builder()
    material = sapien.render.RenderMaterial(base_color=[*color, 1.0], roughness=0.7)
    if prim.kind == "box":
        builder.add_box_collision(half_size=list(prim.size))
        builder.add_box_visual(half_size=list(prim.size), material=material)
    elif prim.kind == "cylinder":  # SAPIEN's cylinders lie along x: stand it up
        pose = sapien.Pose(q=[float(v) for v in quat_from_x_to((0.0, 0.0, 1.0))])
        builder.add_cylinder_collision(pose=pose, radius=prim.size[0], half_length=prim.size[2])
        builder.add_cylinder_visual(pose=pose, radius=prim.size[0], half_length=prim.size[2],
                                    material=material)
    else:
        builder.add_sphere_collision(radius=prim.size[0])
        builder.add_sphere_visual(radius=prim.size[0], material=material)
    builder.initial_pose = sapien.Pose(p=[0.0, 0.0, -5.0])
    return builder.build_kinematic(name=name)


def _gap(xy: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """Distance (m) from the point ``xy`` to the rectangle ``lo``..``hi`` (0 inside)."""
    d = np.maximum(np.maximum(lo - xy, xy - hi), 0.0)
    return float(np.hypot(*d))


def place(prims: list[Primitive], count: int, footprint: tuple[np.ndarray, np.ndarray], cfg: Distractors,
          rng: np.random.RandomState) -> list[np.ndarray | None]:
    """Table positions (x, y, yaw) for the first ``count`` of ``prims`` around ``footprint`` (the
    object's table-plane bounds (lo (2,), hi (2,)), metres): each at a gap uniform in ``cfg.gap``
    from it, at least ``SPACING`` from the others, inside :data:`TABLE_XY`; None where no place was
    found in ``TRIES`` draws (and for the ones past ``count``)."""
    lo, hi = np.asarray(footprint[0], dtype=np.float64), np.asarray(footprint[1], dtype=np.float64)
    (x0, x1), (y0, y1) = TABLE_XY
    placed: list[tuple[np.ndarray, float]] = []
    out: list[np.ndarray | None] = []
    for k, prim in enumerate(prims):
        spot = None
        for _ in range(TRIES if k < count else 0):
            want = float(rng.uniform(*cfg.gap)) + prim.radius
            angle = float(rng.uniform(-math.pi, math.pi))
            # start on the rectangle's boundary towards ``angle``, then step out by ``want``
            centre = (lo + hi) / 2
            direction = np.array([math.cos(angle), math.sin(angle)])
            half = (hi - lo) / 2
            t = min(half[i] / abs(direction[i]) if abs(direction[i]) > 1e-9 else math.inf for i in range(2))
            xy = centre + direction * (t + want)
            r = prim.radius
            ok = (x0 + r <= xy[0] <= x1 - r and y0 + r <= xy[1] <= y1 - r
                  and _gap(xy, lo, hi) >= prim.radius + cfg.gap[0]
                  and all(np.hypot(*(xy - q)) >= prim.radius + r + SPACING for q, r in placed))
            if ok:
                spot = np.array([xy[0], xy[1], float(rng.uniform(-math.pi, math.pi))])
                placed.append((xy, prim.radius))
                break
        out.append(spot)
    return out
