"""Find the points of a cloud that lie on the robot, from its link poses and collision shapes.

Each link's collision shapes (convex meshes and boxes) are turned into convex hulls once, in the link
frame; per call they are moved by the links' current world poses and a point counts as robot if it
lies inside a hull inflated by a margin (every hull face plane pushed out by ``margin`` metres).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial import ConvexHull


@dataclass(frozen=True)
class _Hull:
    link_index: int
    normals: np.ndarray  # (F, 3) outward unit face normals, link frame
    offsets: np.ndarray  # (F,) plane offsets: inside iff normals @ x + offsets <= 0
    centre: np.ndarray  # (3,) link frame
    radius: float  # bounding-sphere radius about centre, metres


def _box_vertices(half: np.ndarray) -> np.ndarray:
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)
    return signs * half


def _shape_vertices(shape: Any) -> np.ndarray | None:
    """Vertices of one SAPIEN collision shape in its link's frame, or None for unsupported shapes."""
    if hasattr(shape, "vertices"):
        verts = np.asarray(shape.vertices, dtype=np.float64) * np.asarray(shape.scale, dtype=np.float64)
    elif hasattr(shape, "half_size"):
        verts = _box_vertices(np.asarray(shape.half_size, dtype=np.float64))
    elif hasattr(shape, "radius") and hasattr(shape, "half_length"):  # capsule along x
        rad, hl = float(shape.radius), float(shape.half_length)
        verts = _box_vertices(np.array([hl + rad, rad, rad]))
    elif hasattr(shape, "radius"):  # sphere
        verts = _box_vertices(np.full(3, float(shape.radius)))
    else:
        return None
    mat = shape.get_local_pose().to_transformation_matrix()
    return verts @ mat[:3, :3].T + mat[:3, 3]


class RobotPointFilter:
    """Masks points on a ManiSkill robot (``env.unwrapped.agent.robot``, one sub-scene)."""

    def __init__(self, robot: Any) -> None:
        self.robot = robot
        self.links = list(robot.links)
        hulls = []
        for i, link in enumerate(self.links):
            for shape in link._objs[0].collision_shapes:
                verts = _shape_vertices(shape)
                if verts is None or len(verts) < 4:
                    continue
                hull = ConvexHull(verts)
                centre = verts.mean(axis=0)
                hulls.append(_Hull(i, hull.equations[:, :3], hull.equations[:, 3], centre,
                                   float(np.linalg.norm(verts - centre, axis=1).max())))
        self.hulls = hulls

    def link_poses(self) -> list[np.ndarray]:
        """(4, 4) world transform of every link (sub-scene 0)."""
        return [np.asarray(link.pose.to_transformation_matrix()[0].cpu().numpy(), dtype=np.float64)
                for link in self.links]

    def mask(self, points: np.ndarray, margin: float) -> np.ndarray:
        """(N,) bool: True where a point (N, 3) world frame lies within ``margin`` m of a link's shape."""
        poses = self.link_poses()
        out = np.zeros(len(points), dtype=bool)
        for hull in self.hulls:
            mat = poses[hull.link_index]
            local = (points - mat[:3, 3]) @ mat[:3, :3]  # world -> link frame
            near = np.linalg.norm(local - hull.centre, axis=1) <= hull.radius + margin
            if not near.any():
                continue
            idx = np.flatnonzero(near)
            inside = (local[idx] @ hull.normals.T + hull.offsets <= margin).all(axis=1)
            out[idx[inside]] = True
        return out
