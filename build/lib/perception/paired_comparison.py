"""Paired bootstrap of the gap between two methods' mean errors on the same test clouds (Table I
comparisons: is CAPT's lower mean error more than the luck of which clouds are in the test split?).

``capt evaluate`` scores every checkpoint on the same clouds of a split in the same order, so the
i-th sample of one method and the i-th sample of another are one cloud. A bootstrap draw resamples
cloud indices with replacement, the same indices for both methods, and recomputes each method's
table value exactly as the table does: per joint slot the mean over the clouds that have that joint,
then the mean over joint slots. The interval says how much the gap moves with the test clouds; it
says nothing of training noise (another training seed can order two close methods the other way).

What a draw resamples (``resample``): ``"clouds"`` draws clouds independently. A test split holds
several views of each unseen instance, and views of one instance may be wrong together, so
``"instances"`` draws the instances with replacement and takes every cloud of a drawn instance (a
cluster bootstrap): the interval is then over which objects are in the test split, wider when the
views of an instance agree (on this project's test splits it came out nearly the same).
It needs every sample's ``instance_id`` (``capt evaluate --json`` records it;
``scripts/attach_instance_ids.py`` adds it to files written before it did).

Training runs (seeds) of one method on one category: samples may carry a ``"run"`` key (any label;
absent counts as one run). Every run of a (category, method) must have scored the same clouds in the
same order; their errors are averaged per cloud and joint before the table value and the bootstrap,
so the gap is that of the methods' mean over runs, and the interval is still over the test clouds
only (two runs do not measure the spread between seeds).

Metrics (per-sample fields of ``capt evaluate --json``):

- ``dir_med``: direction error, degrees, every joint;
- ``pos_aed``: axis-line distance in the normalised object frame, revolute joints only;
- ``state_deg``: state error of revolute joints, degrees; ``state_m``: of prismatic joints, metres.

A difference is reference minus other: negative means the reference has the lower error.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

METRICS: tuple[str, ...] = ("dir_med", "pos_aed", "state_deg", "state_m")
RESAMPLE_UNITS: tuple[str, ...] = ("clouds", "instances")
_FIELDS = {"dir_med": ("direction_error_deg", None), "pos_aed": ("position_error", "revolute"),
           "state_deg": ("state_error", "revolute"), "state_m": ("state_error", "prismatic")}


@dataclass(frozen=True)
class PairedDifference:
    """Reference minus other of one table value: the point difference (on all clouds), the 95%
    percentile bootstrap interval [low, high], and the share of draws in which the reference is lower."""

    difference: float
    low: float
    high: float
    reference_lower_share: float


def error_matrix(samples: Sequence[Mapping], metric: str) -> np.ndarray:
    """(clouds, joint slots) errors of one method on one category, NaN where a cloud has no such joint
    (or the joint is of the other type for ``pos_aed``/``state_*``). ``samples`` are the per-sample
    dicts of ``capt evaluate --json`` for one method and one category, in evaluation order."""
    if metric not in _FIELDS:
        raise ValueError(f"unknown metric {metric!r}; expected one of {METRICS}")
    field, joint_type = _FIELDS[metric]
    slots = 1 + max((j["joint_index"] for s in samples for j in s["joints"]), default=-1)
    out = np.full((len(samples), max(slots, 1)), np.nan)
    for i, s in enumerate(samples):
        for j in s["joints"]:
            value = j.get(field)
            if value is None or (joint_type is not None and j["joint_type"] != joint_type):
                continue
            out[i, j["joint_index"]] = float(value)
    return out


def _mean_over_joints(total: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Per joint ``total / count`` where a joint has values, then the mean over those joints; NaN when
    none has (``total``, ``count``: (..., joints))."""
    has = count > 0
    per_joint = np.where(has, total / np.maximum(count, 1), 0.0)
    n = has.sum(axis=-1)
    with np.errstate(invalid="ignore"):
        return np.where(n > 0, per_joint.sum(axis=-1) / np.maximum(n, 1), np.nan)


def table_value(errors: np.ndarray) -> np.ndarray:
    """The table's value of ``errors`` (..., clouds, joints): per joint the mean over clouds that have
    it, then the mean over joints that any cloud has; NaN when none has a value."""
    present = ~np.isnan(errors)
    return _mean_over_joints(np.where(present, errors, 0.0).sum(axis=-2), present.sum(axis=-2))


def weighted_table_value(errors: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """:func:`table_value` of ``errors`` (clouds, joints) with each cloud counted ``weights`` (draws,
    clouds) times (whole numbers): one value per draw."""
    present = ~np.isnan(errors)
    return _mean_over_joints(weights @ np.where(present, errors, 0.0), weights @ present.astype(float))


def instance_draw_weights(instances: np.ndarray, draws: int, rng: np.random.Generator) -> np.ndarray:
    """(draws, clouds) counts of a cluster bootstrap: each draw takes as many instances as there are,
    with replacement, and every cloud counts as often as its instance was drawn."""
    groups, index = np.unique(instances, return_inverse=True)
    picks = rng.integers(0, len(groups), size=(draws, len(groups)))
    counts = np.stack([np.bincount(row, minlength=len(groups)) for row in picks])
    return counts[:, index].astype(float)


def bootstrap_difference(pairs: Mapping[str, tuple[np.ndarray, np.ndarray]], draws: int = 2000,
                         seed: int = 0, instances: Mapping[str, np.ndarray] | None = None
                         ) -> PairedDifference | None:
    """Reference minus other of the mean over categories of the table value. ``pairs`` maps each
    category to (reference, other) error matrices of the same shape (see :func:`error_matrix`); each
    draw resamples every category's clouds independently, or, with ``instances`` (each category's
    instance id per cloud), its instances (see the module docstring). Categories where the metric has
    no value (e.g. position of a drawer) are left out, as the table's mean leaves them out; None if
    none has."""
    if draws < 1:
        raise ValueError(f"draws must be >= 1, got {draws}")
    rng = np.random.default_rng(seed)
    point, boot = [], []
    for category, (ref, other) in sorted(pairs.items()):
        if ref.shape != other.shape:
            raise ValueError(f"{category}: the two methods were scored on different clouds "
                             f"({ref.shape[0]} vs {other.shape[0]} samples, {ref.shape[1]} vs "
                             f"{other.shape[1]} joint slots); compare checkpoints from one "
                             "`capt evaluate` run")
        diff = float(table_value(ref) - table_value(other))
        if np.isnan(diff):
            continue
        point.append(diff)
        if instances is None:
            idx = rng.integers(0, ref.shape[0], size=(draws, ref.shape[0]))
            boot.append(table_value(ref[idx]) - table_value(other[idx]))
            continue
        ids = np.asarray(instances[category])
        if ids.shape != (ref.shape[0],):
            raise ValueError(f"{category}: {ids.shape[0]} instance ids for {ref.shape[0]} clouds")
        weights = instance_draw_weights(ids, draws, rng)
        boot.append(weighted_table_value(ref, weights) - weighted_table_value(other, weights))
    if not point:
        return None
    dist = np.mean(boot, axis=0)
    low, high = np.percentile(dist, [2.5, 97.5])
    return PairedDifference(float(np.mean(point)), float(low), float(high), float(np.mean(dist < 0.0)))


def run_mean_error_matrix(runs: Mapping[object, Sequence[Mapping]], metric: str, where: str) -> np.ndarray:
    """:func:`error_matrix` averaged over training runs (``{run label: samples}``) of one method on one
    category; the runs must have scored the same number of clouds with the same joint slots."""
    mats = [error_matrix(s, metric) for s in runs.values()]
    shapes = {m.shape for m in mats}
    if len(shapes) != 1:
        raise ValueError(f"{where}: its runs were scored on different clouds (error matrices "
                         f"{sorted(shapes)}); evaluate every run on the same split of the same data")
    return np.mean(mats, axis=0)


def cloud_instances(groups: Mapping[tuple[str, str], Mapping[object, Sequence[Mapping]]], category: str
                    ) -> np.ndarray:
    """The instance id of each cloud of ``category``, the same in every run of every method (they
    pair clouds by position); ValueError naming what is missing or differs."""
    found: np.ndarray | None = None
    for (cat, method), runs in sorted(groups.items()):
        if cat != category:
            continue
        for label, samples in runs.items():
            if any(s.get("instance_id") is None for s in samples):
                raise ValueError(f"{category} {method} (run {label}) has samples without an instance_id: "
                                 "resample clouds, or add the ids with scripts/attach_instance_ids.py")
            ids = np.array([int(s["instance_id"]) for s in samples])
            if found is None:
                found = ids
            elif not np.array_equal(found, ids):
                raise ValueError(f"{category} {method} (run {label}): its clouds show other instances "
                                 "than the other runs' (not the same split in the same order)")
    if found is None:
        raise ValueError(f"no samples of {category}")
    return found


def paired_differences(samples: Sequence[Mapping], reference: str, draws: int = 2000, seed: int = 0,
                       resample: str = "clouds"
                       ) -> dict[str, dict[str, dict[str, PairedDifference | None]]]:
    """``{other method: {category or "mean": {metric: PairedDifference or None}}}`` for every method
    scored on every category beside ``reference``, from the per-sample dicts of one or more
    ``capt evaluate --json`` files; several training runs of a method are averaged per cloud (the
    samples' ``"run"`` key, see the module docstring). ``resample``: ``"clouds"`` or ``"instances"``
    (module docstring). Seeded: the same input gives the same intervals."""
    if resample not in RESAMPLE_UNITS:
        raise ValueError(f"resample must be one of {RESAMPLE_UNITS}, got {resample!r}")
    groups: dict[tuple[str, str], dict[object, list[Mapping]]] = {}
    for s in samples:
        groups.setdefault((s["category"], s["method"]), {}).setdefault(s.get("run", 0), []).append(s)
    categories = sorted({c for c, _ in groups})
    if not any((c, reference) in groups for c in categories):
        raise ValueError(f"no samples of the reference method {reference!r}")
    others = sorted({m for _, m in groups if m != reference
                     and all((c, m) in groups and (c, reference) in groups for c in categories)})
    instances = ({c: cloud_instances(groups, c) for c in categories} if resample == "instances"
                 else None)
    result: dict[str, dict[str, dict[str, PairedDifference | None]]] = {}
    for other in others:
        rows: dict[str, dict[str, PairedDifference | None]] = {c: {} for c in [*categories, "mean"]}
        for metric in METRICS:
            pairs = {c: (run_mean_error_matrix(groups[(c, reference)], metric, f"{c} {reference}"),
                         run_mean_error_matrix(groups[(c, other)], metric, f"{c} {other}"))
                     for c in categories}
            for c in categories:
                rows[c][metric] = bootstrap_difference({c: pairs[c]}, draws, seed, instances)
            rows["mean"][metric] = bootstrap_difference(pairs, draws, seed, instances)
        result[other] = rows
    return result
