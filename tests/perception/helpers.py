"""Helpers of the perception tests: tiny configs and synthetic box objects (CPU-fast)."""

from __future__ import annotations

import numpy as np
import torch

from perception.config import ModelConfig
from perception.data import Sample, prepare_sample
from perception.synthetic import make_box_sample


def tiny_model_config(variant: str = "capt", **kw) -> ModelConfig:
    base = {"variant": variant, "num_points": 128, "embed_dim": 32, "head_dim": 64, "knn_k": 8,
            "dropout": 0.0}
    base.update(kw)
    return ModelConfig(**base)


def make_samples(n: int, seed: int = 0, joint_type: str = "revolute", num_points: int = 256) -> list[Sample]:
    rng = np.random.default_rng(seed)
    return [make_box_sample(rng, num_points, joint_type, instance_id=i) for i in range(n)]


def collate(samples: list[Sample], num_points: int, seed: int = 0) -> dict[str, torch.Tensor]:
    items = [prepare_sample(s, num_points, np.random.default_rng([seed, i])) for i, s in enumerate(samples)]
    return torch.utils.data.default_collate(items)
