"""Deterministic 7:2:1 train/val/test split of instance ids, by a stable hash of (category, id).

Splitting by instance means that test objects are shapes never seen in training (the paper's
protocol). The split is a pure function: the same (category, id) always lands in the same split.
"""

from __future__ import annotations

import zlib

from capt_env.objects.sampling import NUM_INSTANCES, check_instance_id

SPLITS: tuple[str, ...] = ("train", "val", "test")
_BUCKETS = 1000
_TRAIN_END = 700  # buckets [0, 700) -> train, [700, 900) -> val, [900, 1000) -> test
_VAL_END = 900


def split_of(category: str, instance_id: int) -> str:
    """ "train", "val" or "test" for one instance (about 70 / 20 / 10 % of the ids)."""
    check_instance_id(category, instance_id)
    bucket = zlib.crc32(f"capt-split/{category}/{int(instance_id)}".encode()) % _BUCKETS
    if bucket < _TRAIN_END:
        return "train"
    if bucket < _VAL_END:
        return "val"
    return "test"


def instance_ids(category: str, split: str, limit: int | None = None) -> list[int]:
    """Ascending instance ids of ``category`` in ``split``; the first ``limit`` of them if given."""
    if split not in SPLITS:
        raise ValueError(f"unknown split {split!r}; known: {list(SPLITS)}")
    if limit is not None and limit < 0:
        raise ValueError(f"limit must be >= 0, got {limit}")
    ids = [i for i in range(NUM_INSTANCES) if split_of(category, i) == split]
    return ids if limit is None else ids[:limit]
