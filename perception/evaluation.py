"""Evaluation of trained checkpoints (paper Sec. IV-C/E, Tables I and II): end-to-end predictions on the
stored world-frame clouds of a split, per-sample metrics, median time per input, and the Markdown table.

Each checkpoint is run through :class:`perception.inference.ArticulationEstimator` exactly as a user
would call it (world-frame object points in, world-frame joints out). Position errors are given in the
sample's normalised frame (divided by the bounding-box diagonal of its object points, as in the paper's
normalised data) and in metres.

``test_pose`` puts each test cloud in a new pose first, as the paper's test clouds are augmented too:
``"world"`` keeps the stored world-frame clouds; ``"yaw"`` and ``"so3"`` apply a rigid transform
(rotation about +z, or about x, y and z, each angle uniform in [-pi, pi]; translation uniform in
[-1, 1] m per axis; no scaling, so metres stay metres), drawn from the sample's index alone, so every
checkpoint sees the same posed clouds and a paired comparison stays paired.

``corruption`` (:mod:`perception.corruption`) then adds seeded sensor noise to each posed cloud: Gaussian
jitter and stray points. Ground truth and the normalised frame's scale stay those of the clean cloud;
segmentation is scored on the cloud's own points, not on the stray ones. ``outlier_filter``
(:mod:`perception.outlier_filter`) makes every checkpoint drop stray points before its network.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from perception.corruption import Corruption, corrupt_cloud
from perception.data import CaptShardDataset, Sample, check_pose
from perception.inference import ArticulationEstimate, ArticulationEstimator
from perception.metrics import (
    JointResult,
    SampleResult,
    direction_error_deg,
    line_distance,
    mean_iou,
    median_table_markdown,
    segmentation_accuracy,
    state_error,
    table_markdown,
)
from perception.normalisation import Normalisation
from perception.outlier_filter import OutlierFilter


@dataclass(frozen=True)
class EvaluationResult:
    """Per-sample metrics of every checkpoint, median ms per input per method, Table I in Markdown and
    the median errors in Markdown (:func:`perception.metrics.median_table_markdown`)."""

    results: list[SampleResult]
    median_ms: dict[str, float]
    table: str
    medians: str
    target_only: dict[str, int] = field(default_factory=dict)
    """Per method, the clouds with more joints than its model's slots, scored on their target joint
    only (:func:`perception.data.target_joint_only`)."""


def score_sample(est: ArticulationEstimate, sample: Sample, method: str, has_seg: bool) -> SampleResult:
    """Metrics of one estimate against the ground truth of its (object-points-only) sample."""
    labels = np.asarray(sample.part_labels)
    obj = labels >= 0
    scale = Normalisation.fit(np.asarray(sample.points)[obj]).scale
    joints = []
    for j in est.joints:
        k = j.joint_index
        if not sample.joint_mask[k]:
            continue
        u, q = np.asarray(sample.joint_dirs[k], np.float64), np.asarray(sample.joint_pivots[k], np.float64)
        pos_m = None if j.type == "prismatic" else line_distance(j.direction, j.pivot, u, q)
        joints.append(JointResult(k, j.type, direction_error_deg(j.direction, u),
                                  None if pos_m is None else pos_m / scale, pos_m,
                                  state_error(j.state, float(sample.joint_states[k]), j.type)))
    pa = segmentation_accuracy(est.part_labels, labels[obj]) if has_seg else None
    miou = mean_iou(est.part_labels, labels[obj]) if has_seg else None
    true_joints = int(np.asarray(sample.joint_mask).sum())
    return SampleResult(sample.category, method, pa, miou, tuple(joints), est.latency_ms,
                        int(sample.instance_id), missed_joints=true_joints - len(joints),
                        true_joints=true_joints)


WITHOUT_DV = "capt_without_dv"
WARM_UP_CALLS = 3


def evaluate(checkpoints: Sequence[str | Path], data_dir: str | Path, split: str = "test",
             device: str = "cpu", timing_clouds: int = 100, max_samples: int | None = None,
             progress: bool = True, without_double_voting: bool = False,
             test_pose: str = "world", corruption: Corruption | None = None,
             outlier_filter: OutlierFilter | None = None) -> EvaluationResult:
    """Evaluate each checkpoint on ``split``. The method name is the checkpoint's model variant, or
    ``"<variant> (<path>)"`` for every checkpoint whose variant is given more than once (e.g. two CAPT
    checkpoints compared), so no row overwrites another. ``without_double_voting`` also scores every
    CAPT checkpoint with the coarse vote only, as method ``capt_without_dv`` (the paper's "CAPT w/o
    DV": the motion loss's training without double voting's inference). Timing is the median of
    ``predict`` latency over the scored single-cloud calls, after 3 warm-up calls, and more calls
    (cycling over the split) until there are at least ``timing_clouds``. ``test_pose``, ``corruption`` and
    ``outlier_filter``: see the module docstring."""
    check_pose(test_pose, "test_pose")
    if len({str(p) for p in checkpoints}) != len(checkpoints):
        raise ValueError(f"a checkpoint is given twice: {[str(p) for p in checkpoints]}")
    estimators = [ArticulationEstimator.from_checkpoint(path, device=device, outlier_filter=outlier_filter)
                  for path in checkpoints]
    variants = [e.config.model.variant for e in estimators]
    if without_double_voting and "capt" not in variants:
        raise ValueError(f"without_double_voting needs a capt checkpoint to score without double voting; "
                         f"these are {variants}")
    runs: list[tuple[str, ArticulationEstimator]] = []
    for path, est, variant in zip(checkpoints, estimators, variants, strict=True):
        suffix = "" if variants.count(variant) == 1 else f" ({path})"
        runs.append((variant + suffix, est))
        if without_double_voting and variant == "capt":
            runs.append((WITHOUT_DV + suffix,
                         ArticulationEstimator(est.model, est.config, est.voting_window, est.category, device,
                                               est.seed, double_voting=False, outlier_filter=outlier_filter)))
    results: list[SampleResult] = []
    median_ms: dict[str, float] = {}
    target_only: dict[str, int] = {}
    for method, est in runs:
        cfg = est.config.model
        ds = CaptShardDataset(data_dir, split, cfg, augment=False, max_samples=max_samples, pose=test_pose,
                              target_only=True)
        if ds.target_only_count:
            target_only[method] = ds.target_only_count
        samples = [ds.posed(i) for i in range(len(ds))]
        clean = [s.object_points() for s in samples]
        clouds = [corrupt_cloud(c, i, corruption) for i, c in enumerate(clean)] if corruption else clean
        for c in clouds[:WARM_UP_CALLS]:
            est.predict(c)
        times = []
        for s, n, cloud in tqdm(list(zip(samples, map(len, clean), clouds, strict=True)),
                                desc=f"evaluate {method}", disable=not progress):
            pred = est.predict(cloud)
            times.append(pred.latency_ms)
            if len(cloud) > n:  # stray points appended by the corruption have no true part
                pred = replace(pred, part_labels=pred.part_labels[:n])
            results.append(score_sample(pred, s, method, cfg.has_segmentation))
        times += [est.predict(clouds[i % len(clouds)]).latency_ms for i in range(timing_clouds - len(times))]
        median_ms[method] = statistics.median(times)
    return EvaluationResult(results, median_ms, table_markdown(results), median_table_markdown(results),
                            target_only)
