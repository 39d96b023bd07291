"""Training data for CAPT (paper Sec. IV-A): the sample format, the shard reader, the paper's
augmentation and the per-point targets of the articulation branch. Simulator-free.

On-disk layout (written by ``capt generate`` / :func:`write_dataset`)::

    DATA_DIR/manifest.json              {"format": "capt-env-shards/1", ...}; informative only
    DATA_DIR/<split>/shard_XXXXX.npz    split in {train, val, test}; shards read in name order

Keys of a shard holding S samples of N points and J joint slots (world frame, metres, radians)::

    points (S,N,3) float32        object points
    part_labels (S,N) int64       part (link) index per point, 0 = base; -1 = background (dropped)
    joint_types (S,J) int64       0 revolute, 1 prismatic, -1 unused slot
    joint_dirs (S,J,3) float32    unit axis direction; +state opens
    joint_pivots (S,J,3) float32  a point on the axis
    joint_states (S,J) float32    radians (revolute) or metres (prismatic)
    joint_limits (S,J,2) float32  same units as states
    joint_child_part (S,J) int64  part label each joint moves (-1 unused)
    joint_mask (S,J) bool         which slots hold a joint
    category (S,) str             category name
    instance_id (S,) int64        object instance (splits are by instance)

``target_joint`` (S,) int64, the task's joint, is loaded when every shard has it (scoring a model with
fewer joint slots than an object has joints: :func:`target_joint_only`); other keys (e.g.
``camera_eye``) are ignored. A single-sample ``.npz`` holds the same
keys without the leading S axis (:meth:`Sample.save` / :meth:`Sample.load`).

:class:`CaptShardDataset` loads a split into memory, and for item i of epoch e draws its randomness from
``np.random.default_rng([seed, e, i])`` (different every epoch, reproducible): optional augmentation
(rotation about x, y, z each uniform in [-pi, pi], translation uniform in [-1, 1]^3, scale uniform in
[0.8, 1.2]; directions rotate, pivots rotate/scale/translate, prismatic states and limits scale,
revolute states are unchanged) and optional sensor noise (:func:`add_sensor_noise`), background removal,
resampling to ``num_points``, normalisation to the object frame (:mod:`perception.normalisation`) and
per-point targets (dist, pdir).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np
import torch
from torch.utils.data import Dataset

from perception.config import JOINT_TYPE_CODES, ModelConfig
from perception.corruption import Corruption, corrupt_points
from perception.geometry import axis_targets
from perception.normalisation import Normalisation

SAMPLE_KEYS = ("points", "part_labels", "joint_types", "joint_dirs", "joint_pivots", "joint_states",
               "joint_limits", "joint_child_part", "joint_mask", "category", "instance_id")
PRISMATIC = JOINT_TYPE_CODES["prismatic"]
TARGET_KEY = "target_joint"
"""The task's joint of each sample (``capt generate`` writes it); loaded when every shard has it."""


@dataclass
class Sample:
    """One labelled cloud (world frame, metres, radians); see the module docstring for the keys."""

    points: np.ndarray
    part_labels: np.ndarray
    joint_types: np.ndarray
    joint_dirs: np.ndarray
    joint_pivots: np.ndarray
    joint_states: np.ndarray
    joint_limits: np.ndarray
    joint_child_part: np.ndarray
    joint_mask: np.ndarray
    category: str = ""
    instance_id: int = 0

    def object_points(self) -> np.ndarray:
        """(M, 3) float64: the points on the object (part label >= 0), world frame, metres."""
        return np.asarray(self.points, np.float64)[np.asarray(self.part_labels) >= 0]

    def arrays(self) -> dict[str, np.ndarray]:
        """The npz arrays with their canonical dtypes."""
        return {
            "points": np.asarray(self.points, np.float32),
            "part_labels": np.asarray(self.part_labels, np.int64),
            "joint_types": np.asarray(self.joint_types, np.int64),
            "joint_dirs": np.asarray(self.joint_dirs, np.float32),
            "joint_pivots": np.asarray(self.joint_pivots, np.float32),
            "joint_states": np.asarray(self.joint_states, np.float32),
            "joint_limits": np.asarray(self.joint_limits, np.float32),
            "joint_child_part": np.asarray(self.joint_child_part, np.int64),
            "joint_mask": np.asarray(self.joint_mask, bool), "category": np.asarray(self.category),
            "instance_id": np.asarray(self.instance_id, np.int64),
        }

    def save(self, path: str | Path) -> None:
        """Write as a single-sample npz."""
        np.savez(path, **self.arrays())

    @classmethod
    def load(cls, path: str | Path) -> Sample:
        """Read a single-sample npz."""
        with np.load(path, allow_pickle=False) as z:
            return cls.from_arrays({k: z[k] for k in SAMPLE_KEYS})

    @classmethod
    def from_arrays(cls, a: dict[str, np.ndarray]) -> Sample:
        """Build from per-sample arrays (extra keys ignored)."""
        kw = {f.name: a[f.name] for f in fields(cls)}
        kw["category"] = str(kw["category"])
        kw["instance_id"] = int(kw["instance_id"])
        return cls(**kw)


def write_shard(path: str | Path, samples: Sequence[Sample]) -> None:
    """Stack samples (same N and J) into one shard npz."""
    arrays = [s.arrays() for s in samples]
    np.savez(path, **{k: np.stack([a[k] for a in arrays]) for k in SAMPLE_KEYS})


def write_dataset(out_dir: str | Path, splits: dict[str, Sequence[Sample]],
                  samples_per_shard: int = 64) -> Path:
    """Write samples in the shard layout above (for tests and tools; ``capt generate`` has its own)."""
    out = Path(out_dir)
    counts, shards = {}, {}
    for split, samples in splits.items():
        (out / split).mkdir(parents=True, exist_ok=True)
        chunks = [samples[i:i + samples_per_shard] for i in range(0, len(samples), samples_per_shard)]
        for j, chunk in enumerate(chunks):
            write_shard(out / split / f"shard_{j:05d}.npz", chunk)
        counts[split], shards[split] = len(samples), len(chunks)
    (out / "manifest.json").write_text(json.dumps({"format": "capt-env-shards/1", "complete": True,
                                                   "counts": counts, "shards": shards}, indent=2))
    return out


def load_split(data_dir: str | Path, split: str) -> dict[str, np.ndarray]:
    """All shards of a split concatenated along axis 0 (keys of :data:`SAMPLE_KEYS`)."""
    files = sorted((Path(data_dir) / split).glob("shard_*.npz"))
    if not files:
        raise FileNotFoundError(f"no shard_*.npz files in {Path(data_dir) / split}")
    parts: dict[str, list[np.ndarray]] = {k: [] for k in (*SAMPLE_KEYS, TARGET_KEY)}
    for f in files:
        with np.load(f, allow_pickle=False) as z:
            missing = [k for k in SAMPLE_KEYS if k not in z.files]
            if missing:
                raise ValueError(f"{f} lacks keys {missing}")
            for k in SAMPLE_KEYS:
                parts[k].append(z[k])
            if TARGET_KEY in z.files:
                parts[TARGET_KEY].append(z[TARGET_KEY])
    if len(parts[TARGET_KEY]) < len(files):  # the target joint is known for every shard or not at all
        del parts[TARGET_KEY]
    return {k: np.concatenate(v) for k, v in parts.items()}


JOINT_KEYS = ("joint_types", "joint_dirs", "joint_pivots", "joint_states", "joint_limits", "joint_child_part",
              "joint_mask")
"""The stacked arrays with a joint axis (axis 1)."""


def empty_slot_value(key: str) -> int:
    """What a slot without a joint holds in ``key`` (one of :data:`JOINT_KEYS`): -1 for its type and
    child part, 0 elsewhere."""
    return -1 if key in ("joint_types", "joint_child_part") else 0


TARGET_ONLY_KEY = "target_only"
"""(S,) bool: the sample was cut to its target joint by :func:`target_joint_only`."""


def target_joint_only(a: dict[str, np.ndarray], num_joints: int) -> dict[str, np.ndarray]:
    """Each sample with a joint in a slot ``>= num_joints`` keeps only its target joint, moved to slot
    ``min(target, num_joints - 1)`` (the slot the estimate pipeline reads a target from), its part
    relabelled that slot's part (slot + 1) and every other moving part counted as fixed (0): what a
    model with ``num_joints`` slots can be scored on (a one-door model on one leaf of a double door).
    Other samples are unchanged; ``TARGET_ONLY_KEY`` marks the changed ones. Without
    ``target_joint`` the arrays are returned as they are (:func:`fit_joint_slots` then refuses)."""
    if TARGET_KEY not in a:
        return a
    over = np.flatnonzero(a["joint_mask"][:, num_joints:].any(axis=1))
    out = {k: v.copy() for k, v in a.items()}
    out[TARGET_ONLY_KEY] = np.zeros(len(a["joint_mask"]), dtype=bool)
    out[TARGET_ONLY_KEY][over] = True
    for i in over:
        t = int(a[TARGET_KEY][i])
        slot = min(t, num_joints - 1)
        for k in JOINT_KEYS:
            row = out[k][i]
            row[:] = empty_slot_value(k)
            row[slot] = a[k][i, t]
        out["joint_child_part"][i, slot] = slot + 1
        labels = a["part_labels"][i]
        out["part_labels"][i] = np.where(labels == a["joint_child_part"][i, t], slot + 1,
                                         np.where(labels > 0, 0, labels))
        out[TARGET_KEY][i] = slot
    return out


def fit_joint_slots(a: dict[str, np.ndarray], num_joints: int) -> dict[str, np.ndarray]:
    """Cut or pad the joint axis (axis 1 of stacked joint arrays) to ``num_joints`` slots; refuses to drop a
    slot that holds a joint (:func:`target_joint_only` makes such samples fit for scoring)."""
    out = dict(a)
    j = a["joint_mask"].shape[1]
    if j > num_joints and a["joint_mask"][:, num_joints:].any():
        raise ValueError(f"data has joints in slots >= {num_joints}; raise model.max_joints (training), "
                         f"or score the target joint only (capt evaluate does)")
    for k in JOINT_KEYS:
        v = a[k][:, :num_joints]
        if j < num_joints:
            pad = np.full((v.shape[0], num_joints - j, *v.shape[2:]), empty_slot_value(k), dtype=v.dtype)
            v = np.concatenate([v, pad], axis=1)
        out[k] = v
    return out


def random_rotation(rng: np.random.Generator, mode: str = "so3") -> np.ndarray:
    """``so3``: R = Rz Ry Rx with each angle uniform in [-pi, pi] (the paper's augmentation).
    ``yaw``: a rotation about +z only, uniform in [-pi, pi] -- for world-frame clouds whose up
    direction is known (a calibrated robot camera), where gravity need not be learned away."""
    if mode == "yaw":
        az = rng.uniform(-np.pi, np.pi)
        cz, sz = np.cos(az), np.sin(az)
        return np.array([[cz, -sz, 0.0], [sz, cz, 0.0], [0.0, 0.0, 1.0]])
    if mode != "so3":
        raise ValueError(f"rotation mode must be 'so3' or 'yaw', got {mode!r}")
    ax, ay, az = rng.uniform(-np.pi, np.pi, size=3)
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def augment(sample: Sample, rng: np.random.Generator, translation: float = 1.0,
            scale_range: tuple[float, float] = (0.8, 1.2), rotation: str = "so3") -> Sample:
    """x -> s R x + t applied consistently to points and labels (see module docstring);
    ``rotation`` picks R (see :func:`random_rotation`)."""
    rot = random_rotation(rng, rotation)
    t = rng.uniform(-translation, translation, size=3)
    s = float(rng.uniform(*scale_range))
    prism = (np.asarray(sample.joint_types) == PRISMATIC)
    return Sample(
        points=s * np.asarray(sample.points, np.float64) @ rot.T + t,
        part_labels=sample.part_labels,
        joint_types=sample.joint_types,
        joint_dirs=np.asarray(sample.joint_dirs, np.float64) @ rot.T,
        joint_pivots=s * np.asarray(sample.joint_pivots, np.float64) @ rot.T + t,
        joint_states=np.where(prism, s * np.asarray(sample.joint_states, np.float64), sample.joint_states),
        joint_limits=np.where(prism[:, None], s * np.asarray(sample.joint_limits, np.float64),
                              sample.joint_limits),
        joint_child_part=sample.joint_child_part,
        joint_mask=sample.joint_mask,
        category=sample.category,
        instance_id=sample.instance_id,
    )


def add_sensor_noise(sample: Sample, rng: np.random.Generator, noise: Corruption) -> Sample:
    """``sample``'s object points (background dropped) with ``noise`` drawn from ``rng``
    (:func:`perception.corruption.corrupt_points`); each stray point takes the part label of its
    nearest object point. Joints are unchanged. A clean ``noise`` returns ``sample`` itself."""
    if noise.is_clean:
        return sample
    from perception.inference import nearest_labels

    labels = np.asarray(sample.part_labels, np.int64)
    obj = labels >= 0
    if not obj.any():
        raise ValueError("sample has no object points")
    pts = np.asarray(sample.points, np.float64)[obj]
    noisy = corrupt_points(pts, rng, noise)
    stray = noisy[len(pts):]
    stray_labels = nearest_labels(stray, pts, labels[obj]) if len(stray) else np.empty(0, np.int64)
    return replace(sample, points=noisy, part_labels=np.concatenate([labels[obj], stray_labels]))


POSES = ("world", "yaw", "so3")
POSE_SEED = 20240


def check_pose(pose: str, name: str = "pose") -> None:
    """ValueError naming ``name`` unless ``pose`` is one of :data:`POSES`."""
    if pose not in POSES:
        raise ValueError(f"{name} must be one of {POSES}, got {pose!r}")


def posed_sample(sample: Sample, index: int, pose: str) -> Sample:
    """``sample`` (world frame) in the fixed pose of split index ``index``: ``"world"`` returns it
    unchanged; ``"yaw"`` and ``"so3"`` apply a rigid transform (rotation about +z, or about x, y and z,
    each angle uniform in [-pi, pi]; translation uniform in [-1, 1] m per axis; no scaling, so metres
    stay metres) drawn from the index alone. Validation (``TrainConfig.val_pose``) and test clouds
    (``capt evaluate --test-pose``) are posed this way, the same for every checkpoint and epoch."""
    check_pose(pose)
    if pose == "world":
        return sample
    rng = np.random.default_rng([POSE_SEED, int(index)])
    return augment(sample, rng, translation=1.0, scale_range=(1.0, 1.0), rotation=pose)


def prepare_sample(sample: Sample, num_points: int, rng: np.random.Generator) -> dict[str, torch.Tensor]:
    """Drop background, resample to ``num_points``, normalise, compute targets; returns training tensors:
    points (n,3), part_labels (n,), joint_dirs (J,3), joint_pivots (J,3), joint_states (J,) (prismatic in
    normalised units), joint_types (J,), joint_mask (J,), joint_child_part (J,), dist (n,J), pdir (n,J,3),
    centre (3,), scale ()."""
    labels = np.asarray(sample.part_labels, np.int64)
    keep = np.flatnonzero(labels >= 0)
    if len(keep) == 0:
        raise ValueError("sample has no object points")
    idx = keep[rng.choice(len(keep), size=num_points, replace=len(keep) < num_points)]
    pts = np.asarray(sample.points, np.float64)[idx]
    norm = Normalisation.fit(pts)
    types = np.asarray(sample.joint_types, np.int64)
    mask = np.asarray(sample.joint_mask, bool)
    dirs = np.asarray(sample.joint_dirs, np.float64)
    dirs = dirs / np.maximum(np.linalg.norm(dirs, axis=-1, keepdims=True), 1e-12)
    p_n = torch.as_tensor(norm.points(pts))
    q_n = torch.as_tensor(norm.points(sample.joint_pivots))
    u = torch.as_tensor(dirs)
    dist, pdir = axis_targets(p_n.unsqueeze(0), u, q_n)  # (J, n), (J, n, 3)
    dist = torch.where(torch.as_tensor(mask)[:, None], dist, torch.zeros_like(dist))
    f32 = torch.float32
    return {
        "points": p_n.to(f32), "part_labels": torch.as_tensor(labels[idx]),
        "joint_dirs": u.to(f32), "joint_pivots": q_n.to(f32),
        "joint_states": torch.as_tensor(norm.states(sample.joint_states, types == PRISMATIC)).to(f32),
        "joint_types": torch.as_tensor(types), "joint_mask": torch.as_tensor(mask),
        "joint_child_part": torch.as_tensor(np.asarray(sample.joint_child_part, np.int64)),
        "dist": dist.T.contiguous().to(f32), "pdir": pdir.transpose(0, 1).contiguous().to(f32),
        "centre": torch.as_tensor(norm.centre).to(f32), "scale": torch.tensor(norm.scale, dtype=f32),
    }


def load_splits(data_dirs: Sequence[str | Path], split: str, num_joints: int,
                target_only: bool = False) -> dict[str, np.ndarray]:
    """:func:`load_split` of every directory, each fitted to ``num_joints`` slots, concatenated (the
    training set of a cross-category model: one directory per category). ``target_only``: a sample
    with more joints than slots keeps its target joint only (:func:`target_joint_only`; for scoring,
    never for training)."""
    loaded = [load_split(d, split) for d in data_dirs]
    if target_only:
        loaded = [target_joint_only(a, num_joints) for a in loaded]
    arrays = [fit_joint_slots(a, num_joints) for a in loaded]
    shapes = {a["points"].shape[1:] for a in arrays}
    if len(shapes) > 1:
        raise ValueError(f"the datasets {[str(d) for d in data_dirs]} store clouds of different sizes "
                         f"{sorted(shapes)}; generate them with one num_points")
    common = [k for k in arrays[0] if all(k in a for a in arrays)]
    return {k: np.concatenate([a[k] for a in arrays]) for k in common}


class CaptShardDataset(Dataset):
    """A split of a shard directory (or of several, concatenated in order: one per category for a
    cross-category model) as training tensors (see module docstring). ``max_samples`` keeps
    the first samples only. ``pose`` puts every sample in its fixed seeded pose first (see
    :func:`posed_sample`; validation and test clouds), before any augmentation. ``sensor_noise`` is added
    to augmented clouds only (:func:`add_sensor_noise`). ``target_only`` (scoring only): a sample with
    more joints than the model has slots keeps its target joint (:func:`target_joint_only`;
    :attr:`target_only_count` counts them). Call :meth:`set_epoch` each epoch to change the
    augmentation draw."""

    def __init__(self, data_dir: str | Path | Sequence[str | Path], split: str, model: ModelConfig,
                 augment: bool = False, seed: int = 0, max_samples: int | None = None,
                 rotation: str = "so3", pose: str = "world", sensor_noise: Corruption | None = None,
                 target_only: bool = False) -> None:
        check_pose(pose)
        dirs = [data_dir] if isinstance(data_dir, (str, Path)) else list(data_dir)
        arrays = load_splits(dirs, split, model.max_joints, target_only)
        if max_samples is not None:
            arrays = {k: v[:max_samples] for k, v in arrays.items()}
        self.arrays = arrays
        self.target_only_count = int(arrays[TARGET_ONLY_KEY].sum()) if TARGET_ONLY_KEY in arrays else 0
        self.num_points = model.num_points
        self.augment = augment
        self.rotation = rotation
        self.pose = pose
        self.sensor_noise = sensor_noise or Corruption()
        self.seed = seed
        self.epoch = 0
        self._check(model)

    def _check(self, model: ModelConfig) -> None:
        a = self.arrays
        if a["part_labels"].max() >= model.max_parts:
            raise ValueError(f"part label {a['part_labels'].max()} >= model.max_parts {model.max_parts}")
        want = np.array([JOINT_TYPE_CODES.get(t, -1) for t in model.joint_types])
        bad = a["joint_mask"] & (want[None, :] >= 0) & (a["joint_types"] != want[None, :])
        if bad.any():
            raise ValueError(f"joint types in data differ from model.joint_types {model.joint_types}")

    def set_epoch(self, epoch: int) -> None:
        """Select the augmentation/resampling draw of ``epoch``."""
        self.epoch = int(epoch)

    def __len__(self) -> int:
        return len(self.arrays["points"])

    def sample(self, index: int) -> Sample:
        """The stored (un-augmented, world-frame) sample ``index``."""
        return Sample.from_arrays({k: v[index] for k, v in self.arrays.items()})

    def posed(self, index: int) -> Sample:
        """Sample ``index`` in this split's fixed ``pose`` (see :func:`posed_sample`)."""
        return posed_sample(self.sample(index), index, self.pose)

    def __getitem__(self, index: int) -> dict[str, torch.Tensor]:
        rng = np.random.default_rng([self.seed, self.epoch, int(index)])
        s = self.posed(index)
        if self.augment:
            s = add_sensor_noise(augment(s, rng, rotation=self.rotation), rng, self.sensor_noise)
        item = prepare_sample(s, self.num_points, rng)
        item["index"] = torch.tensor(int(index))
        return item
