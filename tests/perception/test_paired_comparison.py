"""Paired bootstrap of two methods' table values on the same test clouds."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from perception.paired_comparison import (
    bootstrap_difference,
    error_matrix,
    instance_draw_weights,
    paired_differences,
    table_value,
    weighted_table_value,
)

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"


def _sample(category, method, joints):
    return {"category": category, "method": method,
            "joints": [{"joint_index": k, "joint_type": t, "direction_error_deg": d, "position_error": p,
                        "state_error": s} for k, t, d, p, s in joints]}


def test_error_matrix_keeps_joint_slots_and_types_apart():
    samples = [_sample("c", "m", [(0, "revolute", 1.0, 0.1, 2.0), (2, "prismatic", 3.0, None, 0.05)]),
               _sample("c", "m", [(1, "prismatic", 4.0, None, 0.07)])]
    d = error_matrix(samples, "dir_med")
    assert d.shape == (2, 3)
    np.testing.assert_allclose(d, [[1.0, np.nan, 3.0], [np.nan, 4.0, np.nan]])
    np.testing.assert_allclose(error_matrix(samples, "pos_aed")[0], [0.1, np.nan, np.nan])
    np.testing.assert_allclose(error_matrix(samples, "state_deg")[:, 0], [2.0, np.nan])
    np.testing.assert_allclose(error_matrix(samples, "state_m"),
                               [[np.nan, np.nan, 0.05], [np.nan, 0.07, np.nan]])
    # per joint over the clouds that have it, then over joints: (1 + 4 + 3) / 3
    assert table_value(d) == pytest.approx(8.0 / 3.0)
    assert np.isnan(table_value(np.full((2, 1), np.nan)))
    with pytest.raises(ValueError, match="unknown metric"):
        error_matrix(samples, "speed")


@pytest.mark.parametrize("name", ["perception_drawer_cabinet_variants", "perception_eyeglasses_variants"])
def test_table_value_matches_capt_evaluate_summary(name):
    """On a measured run (drawers with 1-3 joints; two temples) the per-sample recomputation gives the
    summary's per-joint means averaged over joints, as the variants table computes them."""
    run = json.loads((BENCH / f"{name}.json").read_text())
    for method, by_cat in run["summary"].items():
        for category, s in by_cat.items():
            samples = [x for x in run["samples"] if x["method"] == method and x["category"] == category]
            assert table_value(error_matrix(samples, "dir_med")) == pytest.approx(np.mean(s["dir_med"]))


def test_pairing_removes_the_spread_between_clouds():
    """Errors that vary from 0 to 100 deg between clouds but are exactly 1 deg lower for the reference
    on every cloud: a paired interval is exactly [-1, -1] (an unpaired one would span tens of degrees)."""
    rng = np.random.default_rng(3)
    other = rng.uniform(1.0, 100.0, size=(200, 1))
    diff = bootstrap_difference({"c": (other - 1.0, other)}, draws=500, seed=0)
    assert diff.difference == pytest.approx(-1.0)
    assert diff.low == pytest.approx(-1.0) and diff.high == pytest.approx(-1.0)
    assert diff.reference_lower_share == 1.0


def test_noise_gives_an_interval_that_covers_zero_and_is_seeded():
    rng = np.random.default_rng(5)
    a, b = rng.normal(10.0, 3.0, size=(200, 1)), rng.normal(10.0, 3.0, size=(200, 1))
    d1 = bootstrap_difference({"c": (a, b)}, draws=1000, seed=7)
    d2 = bootstrap_difference({"c": (a, b)}, draws=1000, seed=7)
    assert d1 == d2
    assert d1.low < 0.0 < d1.high
    assert d1.low < d1.difference < d1.high
    # about sqrt(2) * 3 / sqrt(200) = 0.3 deg standard error: the interval is near +-0.6 wide
    assert 0.8 < d1.high - d1.low < 1.6


def test_mean_over_categories_skips_categories_without_the_metric():
    n = 50
    door = (np.full((n, 1), 2.0), np.full((n, 1), 3.0))   # reference 1 lower
    oven = (np.full((n, 1), 1.0), np.full((n, 1), 4.0))   # reference 3 lower
    drawer = (np.full((n, 1), np.nan), np.full((n, 1), np.nan))  # e.g. no position for a drawer
    diff = bootstrap_difference({"door": door, "oven": oven, "drawer": drawer}, draws=200)
    assert diff.difference == pytest.approx(-2.0) and diff.low == pytest.approx(-2.0)
    assert bootstrap_difference({"drawer": drawer}) is None
    with pytest.raises(ValueError, match="different clouds"):
        bootstrap_difference({"door": (np.zeros((4, 1)), np.zeros((5, 1)))})
    with pytest.raises(ValueError, match="draws"):
        bootstrap_difference({"door": door}, draws=0)


def test_paired_differences_over_methods_and_categories():
    samples = []
    for cat, offset in (("laptop", 1.0), ("oven", 3.0)):
        for i in range(40):
            base = float(i)
            samples.append(_sample(cat, "capt", [(0, "revolute", base, 0.01, base)]))
            samples.append(_sample(cat, "capt_plain", [(0, "revolute", base + offset, 0.01, base)]))
    samples.append(_sample("laptop", "pct_regression", [(0, "revolute", 9.0, 0.1, 9.0)]))  # not on the oven
    result = paired_differences(samples, "capt", draws=300)
    assert list(result) == ["capt_plain"]
    assert result["capt_plain"]["laptop"]["dir_med"].difference == pytest.approx(-1.0)
    assert result["capt_plain"]["mean"]["dir_med"].high == pytest.approx(-2.0)
    assert result["capt_plain"]["mean"]["pos_aed"].difference == pytest.approx(0.0)
    assert result["capt_plain"]["mean"]["state_m"] is None
    with pytest.raises(ValueError, match="reference method 'oracle'"):
        paired_differences(samples, "oracle")


def test_weighted_table_value_counts_each_cloud_as_often_as_drawn():
    errors = np.array([[1.0, np.nan], [3.0, 10.0], [np.nan, 20.0]])
    # cloud 0 twice, cloud 2 once: joint 0 mean (1 + 1) / 2, joint 1 mean 20 -> (1 + 20) / 2
    w = np.array([[2.0, 0.0, 1.0], [1.0, 1.0, 1.0]])
    np.testing.assert_allclose(weighted_table_value(errors, w), [10.5, table_value(errors)])
    rng = np.random.default_rng(0)
    idx = rng.integers(0, 3, size=(50, 3))
    counts = np.stack([np.bincount(r, minlength=3) for r in idx]).astype(float)
    np.testing.assert_allclose(weighted_table_value(errors, counts), table_value(errors[idx]))


def test_instance_draws_take_every_cloud_of_a_drawn_instance():
    ids = np.array([7, 7, 7, 3, 3, 9])
    w = instance_draw_weights(ids, 200, np.random.default_rng(1))
    assert w.shape == (200, 6)
    assert (w[:, 0] == w[:, 1]).all() and (w[:, 1] == w[:, 2]).all() and (w[:, 3] == w[:, 4]).all()
    # three instances drawn per draw
    assert (w[:, [0, 3, 5]].sum(axis=1) == 3).all()


def test_one_cloud_per_instance_gives_the_cloud_bootstrap():
    rng = np.random.default_rng(5)
    other = rng.uniform(0.0, 10.0, size=(40, 1))
    ref = other + rng.normal(0.0, 1.0, size=(40, 1))
    pairs = {"c": (ref, other)}
    clouds = bootstrap_difference(pairs, draws=300, seed=2)
    instances = bootstrap_difference(pairs, draws=300, seed=2, instances={"c": np.arange(40)})
    assert (instances.low, instances.high) == pytest.approx((clouds.low, clouds.high))


def test_views_of_one_instance_that_err_together_widen_the_interval():
    """10 instances x 5 views whose gap is the instance's (views agree): resampling clouds treats 50
    agreeing views as 50 independent clouds; resampling instances sees 10, an interval about sqrt(5)
    times wider."""
    rng = np.random.default_rng(7)
    per_instance = rng.normal(0.0, 1.0, size=10)
    gap = np.repeat(per_instance, 5)[:, None]
    other = rng.uniform(5.0, 6.0, size=(50, 1))
    pairs = {"c": (other + gap, other)}
    clouds = bootstrap_difference(pairs, draws=2000, seed=0)
    inst = bootstrap_difference(pairs, draws=2000, seed=0, instances={"c": np.repeat(np.arange(10), 5)})
    assert clouds.difference == inst.difference
    ratio = (inst.high - inst.low) / (clouds.high - clouds.low)
    assert 1.7 < ratio < 3.0


def test_instance_resampling_needs_matching_instance_ids():
    a = [dict(_sample("c", m, [(0, "revolute", 1.0 + i, 0.1, 2.0)]), instance_id=i // 2)
         for m in ("capt", "plain") for i in range(4)]
    out = paired_differences(a, "capt", draws=100, resample="instances")
    assert out["plain"]["c"]["dir_med"] is not None
    missing = [dict(x) for x in a]
    del missing[5]["instance_id"]
    with pytest.raises(ValueError, match="without an instance_id"):
        paired_differences(missing, "capt", draws=10, resample="instances")
    other = [dict(x, instance_id=x["instance_id"] + (x["method"] == "plain")) for x in a]
    with pytest.raises(ValueError, match="other instances"):
        paired_differences(other, "capt", draws=10, resample="instances")
    with pytest.raises(ValueError, match="resample must be"):
        paired_differences(a, "capt", draws=10, resample="objects")
