"""Shared pytest setup: deterministic torch, and one place that says why a test is skipped."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("OMP_NUM_THREADS", "2")


@pytest.fixture(autouse=True)
def _seed_everything() -> None:
    import numpy as np
    import torch

    np.random.seed(0)
    torch.manual_seed(0)
