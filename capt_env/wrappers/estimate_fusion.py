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

An estimate whose grasp point was found on a handle (``from_handle``) is worth more than one whose
grasp point fell back to the part's far edge: a hand on the handle hides it, and the fallback
(and the hinge line placed away from it) can land on the wrong side of the part. Once any estimate
found the handle, the pivot and the grasp point come from those only; a moved part whose handle is
not seen now has its last handle point carried with the part to the current state (turned about
the fused axis, or slid along it), as the handle moves rigidly with the part.

For the same reason a handle found on a slid-out part (prismatic) must lie where the slide carried
the last one: one farther than ``handle_jump_m`` m, and than ``handle_jump_share`` of that slide,
from there is another protrusion and counts as not seen (drawer seed 143: the handle search stayed
on the cabinet's front where the drawer had been while it slid 22 cm open, and a re-grasp there
pushed the drawer shut). Not for hinges: an estimated angle 0.2 rad off moves a handle 0.3 m from
the hinge by 6 cm, and the check rejected the handle itself (washing machine seeds 119-123 failed
with it, measured).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from capt_common.typed_yaml import require
from capt_env.objects.geometry import rotate_about_axis
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


@dataclass(frozen=True)
class FusionConfig:
    """``state_tolerance`` (rad or m): the part counts as not moved while the state is within it of
    the first look's; ``handle_jump_m`` (m) and ``handle_jump_share`` (of the slide): a handle seen on
    a slid-out part farther than both from where the slide carried the last one is not trusted."""

    state_tolerance: float = 0.05
    handle_jump_m: float = 0.05
    handle_jump_share: float = 0.5

    def validate(self) -> None:
        require(self.state_tolerance >= 0 and self.handle_jump_share >= 0 and self.handle_jump_m > 0,
                "fusion.state_tolerance and fusion.handle_jump_share must be >= 0, "
                "fusion.handle_jump_m > 0")


class EstimateFusion:
    """Running confidence-weighted fusion; call :meth:`reset` at every episode start. The defaults
    are :class:`FusionConfig`'s (``EstimateFusion(**asdict(config))``)."""

    def __init__(self, state_tolerance: float = FusionConfig.state_tolerance,
                 handle_jump_m: float = FusionConfig.handle_jump_m,
                 handle_jump_share: float = FusionConfig.handle_jump_share) -> None:
        if state_tolerance < 0 or handle_jump_m <= 0 or handle_jump_share < 0:
            raise ValueError("state_tolerance and handle_jump_share must be >= 0, handle_jump_m > 0")
        self.state_tolerance = state_tolerance
        self.handle_jump_m = handle_jump_m
        self.handle_jump_share = handle_jump_share
        self.reset()

    def reset(self) -> None:
        self._weight = 0.0
        self._direction = np.zeros(3)
        self._signed: list[tuple[float, np.ndarray]] = []
        self._pivots: list[tuple[np.ndarray, float, bool]] = []  # (pivot, weight, from_handle)
        self._grasps: list[tuple[np.ndarray, float, bool]] = []  # while the part has not moved
        self._handle_grasp: tuple[np.ndarray, float] | None = None  # latest (point, state) on the handle
        self._first_state: float | None = None

    def update(self, estimate: JointAxisEstimate, from_handle: bool = True) -> JointAxisEstimate:
        """Add ``estimate`` (world frame) and return the fused estimate. ``from_handle``: its grasp
        point was found on a handle (not the fallback far edge of the part)."""
        w = max(float(estimate.confidence), 1e-3)
        d = unit(estimate.direction)
        latest = np.asarray(estimate.grasp_point, dtype=np.float64)
        state = float(estimate.state)
        if self._first_state is None:
            self._first_state = state
        moved = abs(state - self._first_state) > self.state_tolerance
        self._signed.append((w, d))
        aligned = -d if self._weight > 0 and float(self._direction @ d) < 0 else d
        self._direction += w * aligned
        self._weight += w
        direction = unit(self._direction)
        vote = sum(wi * float(np.sign(di @ direction)) for wi, di in self._signed)
        if vote < 0:
            direction = -direction
        if from_handle and moved and estimate.joint_type == "prismatic" and self._handle_grasp is not None:
            handle, handle_state = self._handle_grasp
            slide = state - handle_state
            if float(np.linalg.norm(latest - (handle + slide * direction))) > max(
                    self.handle_jump_m, self.handle_jump_share * abs(slide)):
                from_handle = False  # not where the slide carried its handle: something else
        self._pivots.append((np.asarray(estimate.pivot, dtype=np.float64), w, from_handle))
        line_point = robust_centre(*_trusted(self._pivots))
        if from_handle:
            self._handle_grasp = (latest, state)
        if not moved:
            self._grasps.append((latest, w, from_handle))
            grasp = robust_centre(*_trusted(self._grasps))
        elif from_handle or self._handle_grasp is None:
            grasp = latest
        else:
            handle, handle_state = self._handle_grasp
            grasp = moved_with_part(handle, estimate.joint_type, direction, line_point,
                                    state - handle_state)
        pivot = canonical_pivot(direction, line_point, grasp)
        agreement = float(np.linalg.norm(self._direction) / self._weight)
        return JointAxisEstimate(estimate.joint_type, direction, pivot, float(estimate.state), grasp,
                                 float(min(1.0, agreement * estimate.confidence)))


def moved_with_part(point: np.ndarray, joint_type: str, direction: np.ndarray, line_point: np.ndarray,
                    delta: float) -> np.ndarray:
    """``point`` (3,) on a part, moved with the part by ``delta`` of its joint state: turned by
    ``delta`` rad about the line through ``line_point`` along unit ``direction`` (right hand;
    revolute) or slid ``delta`` m along ``direction`` (prismatic). World frame, metres."""
    if joint_type == "prismatic":
        return point + delta * direction
    return rotate_about_axis(point[None], direction, line_point, delta)[0]


def _trusted(entries: list[tuple[np.ndarray, float, bool]]) -> tuple[list[np.ndarray], list[float]]:
    """(points, weights) of the entries found on a handle, or of all entries when none was."""
    kept = [e for e in entries if e[2]] or entries
    return [e[0] for e in kept], [e[1] for e in kept]
