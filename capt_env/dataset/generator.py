"""Dataset generation: render labelled object clouds through the task's camera, write them as shards.

Layout of an output directory::

    manifest.json                 config, seed, versions, per-split sample and shard counts
    train/shard_00000.npz         ``samples_per_shard`` samples stacked on axis 0 (last may be short)
    val/...  test/...

Keys of a shard (S samples, N = ``num_points``, J = ``MAX_JOINTS``; world frame, metres, radians):

    points (S,N,3) float32       object points (robot and table removed by labels), plus distractor
                                 points with ``variation.distractors``
    part_labels (S,N) int64      part of each point (0 = base, k + 1 = moved by joint k; -1 = a
                                 distractor, background)
    joint_types (S,J) int64      0 revolute, 1 prismatic (-1 in unused slots)
    joint_dirs (S,J,3) float32   unit axis direction, +state opens
    joint_pivots (S,J,3) float32 the point of the axis closest to the cloud's centroid
    joint_states (S,J) float32   radians (revolute) or metres (prismatic); 0 = closed
    joint_limits (S,J,2) float32
    joint_child_part (S,J) int64 part label moved by each joint
    joint_mask (S,J) bool        which slots hold a joint
    target_joint (S,) int64      the joint a robot would open
    instance_id (S,) int64       procedural instance (splits are by instance: test shapes are unseen)
    camera_eye (S,3) float32     where the camera was
    category (S,) str

Each shard is a pure function of (config, split, shard index) and is written atomically (temporary
file, then rename), so an interrupted run resumes by skipping the shards that exist: nothing is
lost or duplicated. Shards are rendered in parallel, one process and one environment per core.

``GenerateConfig.variation`` (:mod:`capt_env.dataset.variation`) renders a varied scene
(:mod:`capt_env.dataset.scene_env`) and adds sensor noise (:mod:`capt_env.dataset.sensor_noise`);
with all of it off the shards, and the manifest, are exactly those of a config without it.
"""

from __future__ import annotations

import json
import math
import multiprocessing as mp
import os
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from capt_common.typed_yaml import to_dict
from capt_env.dataset.config import MAX_JOINTS, GenerateConfig

SPLITS = ("train", "val", "test")
MANIFEST = "manifest.json"


@dataclass(frozen=True)
class ShardJob:
    split: str
    index: int
    num_samples: int


def plan_shards(cfg: GenerateConfig) -> list[ShardJob]:
    """Every shard of every split, in a fixed order."""
    jobs = []
    for split in SPLITS:
        n = cfg.counts.get(split, 0)
        for i in range(math.ceil(n / cfg.samples_per_shard)):
            jobs.append(ShardJob(split, i, min(cfg.samples_per_shard, n - i * cfg.samples_per_shard)))
    return jobs


def shard_path(out_dir: Path, job: ShardJob) -> Path:
    return out_dir / job.split / f"shard_{job.index:05d}.npz"


# One environment per worker process, built on first use.
_ENV: Any = None
_ENV_KEY: tuple | None = None


def _env_for(cfg: GenerateConfig) -> Any:
    global _ENV, _ENV_KEY
    key = (cfg.category, json.dumps(cfg.object, sort_keys=True), to_json(cfg.camera), to_json(cfg.variation))
    if _ENV is None or _ENV_KEY != key:
        import gymnasium as gym

        import capt_env
        from capt_env.tasks.open_articulated import UnseenGraspPointWarning

        if _ENV is not None:
            _ENV.close()
        what = {"category": cfg.category, "split": "all"} if cfg.object is None else dict(cfg.object)
        task = {
            # the placement the shipped datasets were rendered at (cameras aim at the object, so
            # only what the robot hides depends on it), whatever the category's task default
            **what, "cameras": [to_dict(cfg.camera)],
            "object_xy": [0.3, 0.0],
            "target_init_fraction": [0.0, 1.0], "other_init_fraction": [0.0, 1.0],
        }
        if cfg.variation.viewpoints.mode == "robot":
            del task["object_xy"]  # where the task puts the object: robot-centric views
        # a random view that misses the handle is a training sample, not a task that cannot be
        # perceived: the task's unseen-grasp warning is not for datasets
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UnseenGraspPointWarning)
            if cfg.variation.needs_scene:
                from capt_env.dataset.scene_env import make_generate_env

                _ENV = make_generate_env(task, cfg.variation)
            else:
                _ENV = gym.make(capt_env.registration.GENERIC_ID, obs_mode="pointcloud", task=task,
                                reconfiguration_freq=0)
        _ENV.unwrapped.warn_unseen_grasp_point = False
        _ENV_KEY = key
    return _ENV


def to_json(obj: Any) -> str:
    return json.dumps(to_dict(obj), sort_keys=True)


def _one_sample(obs: dict, info: dict, cfg: GenerateConfig, rng: np.random.Generator,
                env: Any = None) -> dict | None:
    """Cut the object (and any distractors) out of one rendered cloud of ``env`` and label it, with
    the config's sensor noise; None if too few object points."""
    pc = obs["pointcloud"]
    labels = pc["part_label"].astype(np.int64)
    mask = labels >= 0
    noise = cfg.variation.sensor_noise
    kept = np.ones_like(mask)
    if noise.edge_dropout > 0:
        from capt_env.dataset.sensor_noise import edge_dropout_mask

        eyes, shapes = _cameras(env)
        kept = edge_dropout_mask(pc["xyzw"][:, :3], pc["xyzw"][:, 3] > 0, eyes, shapes, noise, rng)
        mask &= kept
    if mask.sum() < cfg.min_object_points:
        return None
    if cfg.variation.distractors.enabled:  # background points, part label -1
        mask |= np.isin(pc["segmentation"].reshape(-1), env.unwrapped.distractor_segmentation_ids()) & kept
    xyz = pc["xyzw"][mask, :3].astype(np.float32)
    labels = labels[mask]
    if noise.jitter_m > 0 or noise.outlier_fraction > 0:
        from capt_env.dataset.sensor_noise import jitter_and_strays

        xyz, labels = jitter_and_strays(xyz, labels, noise, rng)
    replace = len(xyz) < cfg.num_points
    idx = rng.choice(len(xyz), size=cfg.num_points, replace=replace)
    points, labels = xyz[idx], labels[idx]

    n_j = len(info["joint_type"])
    if n_j > MAX_JOINTS:
        raise ValueError(f"{cfg.category} has {n_j} joints; the dataset stores at most {MAX_JOINTS}")
    dirs = np.asarray(info["joint_axis"], dtype=np.float64)
    raw_pivots = np.asarray(info["joint_pivot"], dtype=np.float64)
    centroid = points.mean(axis=0).astype(np.float64)
    along = ((centroid - raw_pivots) * dirs).sum(-1, keepdims=True)
    pivots = raw_pivots + along * dirs

    def pad(a: np.ndarray, fill: float, dtype: Any) -> np.ndarray:
        out = np.full((MAX_JOINTS, *np.shape(a)[1:]), fill, dtype=dtype)
        out[:n_j] = a
        return out

    return {
        "points": points,
        "part_labels": labels,
        "joint_types": pad(info["joint_type"], -1, np.int64),
        "joint_dirs": pad(dirs, 0.0, np.float32),
        "joint_pivots": pad(pivots, 0.0, np.float32),
        "joint_states": pad(info["joint_state"], 0.0, np.float32),
        "joint_limits": pad(info["joint_limits"], 0.0, np.float32),
        "joint_child_part": pad(info["joint_child_part"], -1, np.int64),
        "joint_mask": pad(np.ones(n_j, dtype=bool), False, bool),
        "target_joint": np.int64(info["target_joint"]),
    }


def render_shard(cfg: GenerateConfig, job: ShardJob) -> dict[str, np.ndarray]:
    """Render one shard: a pure function of (cfg, job)."""
    from capt_env.objects.splits import instance_ids

    env = _env_for(cfg)
    rng = np.random.default_rng([cfg.seed, SPLITS.index(job.split), job.index])
    allowed = instance_ids(cfg.category, job.split) if cfg.object is None else [-1]
    samples: list[dict] = []
    while len(samples) < job.num_samples:
        iid = int(rng.choice(allowed))
        options = {"reconfigure": True, "instance_id": iid} if iid >= 0 else {}
        obs, info = env.reset(seed=int(rng.integers(2**31)), options=options)
        for view in range(cfg.views_per_instance):
            if len(samples) >= job.num_samples:
                break
            if view > 0:
                obs, info = env.reset(seed=int(rng.integers(2**31)))
            sample = _one_sample(obs, info, cfg, rng, env)
            if sample is None:
                continue
            sample["instance_id"] = np.int64(iid)
            sample["camera_eye"] = _camera_eye(env)
            samples.append(sample)
    stacked = {k: np.stack([s[k] for s in samples]) for k in samples[0]}
    stacked["category"] = np.array([cfg.category] * len(samples))
    return stacked


def _camera_eye(env: Any) -> np.ndarray:
    cam = next(iter(env.unwrapped._sensors.values())).camera
    return np.asarray(cam.get_local_pose().p, dtype=np.float32).reshape(-1)[:3]


def _cameras(env: Any) -> tuple[list[np.ndarray], list[tuple[int, int]]]:
    """Eye (3,) and image (height, width) of each of ``env``'s cameras, in the cloud's order."""
    sensors = list(env.unwrapped._sensors.values())
    eyes = [np.asarray(s.camera.get_local_pose().p, dtype=np.float64).reshape(-1)[:3] for s in sensors]
    return eyes, [(int(s.config.height), int(s.config.width)) for s in sensors]


def write_npz_atomic(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write ``arrays`` to ``path`` so that a reader sees either nothing or the whole file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.stem, suffix=".tmp.npz")
    os.close(fd)
    try:
        np.savez(tmp, **arrays)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def _work(payload: tuple[str, ShardJob, str]) -> tuple[ShardJob, int]:
    cfg_json, job, out_dir = payload
    from capt_common.typed_yaml import from_dict

    cfg = from_dict(GenerateConfig, json.loads(cfg_json))
    arrays = render_shard(cfg, job)
    write_npz_atomic(shard_path(Path(out_dir), job), arrays)
    return job, len(arrays["points"])


def config_record(cfg: GenerateConfig) -> dict[str, Any]:
    """``cfg`` as the manifest records it: without ``variation`` when nothing varies, so datasets
    made before that option existed keep their manifest and stay resumable."""
    data = to_dict(cfg)
    if not cfg.variation.enabled:
        del data["variation"]
    return data


def _write_manifest(out_dir: Path, cfg: GenerateConfig, extra: dict) -> None:
    from capt_common.json_report import machine_info

    data = {"format": "capt-env-shards/1", "config": config_record(cfg), "seed": cfg.seed,
            "versions": machine_info(), **extra}
    fd, tmp = tempfile.mkstemp(dir=out_dir, prefix="manifest", suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(data, fh, indent=2)
    os.replace(tmp, out_dir / MANIFEST)


def generate(cfg: GenerateConfig, out_dir: str | Path, workers: int | None = None,
             progress: bool = True) -> dict[str, Any]:
    """Render every missing shard of ``cfg`` into ``out_dir``; return counts and timing.

    Refuses to add to a directory whose manifest holds a different config (no mixed datasets).
    """
    import time

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    manifest = out_dir / MANIFEST
    if manifest.exists():
        old = json.loads(manifest.read_text()).get("config")
        if old != config_record(cfg):
            raise ValueError(f"{out_dir} holds a dataset made with another config; use a new directory")
    else:
        _write_manifest(out_dir, cfg, {"complete": False})

    jobs = plan_shards(cfg)
    todo = [j for j in jobs if not shard_path(out_dir, j).exists()]
    workers = max(1, min(workers or os.cpu_count() or 1, len(todo) or 1))
    cfg_json = to_json(cfg)
    t0 = time.perf_counter()
    rendered = 0
    bar = tqdm(total=sum(j.num_samples for j in todo), desc=f"generate {cfg.category}", unit="sample",
               disable=not progress)
    payloads = [(cfg_json, j, str(out_dir)) for j in todo]
    if workers == 1:
        results = map(_work, payloads)
        for _, n in results:
            rendered += n
            bar.update(n)
    else:
        with mp.get_context("spawn").Pool(workers) as pool:
            for _, n in pool.imap_unordered(_work, payloads):
                rendered += n
                bar.update(n)
    bar.close()
    elapsed = time.perf_counter() - t0
    counts = {s: sum(j.num_samples for j in jobs if j.split == s) for s in SPLITS}
    shards = {s: sum(1 for j in jobs if j.split == s) for s in SPLITS}
    _write_manifest(out_dir, cfg, {"complete": True, "counts": counts, "shards": shards})
    return {
        "out_dir": str(out_dir), "category": cfg.category, "seed": cfg.seed, "counts": counts,
        "rendered_now": rendered,
        "skipped_shards": len(jobs) - len(todo), "workers": workers, "seconds": elapsed,
        "samples_per_second": rendered / elapsed if rendered and elapsed > 0 else None,
    }
