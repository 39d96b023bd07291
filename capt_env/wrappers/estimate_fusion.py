"""Fuse successive CAPT estimates of one joint within an episode.

A hinge or a drawer slide does not move relative to the object's base, so each new single-view
estimate of its axis is another noisy look at the same line. The fused axis is the confidence-weighted
mean of the directions (each sign-aligned with the running mean); its sign is the weighted vote of
the estimates' own signs (each set by geometry, so one bad first look cannot fix the sign for the
episode). The pivot, and the grasp point while the part has not moved (state within
``state_tolerance`` of the first estimate), are weighted means of the estimates for up to two of
them and coordinate-wise weighted medians from three on, so one grasp point found on the wrong part
is outvoted. Once the part moves, the latest grasp point is used. The state is always the latest
estimate.
"""

from __future__ import annotations

import numpy as np

from capt_env.wrappers.estimate import JointAxisEstimate, canonical_pivot, unit


def robust_centre(points: list[np.ndarray], weights: list[float]) -> np.ndarray:
    """Weighted mean of up to two points (3,), coordinate-wise weighted median of three or more."""
    p = np.asarray(points, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    if len(p) <= 2:
        return (w[:, None] * p).sum(axis=0) / w.sum()
    out = np.empty(p.shape[1])
    for k in range(p.shape[1]):
        order = np.argsort(p[:, k])
        cum = np.cumsum(w[order])
        out[k] = p[order[int(np.searchsorted(cum, 0.5 * cum[-1]))], k]
    return out


class EstimateFusion:
    """Running confidence-weighted fusion; call :meth:`reset` at every episode start."""

    def __init__(self, state_tolerance: float = 0.05) -> None:
        self.state_tolerance = state_tolerance
        self.reset()

    def reset(self) -> None:
        self._weight = 0.0
        self._direction = np.zeros(3)
        self._signed: list[tuple[float, np.ndarray]] = []
        self._pivots: list[np.ndarray] = []
        self._weights: list[float] = []
        self._grasps: list[np.ndarray] = []
        self._grasp_weights: list[float] = []
        self._first_state: float | None = None

    def update(self, estimate: JointAxisEstimate) -> JointAxisEstimate:
        """Add ``estimate`` (world frame) and return the fused estimate."""
        w = max(float(estimate.confidence), 1e-3)
        d = unit(estimate.direction)
        self._signed.append((w, d))
        aligned = -d if self._weight > 0 and float(self._direction @ d) < 0 else d
        self._direction += w * aligned
        self._weight += w
        self._pivots.append(np.asarray(estimate.pivot, dtype=np.float64))
        self._weights.append(w)
        if self._first_state is None:
            self._first_state = float(estimate.state)
        moved = abs(float(estimate.state) - self._first_state) > self.state_tolerance
        if moved:
            grasp = np.asarray(estimate.grasp_point, dtype=np.float64)
        else:
            self._grasps.append(np.asarray(estimate.grasp_point, dtype=np.float64))
            self._grasp_weights.append(w)
            grasp = robust_centre(self._grasps, self._grasp_weights)
        direction = unit(self._direction)
        vote = sum(wi * float(np.sign(di @ direction)) for wi, di in self._signed)
        if vote < 0:
            direction = -direction
        pivot = canonical_pivot(direction, robust_centre(self._pivots, self._weights), grasp)
        agreement = float(np.linalg.norm(self._direction) / self._weight)
        return JointAxisEstimate(estimate.joint_type, direction, pivot, float(estimate.state), grasp,
                                 float(min(1.0, agreement * estimate.confidence)))
