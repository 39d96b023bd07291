"""Deterministic per-instance randomness: an object is a pure function of (category, instance_id).

The seed is derived from ``zlib.crc32`` of the category name and the id (never Python's salted
``hash()``), so every process and machine draws the same parameters.
"""

from __future__ import annotations

import zlib
from collections.abc import Sequence
from typing import Any

import numpy as np

NUM_INSTANCES = 1000
"""Valid instance ids of every category are 0 <= id < NUM_INSTANCES."""


def category_seed(category: str) -> int:
    """Stable 32-bit seed of a category name."""
    return zlib.crc32(category.encode("utf-8"))


def check_instance_id(category: str, instance_id: int) -> None:
    """Raise ValueError unless ``instance_id`` is an int in [0, NUM_INSTANCES)."""
    if isinstance(instance_id, bool) or not isinstance(instance_id, (int, np.integer)):
        raise ValueError(f"instance_id of {category!r} must be an int, got {instance_id!r}")
    if not 0 <= int(instance_id) < NUM_INSTANCES:
        raise ValueError(
            f"instance_id {instance_id} of {category!r} is out of range; valid ids are 0..{NUM_INSTANCES - 1}"
        )


def instance_rng(category: str, instance_id: int) -> np.random.Generator:
    """A numpy Generator seeded only by (category, instance_id)."""
    return np.random.default_rng([category_seed(category), int(instance_id)])


class ParamSampler:
    """Draws named shape parameters from an instance's generator and records them in ``params``."""

    def __init__(self, category: str, instance_id: int) -> None:
        check_instance_id(category, instance_id)
        self.rng = instance_rng(category, instance_id)
        self.params: dict[str, Any] = {}

    def uniform(self, name: str, low: float, high: float) -> float:
        """A float in [low, high), recorded under ``name``."""
        value = float(self.rng.uniform(low, high))
        self.params[name] = value
        return value

    def integer(self, name: str, low: int, high: int) -> int:
        """An int in [low, high] (both inclusive), recorded under ``name``."""
        value = int(self.rng.integers(low, high + 1))
        self.params[name] = value
        return value

    def choice(self, name: str, options: Sequence[Any]) -> Any:
        """One of ``options`` (uniformly), recorded under ``name``."""
        value = options[int(self.rng.integers(len(options)))]
        self.params[name] = value
        return value

    def color(
        self, name: str, palette: Sequence[tuple[float, float, float]], jitter: float = 0.05
    ) -> tuple[float, float, float, float]:
        """An RGBA colour near one of ``palette``'s RGB entries, recorded under ``name``."""
        base = np.asarray(palette[int(self.rng.integers(len(palette)))], dtype=np.float64)
        rgb = np.clip(base + self.rng.uniform(-jitter, jitter, size=3), 0.0, 1.0)
        value = (float(rgb[0]), float(rgb[1]), float(rgb[2]), 1.0)
        self.params[name] = value
        return value
