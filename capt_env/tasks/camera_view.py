"""Whether world points fall inside a depth camera's picture, and how far back it must move to see them.

A task camera looks at the object's bounding-box centre from a fixed offset
(:class:`~capt_env.tasks.config.CameraConfig`). On a large or deep object (a kitchen cabinet 0.9 m
wide with its handle at the front corner) the part's handle can fall outside every camera's
picture; perception then cannot find it whatever the network, so the task says so (see
``OpenArticulatedEnv.grasp_point_views``). Cameras follow OpenCV's convention, as ManiSkill's
``intrinsic_cv`` / ``extrinsic_cv`` give them: camera frame x right, y down, z forward; metres.
"""

from __future__ import annotations

import numpy as np


def camera_frame(points: np.ndarray, extrinsic: np.ndarray) -> np.ndarray:
    """World points (n, 3) in the camera frame (OpenCV; ``extrinsic`` world -> camera, 3x4 or 4x4)."""
    ext = np.asarray(extrinsic, dtype=np.float64)
    return np.asarray(points, dtype=np.float64) @ ext[:3, :3].T + ext[:3, 3]


def pixels(points: np.ndarray, intrinsic: np.ndarray, extrinsic: np.ndarray) -> np.ndarray:
    """Pixel (u, v) (n, 2) of world points (n, 3); meaningless for points behind the camera."""
    uvw = camera_frame(points, extrinsic) @ np.asarray(intrinsic, dtype=np.float64).T
    return uvw[:, :2] / np.maximum(uvw[:, 2:3], 1e-6)


def in_picture(points: np.ndarray, intrinsic: np.ndarray, extrinsic: np.ndarray, width: int,
               height: int) -> np.ndarray:
    """(n,) bool: each world point (n, 3) is in front of the camera and inside its ``width`` x
    ``height`` picture."""
    depth = camera_frame(points, extrinsic)[:, 2]
    uv = pixels(points, intrinsic, extrinsic)
    inside = (uv[:, 0] >= 0) & (uv[:, 0] <= width) & (uv[:, 1] >= 0) & (uv[:, 1] <= height)
    return (depth > 0) & inside


def step_back_to_see(points: np.ndarray, intrinsic: np.ndarray, extrinsic: np.ndarray, width: int,
                     height: int) -> float:
    """How far (m) the camera must move back along its line of sight, turned the same way, for every
    world point (n, 3) to be inside its picture; 0 when they already are. Moving back by ``d`` adds
    ``d`` to every point's depth and leaves its offset from the line of sight as it is."""
    k = np.asarray(intrinsic, dtype=np.float64)
    cam = camera_frame(points, extrinsic)
    x, y = cam[:, 0], cam[:, 1]  # offsets from the optical axis
    # pixel u = fx x / z + cx stays in [0, width] while z >= fx |x| / (cx or width - cx on its side)
    room_x = np.where(x >= 0, width - k[0, 2], k[0, 2])
    room_y = np.where(y >= 0, height - k[1, 2], k[1, 2])
    needed = np.maximum(k[0, 0] * np.abs(x) / room_x, k[1, 1] * np.abs(y) / room_y)
    return float(max(0.0, np.max(needed - cam[:, 2])))
