"""The public API of CAPT inference (paper Sec. III, end to end): cloud in, segmentation and joints out.

``ArticulationEstimator.predict(points)`` takes one (N, 3) cloud in metres, in any position and heading
(a model trained with ``rotation_augmentation: yaw``, as the shipped ones, needs the frame's +z up;
one trained with ``so3`` takes any orientation), and does:
bounding-box normalisation -> deterministic resampling to ``num_points`` (seeded) -> network ->
(double) voting -> back to the caller's frame. Part labels of points that were not fed to the network
are those of their nearest fed point. Revolute pivots are returned as the point of the axis closest to
the cloud's bounding-box centre; prismatic joints have no axis position, so their "pivot" is only a
display point (centroid of the predicted moving part). The ``pct_regression`` baseline has no
per-point votes: its confidence is reported as 1.0 and its part labels as -1 unless it has a
segmentation head.
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from scipy.spatial import cKDTree

from perception.batchnorm_folding import fold_batchnorm
from perception.checkpoint import build_model, load_checkpoint
from perception.config import JOINT_TYPE_CODES, SLOT_TYPES, CaptConfig
from perception.model import CaptModel, CaptOutput
from perception.normalisation import Normalisation
from perception.outlier_filter import OutlierFilter, inlier_mask
from perception.voting import PointPredictions, vote

MIN_POINTS = 32


@dataclass(frozen=True)
class JointEstimate:
    """One joint in the caller's frame: ``direction`` (3,) unit (+state opens), ``pivot`` (3,) metres (a
    point on the axis; display point for prismatic), ``state`` radians (revolute) or metres (prismatic),
    ``confidence`` in [0, 1]. ``joint_index`` is the model's joint slot; a cross-category model
    (``any`` slots) leaves out the slots it predicts absent and gives the others their predicted
    ``type``."""

    joint_index: int
    type: str
    direction: np.ndarray
    pivot: np.ndarray
    state: float
    confidence: float


@dataclass(frozen=True)
class ArticulationEstimate:
    """Result for one cloud: ``part_labels`` (N,) int64 for every input point, the joints, and the time
    spent in ``predict`` per cloud in milliseconds."""

    part_labels: np.ndarray
    joints: tuple[JointEstimate, ...]
    latency_ms: float


MIN_EXTENT = 1e-4
"""m: the smallest extent an input cloud may span (identical points carry no shape)."""

DEFAULT_CPU_THREADS = 1
"""Torch threads ``predict`` uses on the CPU. One cloud is too small a job to share between cores: on
a 2-core machine two threads gain little when idle, and when another process keeps one core busy the
second thread's waits make a call an order of magnitude slower (benchmarks/inference_threads.md)."""


@contextmanager
def torch_threads(n: int | None) -> Iterator[None]:
    """Run the block with ``torch.set_num_threads(n)`` and restore the previous count after (None: as
    it is)."""
    before = torch.get_num_threads()
    if n is None or n == before:
        yield
        return
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(before)


def checked_device(device: str | torch.device) -> torch.device:
    """``device`` as a torch device, or a ValueError saying why it cannot be used here."""
    dev = torch.device(device)
    if dev.type == "cuda" and not torch.cuda.is_available():
        build = "a CPU-only build" if torch.version.cuda is None else f"CUDA {torch.version.cuda}, no device"
        raise ValueError(f"device {str(device)!r}: CUDA is not available (torch {torch.__version__}, "
                         f"{build}); use device='cpu'")
    return dev


def check_points(points: np.ndarray, min_points: int = MIN_POINTS) -> np.ndarray:
    """Validate one input cloud; returns it as float64 (N, 3) or raises ValueError saying what is wrong."""
    if not isinstance(points, np.ndarray):
        raise ValueError(f"points must be a numpy array, got {type(points).__name__}")
    if points.ndim != 2 or points.shape[-1] != 3:
        raise ValueError(f"points must have shape (N, 3), got {points.shape}")
    if not np.issubdtype(points.dtype, np.floating):
        raise ValueError(f"points must be a float array, got dtype {points.dtype}")
    if points.shape[0] == 0:
        raise ValueError("points is empty: the cloud has no points")
    if points.shape[0] < min_points:
        raise ValueError(f"too few points: got {points.shape[0]}, need at least {min_points}")
    if not np.isfinite(points).all():
        raise ValueError("points contains NaN or inf values")
    extent = float(np.ptp(points, axis=0).max())
    if extent < MIN_EXTENT:
        raise ValueError(f"degenerate cloud: its {points.shape[0]} points span {extent:.2g} m (need at "
                         f"least {MIN_EXTENT} m); normalising it would divide by zero")
    return points.astype(np.float64)


def resample_indices(num_in: int, num_out: int, seed: int) -> np.ndarray:
    """Deterministic indices: a random subset without replacement when ``num_in >= num_out``, else every
    point once plus random repeats."""
    rng = np.random.default_rng(seed)
    if num_in >= num_out:
        return np.sort(rng.choice(num_in, size=num_out, replace=False))
    extra = rng.choice(num_in, size=num_out - num_in, replace=True)
    return np.concatenate([np.arange(num_in), extra])


def nearest_labels(query: np.ndarray, ref: np.ndarray, ref_labels: np.ndarray) -> np.ndarray:
    """Label of the nearest ``ref`` point for each ``query`` point (Euclidean, float64), found with
    scipy's k-d tree (O(N log n) rather than the N x n distance matrix)."""
    _, nearest = cKDTree(ref).query(query, k=1)
    return np.asarray(ref_labels)[nearest]


def labels_for_all_points(points: np.ndarray, fed: np.ndarray, fed_labels: np.ndarray) -> np.ndarray:
    """Part labels (N,) for every point of ``points`` (N, 3): the network's own label where the point was
    fed (indices ``fed``), the label of the nearest fed point elsewhere."""
    labels = np.empty(len(points), dtype=np.int64)
    labels[fed] = fed_labels
    rest = np.ones(len(points), dtype=bool)
    rest[fed] = False
    if rest.any():
        labels[rest] = nearest_labels(points[rest], points[fed], fed_labels)
    return labels


class ArticulationEstimator:
    """A trained CAPT model plus its voting window, ready to estimate articulation from clouds."""

    def __init__(self, model: CaptModel, config: CaptConfig, voting_window: tuple[float, float] | None = None,
                 category: str = "", device: str | torch.device = "cpu", seed: int = 0,
                 double_voting: bool | None = None, outlier_filter: OutlierFilter | None = None,
                 num_threads: int | None = DEFAULT_CPU_THREADS) -> None:
        """``double_voting``: None votes as the variant was trained to (CAPT twice, CAPT-plain once);
        False makes a CAPT checkpoint vote once, the coarse mean (the paper's "CAPT w/o DV"). True is
        only for CAPT: its voting window was chosen on validation, CAPT-plain's never was.
        ``outlier_filter``: drop stray points (:mod:`perception.outlier_filter`) before normalisation and
        the network; the dropped points still get a part label, their nearest fed point's. None (the
        default) feeds every point. ``num_threads``: torch threads while predicting on the CPU (see
        :data:`DEFAULT_CPU_THREADS`; None leaves torch's setting alone). The network runs with its
        BatchNorms folded into the layers before them (:mod:`perception.batchnorm_folding`, the same
        function up to float rounding); ``model`` itself is left as it is."""
        variant = config.model.variant
        if double_voting is not None and variant == "pct_regression":
            raise ValueError("double_voting does not apply to a pct_regression checkpoint: it regresses "
                             "the joints directly and does not vote")
        if double_voting and variant != "capt":
            raise ValueError(f"double_voting=True needs a capt checkpoint (its voting window is chosen on "
                             f"validation); this one is {variant}")
        self.double_voting = config.double_voting if double_voting is None else double_voting
        self.config = config
        self.device = checked_device(device)
        self.model = fold_batchnorm(model).to(self.device)
        self.num_threads = num_threads if self.device.type == "cpu" else None
        self.voting_window = voting_window or (config.voting.w0, config.voting.w1)
        self.category = category
        self.seed = seed
        self.joint_types = tuple(config.model.joint_types)
        self.outlier_filter = outlier_filter

    @classmethod
    def from_checkpoint(cls, path: str | Path, device: str | torch.device = "cpu", seed: int = 0,
                        double_voting: bool | None = None,
                        outlier_filter: OutlierFilter | None = None,
                        num_threads: int | None = DEFAULT_CPU_THREADS) -> ArticulationEstimator:
        """Load a checkpoint written by :func:`perception.checkpoint.save_checkpoint`
        (``double_voting``, ``outlier_filter`` and ``num_threads`` as in the constructor)."""
        ckpt = load_checkpoint(path)
        device = checked_device(device)
        return cls(build_model(ckpt, device), ckpt.config, ckpt.voting_window, ckpt.category, device, seed,
                   double_voting, outlier_filter, num_threads)

    def _fed_points(self, points: np.ndarray) -> np.ndarray:
        """Indices of the points of one checked cloud that may be fed to the network: all of them, or the
        inliers of ``outlier_filter`` (all of them when it would keep fewer than the minimum)."""
        if self.outlier_filter is None:
            return np.arange(len(points))
        keep = np.flatnonzero(inlier_mask(points, self.outlier_filter))
        return keep if len(keep) >= MIN_POINTS else np.arange(len(points))

    def predict(self, points: np.ndarray) -> ArticulationEstimate:
        """Estimate segmentation and joints of one cloud ``points`` (N, 3) float, metres, in the caller's
        frame (+z up for a yaw-trained model; see the module docstring)."""
        return self.predict_batch([points])[0]

    def predict_batch(self, clouds: Sequence[np.ndarray]) -> list[ArticulationEstimate]:
        """:meth:`predict` for several clouds in one forward pass; ``latency_ms`` = batch time / count."""
        with torch_threads(self.num_threads), torch.inference_mode():
            return self._predict_batch(clouds)

    def _predict_batch(self, clouds: Sequence[np.ndarray]) -> list[ArticulationEstimate]:
        t0 = time.perf_counter()
        if len(clouds) == 0:
            return []
        checked = [check_points(c) for c in clouds]
        n = self.config.model.num_points
        fed = [self._fed_points(c) for c in checked]
        norms = [Normalisation.fit(c[f]) for c, f in zip(checked, fed, strict=True)]
        idxs = [f[resample_indices(len(f), n, self.seed)] for f in fed]
        net_in = np.stack([nm.points(c[i]) for nm, c, i in zip(norms, checked, idxs, strict=True)])
        net_in = net_in.astype(np.float32)
        out = self.model(torch.from_numpy(net_in).to(self.device))
        results = [self._decode(out, b, checked[b], net_in[b], idxs[b], norms[b])
                   for b in range(len(checked))]
        latency = (time.perf_counter() - t0) * 1000.0 / len(checked)
        return [ArticulationEstimate(labels, joints, latency) for labels, joints in results]

    def _slot_types(self, out: CaptOutput, b: int) -> list[str]:
        """Each slot's type for cloud ``b``: the config's, or for an ``any`` slot the slot-type head's
        most likely class (revolute, prismatic or absent)."""
        if out.slot_type_logits is None:
            return list(self.joint_types)
        logits = out.slot_type_logits[b].float().cpu()
        predicted = logits.argmax(dim=-1).tolist()
        types = [SLOT_TYPES[c] if t == "any" else t for t, c in zip(self.joint_types, predicted, strict=True)]
        if all(t == "absent" for t in types):  # an object has a joint: keep the likeliest slot
            margin = logits[:, :2].max(dim=-1).values - logits[:, 2]
            k = int(margin.argmax())
            types[k] = SLOT_TYPES[int(logits[k, :2].argmax())]
        return types

    def _decode(self, out: CaptOutput, b: int, points: np.ndarray, net_points: np.ndarray, idx: np.ndarray,
                norm: Normalisation) -> tuple[np.ndarray, tuple[JointEstimate, ...]]:
        cfg = self.config.model
        if out.seg_logits is not None:
            kept_labels = out.seg_logits[b].argmax(dim=-1).cpu().numpy().astype(np.int64)
            labels = labels_for_all_points(points, idx, kept_labels)
        else:
            kept_labels = None
            labels = np.full(len(points), -1, dtype=np.int64)
        types = self._slot_types(out, b)
        present = [k for k, t in enumerate(types) if t != "absent"]
        codes = [JOINT_TYPE_CODES.get(t, 0) for t in types]
        if out.dir is not None:
            assert out.dist is not None and out.pdir is not None and out.state is not None
            child = None
            if kept_labels is not None:
                child = kept_labels[:, None] == np.asarray(cfg.joint_child_parts)[None, :]
            def arr(t: torch.Tensor) -> np.ndarray:
                return t[b].float().cpu().numpy()

            pred = PointPredictions(net_points, arr(out.dir), arr(out.dist), arr(out.pdir), arr(out.state),
                                    child)
            w0, w1 = self.voting_window
            votes = vote(pred, codes, w0, w1, self.double_voting, self.config.voting.min_points)
            raw = [(v.direction, v.pivot, v.state, v.confidence) for v in votes]
        else:
            assert out.reg_dir is not None and out.reg_pivot is not None and out.reg_state is not None
            d, p, s = (t[b].float().cpu().numpy().astype(np.float64) for t in (out.reg_dir, out.reg_pivot,
                                                                                 out.reg_state))
            raw = [(d[k] / max(np.linalg.norm(d[k]), 1e-12), p[k], float(s[k]), 1.0)
                   for k in range(len(codes))]
        joints = []
        centre = norm.centre
        for k, (u, q, s, conf) in enumerate(raw):
            if k not in present:
                continue
            pivot = norm.points_inv(q)
            if codes[k] == JOINT_TYPE_CODES["revolute"]:
                pivot = pivot + float((centre - pivot) @ u) * u
            state = float(norm.length_inv(s)) if codes[k] == JOINT_TYPE_CODES["prismatic"] else float(s)
            joints.append(JointEstimate(k, types[k], np.asarray(u, dtype=np.float64),
                                        np.asarray(pivot, dtype=np.float64), state,
                                        float(np.clip(conf, 0.0, 1.0))))
        return labels, tuple(joints)
