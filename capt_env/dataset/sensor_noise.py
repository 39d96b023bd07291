"""Depth-sensor noise on rendered clouds (``variation.sensor_noise``): dropout at depth edges on the
camera's pixel grid, then Gaussian jitter and stray points from ``perception.corruption`` (the
corruption ``capt train --sensor_noise`` and ``capt evaluate`` use), with labels carried along.

Clouds are world-frame, metres, in ManiSkill's pixel order: each camera's ``height * width`` points
row by row, cameras one after another.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from capt_env.dataset.variation import SensorNoise
from perception.corruption import Corruption, corrupt_points


def depth_edges(xyz: np.ndarray, valid: np.ndarray, eye: np.ndarray, shape: tuple[int, int],
                threshold_m: float) -> np.ndarray:
    """(H * W,) bool: pixels of one camera whose range from ``eye`` (3,) differs from one of their 4
    image neighbours' by more than ``threshold_m``, or which border an invalid (empty) pixel.
    ``xyz`` (H * W, 3) and ``valid`` (H * W,) are that camera's points in pixel order."""
    h, w = shape
    rng_m = np.linalg.norm(np.asarray(xyz, dtype=np.float64) - eye, axis=-1).reshape(h, w)
    ok = np.asarray(valid, dtype=bool).reshape(h, w)
    rng_m = np.where(ok, rng_m, np.inf)
    edge = np.zeros((h, w), dtype=bool)
    for a, b in (((slice(1, None), slice(None)), (slice(None, -1), slice(None))),
                 ((slice(None), slice(1, None)), (slice(None), slice(None, -1)))):
        with np.errstate(invalid="ignore"):
            jump = ~(np.abs(rng_m[a] - rng_m[b]) <= threshold_m)  # inf - inf is nan: an edge too
        edge[a] |= jump
        edge[b] |= jump
    return (edge & ok).reshape(-1)


def edge_dropout_mask(xyz: np.ndarray, valid: np.ndarray, eyes: list[np.ndarray],
                      shapes: list[tuple[int, int]], noise: SensorNoise,
                      rng: np.random.Generator) -> np.ndarray:
    """(N,) bool keep-mask of a multi-camera cloud (``xyz`` (N, 3), ``valid`` (N,)): each camera's
    depth-edge pixels (:func:`depth_edges`) dropped with probability ``noise.edge_dropout``. Draws
    nothing when that is 0."""
    keep = np.ones(len(xyz), dtype=bool)
    if noise.edge_dropout <= 0:
        return keep
    start = 0
    for eye, shape in zip(eyes, shapes, strict=True):
        n = shape[0] * shape[1]
        block = slice(start, start + n)
        edges = depth_edges(xyz[block], valid[block], eye, shape, noise.edge_threshold_m)
        keep[block] &= ~(edges & (rng.random(n) < noise.edge_dropout))
        start += n
    if start != len(xyz):
        raise ValueError(f"cloud has {len(xyz)} points, the cameras {start}")
    return keep


def jitter_and_strays(points: np.ndarray, labels: np.ndarray, noise: SensorNoise,
                      rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``points`` (n, 3) jittered and followed by stray points (``perception.corruption``), and
    ``labels`` (n,) followed by each stray point's nearest point's label. Unchanged (the same
    arrays, nothing drawn) without jitter and strays."""
    corruption = Corruption(jitter_m=noise.jitter_m, outlier_fraction=noise.outlier_fraction)
    if corruption.is_clean:
        return points, labels
    noisy = corrupt_points(points, rng, corruption).astype(np.float32)
    stray = noisy[len(points):]
    stray_labels = labels[cKDTree(points).query(stray)[1]] if len(stray) else labels[:0]
    return noisy, np.concatenate([labels, stray_labels])
