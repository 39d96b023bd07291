"""Bad inputs to the perception API get one clear error each."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from perception.checkpoint import CheckpointError
from perception.inference import ArticulationEstimator

SHIPPED = Path(__file__).resolve().parents[2] / "perception" / "checkpoints" / "laptop.pt"


@pytest.fixture(scope="module")
def estimator() -> ArticulationEstimator:
    return ArticulationEstimator.from_checkpoint(SHIPPED)


def test_identical_points_are_a_degenerate_cloud_not_a_confident_joint(estimator) -> None:
    with pytest.raises(ValueError, match="degenerate cloud: its 2000 points span 0 m"):
        estimator.predict(np.ones((2000, 3)))


def test_a_directory_as_checkpoint_says_it_is_a_directory(tmp_path: Path) -> None:
    with pytest.raises(CheckpointError, match="is a directory"):
        ArticulationEstimator.from_checkpoint(tmp_path)


def test_a_truncated_checkpoint_is_named_truncated(tmp_path: Path) -> None:
    cut = tmp_path / "cut.pt"
    cut.write_bytes(SHIPPED.read_bytes()[:50_000])
    with pytest.raises(CheckpointError, match=r"cut\.pt is truncated or corrupt \(50000 bytes\)"):
        ArticulationEstimator.from_checkpoint(cut)


@pytest.mark.skipif(torch.cuda.is_available(), reason="needs a machine without CUDA")
def test_cuda_without_cuda_says_so() -> None:
    with pytest.raises(ValueError, match="CUDA is not available"):
        ArticulationEstimator.from_checkpoint(SHIPPED, device="cuda")
