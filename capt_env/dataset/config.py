"""Typed configuration of dataset generation (``capt generate``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from capt_common.typed_yaml import require
from capt_env.dataset.variation import Variation
from capt_env.tasks.config import CameraConfig

# Joint slots stored per sample; a category with fewer joints leaves the rest masked out.
MAX_JOINTS = 4


@dataclass(frozen=True)
class GenerateConfig:
    """What ``capt generate`` renders. Counts are samples per split; every sample is one view of one
    instance at random joint states (uniform over each joint's full range) and a random viewpoint.

    ``views_per_instance`` samples share one built instance (rebuilding costs most of the time);
    ``num_points`` object points are kept per sample (random subset, or repeats if the view has
    fewer); samples with fewer than ``min_object_points`` visible object points are re-drawn.

    ``object``: the TaskConfig keys of a user file (``object`` path and its options such as
    ``joint``, ``closed``, ``front_yaw``) to render instead of a procedural category; ``category`` is
    then only the label stored with each sample (the file stem by default), and every split holds
    views of the one file.

    ``variation``: varied geometry (panel shapes, handle kinds, interiors), distractors on the
    table, robot-centric viewpoints and depth-sensor noise (:mod:`capt_env.dataset.variation`, each
    documented with its units there); all off by default, which renders exactly what a config
    without the key always rendered.
    """

    category: str = "laptop"
    seed: int = 0
    counts: dict[str, int] = field(default_factory=lambda: {"train": 700, "val": 200, "test": 100})
    samples_per_shard: int = 50
    views_per_instance: int = 5
    num_points: int = 2048
    min_object_points: int = 400
    object: dict[str, Any] | None = None
    camera: CameraConfig = field(
        default_factory=lambda: CameraConfig(width=160, height=160, random_view=True, fov=0.9)
    )
    variation: Variation = field(default_factory=Variation)

    def validate(self) -> None:
        from capt_env.objects.registry import CATEGORIES

        if self.object is None:
            require(self.category in CATEGORIES,
                    f"unknown category {self.category!r}; known: {list(CATEGORIES)}")
        else:
            require(bool(self.object.get("object")), "object must hold the file path under 'object'")
            require("category" not in self.object, "object must not set a 'category'")
        require(set(self.counts) <= {"train", "val", "test"},
                f"counts keys must be train/val/test, got {sorted(self.counts)}")
        require(all(v >= 0 for v in self.counts.values()), "counts must be >= 0")
        require(self.samples_per_shard >= 1, "samples_per_shard must be >= 1")
        require(self.views_per_instance >= 1, "views_per_instance must be >= 1")
        require(self.num_points >= 32, "num_points must be >= 32")
        require(self.min_object_points >= 1, "min_object_points must be >= 1")
        require(self.camera.random_view, "dataset cameras must use random_view: true")
        self.camera.validate()
        self.variation.validate()
