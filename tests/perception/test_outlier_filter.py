"""Statistical outlier removal before inference (``ArticulationEstimator(outlier_filter=...)``)."""

from __future__ import annotations

import numpy as np
import pytest

from perception.outlier_filter import OutlierFilter, inlier_mask, mean_neighbour_distance


def _plane_with_strays(strays: int = 60) -> tuple[np.ndarray, int]:
    """A 40 x 40 grid (1 cm spacing) lightly jittered, then stray points 10-30 cm above or below it."""
    rng = np.random.default_rng(0)
    g = np.stack(np.meshgrid(np.arange(40) * 0.01, np.arange(40) * 0.01), axis=-1).reshape(-1, 2)
    plane = np.column_stack([g, np.zeros(len(g))]) + rng.normal(0, 0.001, (len(g), 3))
    xy = rng.uniform(0, 0.39, (strays, 2))
    z = rng.choice([-1.0, 1.0], strays) * rng.uniform(0.1, 0.3, strays)
    return np.concatenate([plane, np.column_stack([xy, z])]), len(plane)


def test_mean_neighbour_distance_on_a_line_and_in_chunks() -> None:
    line = np.column_stack([np.arange(10.0), np.zeros(10), np.zeros(10)])
    d = mean_neighbour_distance(line, 2)
    assert d[5] == pytest.approx(1.0) and d[0] == pytest.approx(1.5)  # ends: neighbours at 1 and 2
    cloud, _ = _plane_with_strays()
    whole = mean_neighbour_distance(cloud, 8)
    np.testing.assert_allclose(mean_neighbour_distance(cloud, 8, chunk=100), whole)
    assert (mean_neighbour_distance(line[:3], 8) > 0).all()  # fewer points than neighbours asked


def test_strays_are_dropped_and_the_surface_kept() -> None:
    cloud, n = _plane_with_strays()
    keep = inlier_mask(cloud, OutlierFilter())
    assert not keep[n:].any()
    assert keep[:n].mean() > 0.97


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"neighbours": 0}, "neighbours must be"), ({"neighbours": 2.5}, "neighbours must be"),
    ({"neighbours": True}, "neighbours must be"), ({"std_ratio": 0.0}, "std_ratio must be"),
    ({"std_ratio": float("inf")}, "std_ratio must be"),
])
def test_a_bad_filter_is_named(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        OutlierFilter(**kwargs)
