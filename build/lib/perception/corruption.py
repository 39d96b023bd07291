"""Seeded sensor corruption of test clouds, to measure how an estimator degrades on noisy input.

Two corruptions a depth camera produces, applied to one object cloud (world frame, metres) in this order:

- ``jitter_m``: every point moves by isotropic Gaussian noise with this standard deviation in metres;
- ``outlier_fraction``: ``round(outlier_fraction * n)`` points are appended, uniform in the axis-aligned
  bounding box of the clean cloud (stray returns of the kind that double voting is meant to reject;
  kept inside the box so that the bounding-box normalisation, and so the normalised frame, is the
  clean cloud's).

For test clouds (:func:`corrupt_cloud`) the draw depends on the sample's split index alone
(``np.random.default_rng([CORRUPTION_SEED, index])``), so every checkpoint scored in one run sees the same
corrupted clouds and a paired comparison stays paired. The first ``n`` points of the result are the
clean points (jittered) in their original order; outliers have no ground-truth part, so segmentation is
scored on those first ``n`` only. For training (:func:`corrupt_points` with the epoch's generator, as
``TrainConfig.sensor_noise`` does) the draw changes every epoch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

CORRUPTION_SEED = 31337


@dataclass(frozen=True)
class Corruption:
    """Gaussian jitter (standard deviation, metres) and the fraction of stray points added (of the clean
    point count). The default is no corruption."""

    jitter_m: float = 0.0
    outlier_fraction: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.jitter_m) and self.jitter_m >= 0.0):
            raise ValueError(f"jitter_m must be a finite number >= 0 (metres), got {self.jitter_m!r}")
        if not (math.isfinite(self.outlier_fraction) and 0.0 <= self.outlier_fraction <= 1.0):
            raise ValueError(f"outlier_fraction must be in [0, 1], got {self.outlier_fraction!r}")

    @property
    def is_clean(self) -> bool:
        """True when this corruption changes nothing."""
        return self.jitter_m == 0.0 and self.outlier_fraction == 0.0

    def describe(self) -> str:
        """A short human-readable label, e.g. ``"jitter 5.0 mm, outliers 10%"`` or ``"none"``."""
        parts = []
        if self.jitter_m > 0.0:
            parts.append(f"jitter {self.jitter_m * 1000:.1f} mm")
        if self.outlier_fraction > 0.0:
            parts.append(f"outliers {self.outlier_fraction:.0%}")
        return ", ".join(parts) or "none"


def corrupt_cloud(points: np.ndarray, index: int, corruption: Corruption) -> np.ndarray:
    """Test cloud ``index``'s corruption: :func:`corrupt_points` with the index's fixed generator."""
    return corrupt_points(points, np.random.default_rng([CORRUPTION_SEED, int(index)]), corruption)


def corrupt_points(points: np.ndarray, rng: np.random.Generator, corruption: Corruption) -> np.ndarray:
    """``points`` (n, 3) metres -> (n + m, 3): the clean points jittered, then ``m`` outliers (see the
    module docstring), drawn from ``rng``. A clean ``corruption`` returns the input unchanged (same
    object) and draws nothing."""
    pts = np.asarray(points, np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0:
        raise ValueError(f"points must have shape (n, 3) with n > 0, got {pts.shape}")
    if corruption.is_clean:
        return points
    noisy = pts + rng.normal(0.0, corruption.jitter_m, size=pts.shape) if corruption.jitter_m > 0 else pts
    m = int(round(corruption.outlier_fraction * len(pts)))
    if m == 0:
        return noisy
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return np.concatenate([noisy, rng.uniform(lo, hi, size=(m, 3))])
