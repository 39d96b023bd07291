"""Double voting (paper Sec. III-D): coarse mean of per-point predictions, then a fine mean over the
points whose distance to the coarse axis lies in [w0, w1] x median distance.

Everything here is numpy, one sample at a time, in the normalised object frame. For each joint k:

- coarse: direction = normalised mean of per-point directions; pivot = mean of p + dist * pdir;
  state = mean of per-point states;
- fine (``double=True``): distances of the *points* p to the coarse axis, keep the points with
  distance in [w0 * median, w1 * median], and average their predictions as above; fewer than
  ``min_points`` kept -> the coarse answer.
- prismatic joints have no axis position: their direction and state are voted by plain mean over all
  points, and their pivot is only a display point (centroid of the points of the predicted child part,
  or of all points).
- confidence = length of the mean of the unit per-point directions over the voting set, in [0, 1]
  (1 when every point agrees).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

REVOLUTE, PRISMATIC = 0, 1


@dataclass(frozen=True)
class JointVote:
    """Voted joint in the normalised frame: unit direction (3,), pivot (3,), state, confidence in [0, 1],
    and how many points took part in the final vote."""

    direction: np.ndarray
    pivot: np.ndarray
    state: float
    confidence: float
    num_voters: int


@dataclass(frozen=True)
class PointPredictions:
    """One sample's per-point outputs (normalised frame): points (n,3), dir (n,J,3), dist (n,J),
    pdir (n,J,3), state (n,J); ``child_mask`` (n,J) optional predicted child part of each joint."""

    points: np.ndarray
    dir: np.ndarray
    dist: np.ndarray
    pdir: np.ndarray
    state: np.ndarray
    child_mask: np.ndarray | None = None


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, 1e-12)


def point_axis_distance(points: np.ndarray, u: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Psi_dist: distance of points (n,3) to the line through q (3,) along unit u (3,)."""
    v = points - q
    return np.linalg.norm(v - (v @ u)[:, None] * u, axis=-1)


def _mean_vote(dirs: np.ndarray, pivots: np.ndarray, states: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                                   float, float]:
    mean_dir = _unit(dirs).mean(axis=0)
    return _unit(mean_dir), pivots.mean(axis=0), float(states.mean()), float(np.linalg.norm(mean_dir))


def vote_joint(pred: PointPredictions, k: int, joint_type: int, w0: float, w1: float,
               double: bool = True, min_points: int = 8) -> JointVote:
    """Vote joint slot ``k`` of one sample (see module docstring)."""
    pts = np.asarray(pred.points, dtype=np.float64)
    dirs = np.asarray(pred.dir[:, k], dtype=np.float64)
    states = np.asarray(pred.state[:, k], dtype=np.float64)
    if joint_type == PRISMATIC:
        sel = pred.child_mask[:, k] if pred.child_mask is not None else None
        display = pts[sel].mean(axis=0) if sel is not None and sel.any() else pts.mean(axis=0)
        u, _, s, conf = _mean_vote(dirs, pts, states)
        return JointVote(u, display, s, conf, len(pts))
    pivots = pts + np.asarray(pred.dist[:, k], dtype=np.float64)[:, None] * np.asarray(pred.pdir[:, k],
                                                                                        dtype=np.float64)
    u, q, s, conf = _mean_vote(dirs, pivots, states)
    if not double:
        return JointVote(u, q, s, conf, len(pts))
    d = point_axis_distance(pts, u, q)
    med = float(np.median(d))
    keep = (d >= w0 * med) & (d <= w1 * med)
    if int(keep.sum()) < min_points:
        return JointVote(u, q, s, conf, len(pts))
    u, q, s, conf = _mean_vote(dirs[keep], pivots[keep], states[keep])
    return JointVote(u, q, s, conf, int(keep.sum()))


def vote(pred: PointPredictions, joint_types: Sequence[int], w0: float, w1: float, double: bool = True,
         min_points: int = 8) -> list[JointVote]:
    """Vote every joint slot; ``joint_types`` gives 0 (revolute) or 1 (prismatic) per slot."""
    return [vote_joint(pred, k, int(t), w0, w1, double, min_points) for k, t in enumerate(joint_types)]


def window_error(votes: Sequence[Sequence[JointVote]], gt_dirs: Sequence[np.ndarray],
                 gt_pivots: Sequence[np.ndarray], gt_masks: Sequence[np.ndarray],
                 joint_types: Sequence[int] | Sequence[Sequence[int]], dir_scale_deg: float = 10.0,
                 pos_scale: float = 0.05) -> float:
    """Mean over present joints of direction error / ``dir_scale_deg`` + line distance / ``pos_scale``
    (the second for revolute joints only); the AP10 and AP5 thresholds make the two comparable.
    ``joint_types``: per slot, or per sample and slot (see :func:`choose_voting_window`)."""
    from perception.metrics import direction_error_deg, line_distance

    errs = []
    per_sample = _types_per_sample(joint_types, len(votes))
    for sample_votes, dirs, pivots, mask, types in zip(votes, gt_dirs, gt_pivots, gt_masks, per_sample,
                                                       strict=True):
        for k, v in enumerate(sample_votes):
            if not mask[k]:
                continue
            e = direction_error_deg(v.direction, dirs[k]) / dir_scale_deg
            if types[k] == REVOLUTE:
                e += line_distance(v.direction, v.pivot, dirs[k], pivots[k]) / pos_scale
            errs.append(e)
    return float(np.mean(errs)) if errs else 0.0


def choose_voting_window(preds: Sequence[PointPredictions], gt_dirs: Sequence[np.ndarray],
                         gt_pivots: Sequence[np.ndarray], gt_masks: Sequence[np.ndarray],
                         joint_types: Sequence[int] | Sequence[Sequence[int]], grid_w0: Sequence[float],
                         grid_w1: Sequence[float], min_points: int = 8) -> tuple[float, float, float]:
    """Grid-search (w0, w1) on validation predictions (normalised frame) to minimise
    :func:`window_error`; returns (w0, w1, error). Ties keep the first pair in grid order.
    ``joint_types`` gives each slot's type for every sample, or one sequence per sample (a
    cross-category model's slots have each object's own types)."""
    if not preds:
        raise ValueError("choose_voting_window needs at least one validation sample")
    per_sample = _types_per_sample(joint_types, len(preds))
    best: tuple[float, float, float] | None = None
    for w0 in grid_w0:
        for w1 in grid_w1:
            if not w0 < w1:
                continue
            votes = [vote(p, t, w0, w1, True, min_points) for p, t in zip(preds, per_sample, strict=True)]
            err = window_error(votes, gt_dirs, gt_pivots, gt_masks, joint_types)
            if best is None or err < best[2] - 1e-12:
                best = (float(w0), float(w1), err)
    if best is None:
        raise ValueError("no (w0, w1) pair in the grids has w0 < w1")
    return best


def _types_per_sample(joint_types: Sequence[int] | Sequence[Sequence[int]], n: int) -> list[Sequence[int]]:
    """``joint_types`` as one sequence of slot types per sample (a shared per-slot sequence repeated)."""
    if len(joint_types) and np.ndim(joint_types[0]) > 0:
        if len(joint_types) != n:
            raise ValueError(f"got slot types for {len(joint_types)} samples, need {n}")
        return list(joint_types)
    return [joint_types] * n
