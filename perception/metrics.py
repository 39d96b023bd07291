"""Evaluation metrics of the paper (Sec. IV-C, Table I): segmentation PA and mIoU, axis direction error
(MED, AP5/AP10), axis position error (AED, AP1/AP5), joint state error (MED, AP5/AP10), time per input.

Conventions:
- Direction error is the angle between the predicted and the true *signed* direction, in [0, 180]
  degrees: the library fixes a sign per joint (+state opens), so a flipped axis counts as 180.
- Position error is the distance between the predicted and the true axis lines (0 when they
  intersect, the perpendicular separation when parallel), reported in the normalised object frame
  (unit bounding-box diagonal, comparable with the paper) and in metres. Prismatic joints have no
  position: their position error is None (skipped by every aggregate).
- State error: degrees for revolute joints, metres for prismatic joints. AP thresholds: 5 and 10
  degrees (revolute); 0.01 and 0.05 m (prismatic).
- mIoU averages the IoU over the parts that occur in the ground truth or the prediction of that sample
  (points with ground truth -1 are ignored).
- AP x = share of results with error strictly below x.
- Beyond the paper, each summary also has the median direction error and the share of axes that
  point the other way (``dir_flipped``: error over 90 degrees): a few whole sign flips can carry a
  mean error whose median is a fraction of a degree; and the median axis-line distance in metres
  (``pos_median_m``) and median state error (``state_median``, degrees or metres), shown with the
  direction's in :func:`median_table_markdown`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

DIR_THRESHOLDS_DEG = (5.0, 10.0)
FLIPPED_ABOVE_DEG = 90.0
POS_THRESHOLDS = (0.01, 0.05)
STATE_THRESHOLDS_DEG = (5.0, 10.0)
STATE_THRESHOLDS_M = (0.01, 0.05)


def segmentation_accuracy(pred: np.ndarray, gt: np.ndarray) -> float:
    """Per-point accuracy over points with gt >= 0."""
    pred, gt = np.asarray(pred), np.asarray(gt)
    valid = gt >= 0
    return float((pred[valid] == gt[valid]).mean()) if valid.any() else float("nan")


def mean_iou(pred: np.ndarray, gt: np.ndarray) -> float:
    """Mean IoU over parts present in gt or prediction (among points with gt >= 0)."""
    pred, gt = np.asarray(pred), np.asarray(gt)
    valid = gt >= 0
    pred, gt = pred[valid], gt[valid]
    parts = np.union1d(np.unique(gt), np.unique(pred))
    if len(parts) == 0:
        return float("nan")
    ious = [np.sum((pred == c) & (gt == c)) / np.sum((pred == c) | (gt == c)) for c in parts]
    return float(np.mean(ious))


def _unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / max(float(np.linalg.norm(v)), 1e-12)


def direction_error_deg(pred: np.ndarray, gt: np.ndarray) -> float:
    """Angle in degrees, [0, 180], between two signed directions (3,)."""
    a, b = _unit(pred), _unit(gt)
    return math.degrees(math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b)))


def line_distance(u1: np.ndarray, q1: np.ndarray, u2: np.ndarray, q2: np.ndarray,
                  parallel_tol: float = 1e-6) -> float:
    """Distance between the lines (q1, u1) and (q2, u2), as :func:`perception.geometry.line_line_distance`."""
    u1, u2 = _unit(u1), _unit(u2)
    w = np.asarray(q2, dtype=np.float64) - np.asarray(q1, dtype=np.float64)
    cross = np.cross(u1, u2)
    cn = float(np.linalg.norm(cross))
    if cn < parallel_tol:
        return float(np.linalg.norm(w - (w @ u1) * u1))
    return abs(float(w @ cross)) / cn


def state_error(pred: float, gt: float, joint_type: str) -> float:
    """|pred - gt| in degrees (revolute, inputs radians) or metres (prismatic, inputs metres)."""
    err = abs(float(pred) - float(gt))
    return math.degrees(err) if joint_type == "revolute" else err


def _finite(errors: Sequence[float | None]) -> np.ndarray:
    return np.asarray([x for x in errors if x is not None and not math.isnan(x)], dtype=np.float64)


def average_precision(errors: Sequence[float], threshold: float) -> float:
    """Share of errors strictly below ``threshold`` (NaN when there are none)."""
    e = _finite(errors)
    return float((e < threshold).mean()) if len(e) else float("nan")


@dataclass(frozen=True)
class JointResult:
    """Errors of one joint of one sample. ``position_error`` normalised units (None for prismatic),
    ``position_error_m`` metres, ``state_error`` degrees (revolute) or metres (prismatic)."""

    joint_index: int
    joint_type: str
    direction_error_deg: float
    position_error: float | None
    position_error_m: float | None
    state_error: float


@dataclass(frozen=True)
class SampleResult:
    """Metrics of one evaluated cloud; ``pa``/``miou`` None when the method has no segmentation;
    ``instance_id`` the object instance the cloud shows (a test split has several views of each);
    ``missed_joints`` the cloud's joints the method gave no estimate for (a cross-category model that
    predicted their slot absent) and ``true_joints`` how many it has."""

    category: str
    method: str
    pa: float | None
    miou: float | None
    joints: tuple[JointResult, ...] = field(default_factory=tuple)
    time_ms: float | None = None
    instance_id: int | None = None
    missed_joints: int = 0
    true_joints: int = 0


def _share_above(errors: Sequence[float], threshold: float) -> float:
    """Share of errors strictly above ``threshold`` (NaN when there are none)."""
    e = _finite(errors)
    return float((e > threshold).mean()) if len(e) else float("nan")


def _mean(xs: Sequence[float | None]) -> float:
    v = [x for x in xs if x is not None and not math.isnan(x)]
    return float(np.mean(v)) if v else float("nan")


def _median(xs: Sequence[float]) -> float:
    return float(np.median(xs)) if len(xs) else float("nan")


def summarise(results: Sequence[SampleResult]) -> dict[str, float | list[float]]:
    """Aggregate one (category, method) group: scalars for segmentation/time, per-joint lists otherwise
    (the paper's columns, then ``dir_median`` in degrees, ``dir_flipped``, the share of direction
    errors over :data:`FLIPPED_ABOVE_DEG`, ``pos_median_m`` in metres and ``state_median`` in
    degrees or metres)."""
    out: dict[str, float | list[float]] = {
        "pa": _mean([r.pa for r in results]),
        "miou": _mean([r.miou for r in results]),
        "time_ms": _mean([r.time_ms for r in results]),
        "joints_missed": sum(r.missed_joints for r in results) / max(1, sum(r.true_joints for r in results)),
    }
    slots = sorted({j.joint_index for r in results for j in r.joints})
    keys = ["dir_med", "dir_ap5", "dir_ap10", "pos_aed", "pos_ap1", "pos_ap5", "state_med", "state_ap5",
            "state_ap10", "dir_median", "dir_flipped", "pos_median_m", "state_median"]
    cols: dict[str, list[float]] = {k: [] for k in keys}
    for k in slots:  # by joint slot (true joints fill the first slots, so this is their order)
        js = [j for r in results for j in r.joints if j.joint_index == k]
        d = [j.direction_error_deg for j in js]
        p = [j.position_error for j in js if j.position_error is not None]
        p_m = [j.position_error_m for j in js if j.position_error_m is not None]
        s = [j.state_error for j in js]
        st = STATE_THRESHOLDS_DEG if js and js[0].joint_type == "revolute" else STATE_THRESHOLDS_M
        vals = [_mean(d), average_precision(d, DIR_THRESHOLDS_DEG[0]),
                average_precision(d, DIR_THRESHOLDS_DEG[1]),
                _mean(p), average_precision(p, POS_THRESHOLDS[0]), average_precision(p, POS_THRESHOLDS[1]),
                _mean(s), average_precision(s, st[0]), average_precision(s, st[1]),
                _median(d), _share_above(d, FLIPPED_ABOVE_DEG), _median(p_m), _median(s)]
        for key, v in zip(keys, vals, strict=True):
            cols[key].append(v)
    out.update(cols)
    return out


def _fmt(v: float | list[float] | None, digits: int = 2) -> str:
    if isinstance(v, list):
        return ", ".join(_fmt(x, digits) for x in v) if v else "-"
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    return f"{v:.{digits}f}"


def _by_category_and_method(results: Sequence[SampleResult]) -> dict[tuple[str, str], list[SampleResult]]:
    """The results grouped by (category, method), in the order they first occur."""
    groups: dict[tuple[str, str], list[SampleResult]] = {}
    for r in results:
        groups.setdefault((r.category, r.method), []).append(r)
    return groups


TABLE_COLUMNS = ("Dataset", "Method", "PA", "mIoU", "Dir MED", "Dir AP5", "Dir AP10", "Pos AED", "Pos AP1",
                 "Pos AP5", "State MED", "State AP5", "State AP10", "ms/input")


def table_markdown(results: Sequence[SampleResult]) -> str:
    """The paper's Table I as Markdown: one row per (category, method), then a Mean row per method
    (mean over categories of the per-category values, joint by joint averaged). Multi-joint categories
    show one value per joint, comma-separated."""
    groups = _by_category_and_method(results)
    categories = list(dict.fromkeys(r.category for r in results))
    methods = list(dict.fromkeys(r.method for r in results))
    keys = ["pa", "miou", "dir_med", "dir_ap5", "dir_ap10", "pos_aed", "pos_ap1", "pos_ap5", "state_med",
            "state_ap5", "state_ap10", "time_ms"]
    lines = ["| " + " | ".join(TABLE_COLUMNS) + " |", "|" + "---|" * len(TABLE_COLUMNS)]
    summaries: dict[tuple[str, str], dict] = {key: summarise(rs) for key, rs in groups.items()}
    for cat in categories:
        for m in methods:
            if (cat, m) in summaries:
                s = summaries[(cat, m)]
                lines.append("| " + " | ".join([cat, m] + [_fmt(s[k], 1 if k == "time_ms" else 2)
                                                            for k in keys]) + " |")
    if len(categories) > 1:
        for m in methods:
            ss = [summaries[(c, m)] for c in categories if (c, m) in summaries]
            row = []
            for k in keys:
                vals = [np.mean(s[k]) if isinstance(s[k], list) and s[k] else s[k] for s in ss]
                row.append(_fmt(_mean([float(v) for v in vals if not isinstance(v, list)]),
                                1 if k == "time_ms" else 2))
            lines.append("| " + " | ".join(["Mean", m] + row) + " |")
    return "\n".join(lines)


MEDIAN_TABLE_COLUMNS = ("Dataset", "Method", "Dir median (deg)", "Flipped", "Pos median (cm)", "State median")


def median_table_markdown(results: Sequence[SampleResult]) -> str:
    """Median errors as Markdown, one row per (category, method): direction (degrees), the share of
    flipped axes, axis-line distance (centimetres, '-' for prismatic joints) and state ('deg' for a
    revolute joint, 'm' for a prismatic one). Multi-joint categories show one value per joint slot."""
    groups = _by_category_and_method(results)
    lines = ["| " + " | ".join(MEDIAN_TABLE_COLUMNS) + " |", "|" + "---|" * len(MEDIAN_TABLE_COLUMNS)]
    for (category, method), rs in groups.items():
        s = summarise(rs)
        slots = sorted({j.joint_index for r in rs for j in r.joints})
        units = [next(j.joint_type for r in rs for j in r.joints if j.joint_index == k) for k in slots]
        states = [f"{v:.1f} deg" if t == "revolute" else f"{v:.3f} m"
                  for v, t in zip(s["state_median"], units, strict=True)]
        pos = [100 * v for v in s["pos_median_m"]]
        lines.append("| " + " | ".join([category, method, _fmt(s["dir_median"], 1), _fmt(s["dir_flipped"]),
                                        _fmt(pos, 1), ", ".join(states) or "-"]) + " |")
    return "\n".join(lines)
