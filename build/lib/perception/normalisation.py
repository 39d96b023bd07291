"""The normalised object frame the CAPT network works in (paper Sec. IV-A, "point cloud normalization").

centre = centre of the cloud's axis-aligned bounding box, scale = length of its diagonal, so a
normalised object fits a box of unit diagonal centred at the origin. No rotation: directions are the
same in both frames. Lengths (pivots, distances, prismatic states) scale by 1/scale; revolute states
(radians) are unchanged. Works on numpy arrays (float64 math) and returns float64.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Normalisation:
    """x_norm = (x - centre) / scale. ``centre`` (3,) in the caller's frame (metres), ``scale`` metres."""

    centre: np.ndarray
    scale: float

    @classmethod
    def fit(cls, points: np.ndarray, min_scale: float = 1e-6) -> Normalisation:
        """Bounding-box centre and diagonal of ``points`` (N, 3)."""
        pts = np.asarray(points, dtype=np.float64)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return cls(centre=(lo + hi) / 2.0, scale=float(max(np.linalg.norm(hi - lo), min_scale)))

    def points(self, x: np.ndarray) -> np.ndarray:
        """Points or pivots (..., 3): caller frame -> normalised frame."""
        return (np.asarray(x, dtype=np.float64) - self.centre) / self.scale

    def points_inv(self, x: np.ndarray) -> np.ndarray:
        """Points or pivots (..., 3): normalised frame -> caller frame."""
        return np.asarray(x, dtype=np.float64) * self.scale + self.centre

    def length(self, d: np.ndarray | float) -> np.ndarray:
        """Lengths (distances, prismatic states): metres -> normalised units."""
        return np.asarray(d, dtype=np.float64) / self.scale

    def length_inv(self, d: np.ndarray | float) -> np.ndarray:
        """Lengths: normalised units -> metres."""
        return np.asarray(d, dtype=np.float64) * self.scale

    def states(self, states: np.ndarray, prismatic: np.ndarray) -> np.ndarray:
        """Joint states (J,): prismatic (bool mask) scaled to normalised units, revolute unchanged."""
        s = np.asarray(states, dtype=np.float64)
        return np.where(np.asarray(prismatic, dtype=bool), s / self.scale, s)

    def states_inv(self, states: np.ndarray, prismatic: np.ndarray) -> np.ndarray:
        """Joint states (J,): normalised -> caller units (metres for prismatic, radians for revolute)."""
        s = np.asarray(states, dtype=np.float64)
        return np.where(np.asarray(prismatic, dtype=bool), s * self.scale, s)

    @staticmethod
    def directions(u: np.ndarray) -> np.ndarray:
        """Directions (..., 3) are unchanged by translation and uniform scale."""
        return np.asarray(u, dtype=np.float64)
