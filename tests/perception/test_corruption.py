"""Seeded sensor corruption of test clouds (``capt evaluate --test-jitter / --test-outliers``)."""

from __future__ import annotations

import numpy as np
import pytest

from perception.corruption import Corruption, corrupt_cloud


def _cloud(n: int = 4000) -> np.ndarray:
    return np.random.default_rng(0).uniform([-0.3, -0.2, 0.0], [0.3, 0.2, 0.5], size=(n, 3))


def test_jitter_has_the_asked_standard_deviation_and_keeps_the_point_order() -> None:
    cloud = _cloud()
    noisy = corrupt_cloud(cloud, 7, Corruption(jitter_m=0.005))
    assert noisy.shape == cloud.shape
    offsets = noisy - cloud
    assert offsets.std() == pytest.approx(0.005, rel=0.03)  # 12000 draws: about 0.6% standard error
    assert abs(offsets.mean()) < 2e-4
    assert np.abs(offsets).max() < 0.005 * 6  # each point moved a little: the order is kept


def test_outliers_are_appended_inside_the_clean_bounding_box() -> None:
    cloud = _cloud(1000)
    out = corrupt_cloud(cloud, 3, Corruption(outlier_fraction=0.1))
    assert out.shape == (1100, 3)
    np.testing.assert_array_equal(out[:1000], cloud)  # no jitter: the cloud's own points untouched
    stray = out[1000:]
    assert (stray >= cloud.min(axis=0)).all() and (stray <= cloud.max(axis=0)).all()
    assert not np.isin(stray[:, 0], cloud[:, 0]).any()  # new points, not copies
    assert corrupt_cloud(cloud, 3, Corruption(outlier_fraction=0.004)).shape == (1004, 3)  # rounded


def test_the_draw_depends_on_the_index_alone() -> None:
    c = Corruption(jitter_m=0.002, outlier_fraction=0.05)
    cloud = _cloud(500)
    np.testing.assert_array_equal(corrupt_cloud(cloud, 4, c), corrupt_cloud(cloud.copy(), 4, c))
    assert not np.allclose(corrupt_cloud(cloud, 4, c), corrupt_cloud(cloud, 5, c))
    assert corrupt_cloud(cloud, 4, Corruption()) is cloud  # no corruption: the input itself


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"jitter_m": -0.001}, "jitter_m must be"), ({"jitter_m": float("nan")}, "jitter_m must be"),
    ({"outlier_fraction": 1.5}, "outlier_fraction must be"), ({"outlier_fraction": -0.1}, "outlier_fraction"),
])
def test_a_bad_corruption_is_named(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        Corruption(**kwargs)


def test_a_bad_cloud_is_refused() -> None:
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        corrupt_cloud(np.zeros((0, 3)), 0, Corruption(jitter_m=0.01))


def test_the_description_says_what_was_done() -> None:
    assert Corruption().describe() == "none"
    assert Corruption(jitter_m=0.005, outlier_fraction=0.1).describe() == "jitter 5.0 mm, outliers 10%"
