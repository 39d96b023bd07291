"""Fuse successive CAPT estimates of one joint within an episode.

A hinge or a drawer slide does not move relative to the object's base, so each new single-view
estimate of its axis is another noisy look at the same line: the fused axis is the confidence-weighted
mean direction (each new direction sign-aligned with the running mean) through the weighted mean
pivot. The grasp point is averaged only while the part has not moved (state within
``state_tolerance`` of the first estimate); once it moves, the latest grasp point is used. The state
is always the latest estimate.
"""

from __future__ import annotations

import numpy as np

from capt_env.wrappers.estimate import JointAxisEstimate, canonical_pivot, unit


class EstimateFusion:
    """Running confidence-weighted fusion; call :meth:`reset` at every episode start."""

    def __init__(self, state_tolerance: float = 0.05) -> None:
        self.state_tolerance = state_tolerance
        self.reset()

    def reset(self) -> None:
        self._weight = 0.0
        self._direction = np.zeros(3)
        self._pivot = np.zeros(3)
        self._grasp = np.zeros(3)
        self._grasp_weight = 0.0
        self._first_state: float | None = None

    def update(self, estimate: JointAxisEstimate) -> JointAxisEstimate:
        """Add ``estimate`` (world frame) and return the fused estimate."""
        w = max(float(estimate.confidence), 1e-3)
        d = unit(estimate.direction)
        if self._weight > 0 and float(self._direction @ d) < 0:
            d = -d
        self._direction += w * d
        self._pivot += w * np.asarray(estimate.pivot, dtype=np.float64)
        self._weight += w
        if self._first_state is None:
            self._first_state = float(estimate.state)
        moved = abs(float(estimate.state) - self._first_state) > self.state_tolerance
        if moved:
            grasp = np.asarray(estimate.grasp_point, dtype=np.float64)
        else:
            self._grasp += w * np.asarray(estimate.grasp_point, dtype=np.float64)
            self._grasp_weight += w
            grasp = self._grasp / self._grasp_weight
        direction = unit(self._direction)
        pivot = canonical_pivot(direction, self._pivot / self._weight, grasp)
        agreement = float(np.linalg.norm(self._direction) / self._weight)
        return JointAxisEstimate(estimate.joint_type, direction, pivot, float(estimate.state), grasp,
                                 float(min(1.0, agreement * estimate.confidence)))
