"""Metrics against hand-computed values (paper Table I definitions)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from perception.metrics import (
    JointResult,
    SampleResult,
    average_precision,
    direction_error_deg,
    line_distance,
    mean_iou,
    median_table_markdown,
    segmentation_accuracy,
    state_error,
    summarise,
    table_markdown,
)


def test_direction_error_sign_convention():
    assert direction_error_deg([1, 0, 0], [-1, 0, 0]) == pytest.approx(180.0)
    assert direction_error_deg([0, 0, 2], [0, 0, 1]) == pytest.approx(0.0, abs=1e-9)
    assert direction_error_deg([1, 0, 0], [0, 1, 0]) == pytest.approx(90.0)
    assert direction_error_deg([1, 1, 0], [1, 0, 0]) == pytest.approx(45.0)


def test_line_distance_cases():
    assert line_distance([0, 0, 1], [0, 0, 0], [0, 0, 1], [0.03, 0.04, 9]) == pytest.approx(0.05)  # parallel
    assert line_distance([1, 0, 0], [0, 0, 0], [0, 1, 0], [0, 0, 0.2]) == pytest.approx(0.2)  # skew
    assert line_distance([1, 0, 0], [0, 0, 0], [0, 1, 1], [3, -1, -1]) == pytest.approx(0.0, abs=1e-12)


def test_segmentation_accuracy_and_miou_hand_example():
    gt = np.array([0, 0, 0, 1, 1, 1, -1])
    pred = np.array([0, 0, 1, 1, 1, 2, 0])
    # valid points: 6; correct: 0,0,_,1,1,_ = 4
    assert segmentation_accuracy(pred, gt) == pytest.approx(4 / 6)
    # IoU0 = 2/3, IoU1 = 2/4, IoU2 = 0/1 (part only in the prediction)
    assert mean_iou(pred, gt) == pytest.approx((2 / 3 + 0.5 + 0.0) / 3)


def test_state_error_units():
    assert state_error(math.radians(30), math.radians(20), "revolute") == pytest.approx(10.0)
    assert state_error(0.12, 0.10, "prismatic") == pytest.approx(0.02)


def test_average_precision_is_strictly_below():
    errs = [1.0, 4.9, 5.0, 7.0, 12.0, float("nan")]
    assert average_precision(errs, 5.0) == pytest.approx(2 / 5)
    assert average_precision(errs, 10.0) == pytest.approx(4 / 5)
    assert math.isnan(average_precision([], 5.0))


def _result(dir_err, pos, state, method="capt", cat="laptop"):
    return SampleResult(cat, method, 1.0, 1.0, (JointResult(0, "revolute", dir_err, pos, pos, state),), 10.0)


def test_summarise_and_table():
    rs = [_result(2.0, 0.005, 4.0), _result(8.0, 0.03, 20.0)]
    s = summarise(rs)
    assert s["dir_med"] == [pytest.approx(5.0)]
    assert s["dir_ap5"] == [0.5] and s["dir_ap10"] == [1.0]
    assert s["pos_aed"] == [pytest.approx(0.0175)]
    assert s["pos_ap1"] == [0.5] and s["pos_ap5"] == [1.0]
    assert s["state_ap5"] == [0.5] and s["state_ap10"] == [0.5]
    assert s["dir_median"] == [pytest.approx(5.0)] and s["dir_flipped"] == [0.0]
    flips = summarise([_result(0.2, 0.005, 1.0), _result(0.4, 0.005, 1.0), _result(179.0, 0.005, 1.0)])
    assert flips["dir_median"] == [pytest.approx(0.4)]
    assert flips["dir_flipped"] == [pytest.approx(1 / 3)]
    assert flips["dir_med"] == [pytest.approx(179.6 / 3)]  # the paper's mean, carried by the flip
    prism = SampleResult("drawer", "capt", None, None, (JointResult(0, "prismatic", 1.0, None, None, 0.02),))
    table = table_markdown([*rs, prism])
    lines = table.splitlines()
    assert lines[0].startswith("| Dataset | Method | PA | mIoU | Dir MED")
    row = "| laptop | capt | 1.00 | 1.00 | 5.00 | 0.50 | 1.00 | 0.02 | 0.50 | 1.00 | 12.00 | 0.50 | 0.50 |"
    assert row in table
    drawer = next(line for line in lines if line.startswith("| drawer"))
    assert "| - | - | 1.00 |" in drawer  # no segmentation; position '-' for prismatic
    assert any(line.startswith("| Mean | capt") for line in lines)


def test_median_table_reports_the_middle_error_not_the_mean_a_flip_carries():
    door = [SampleResult("door", "capt", 1.0, 1.0, (JointResult(0, "revolute", e, 0.1, pos_m, state),))
            for e, pos_m, state in ((0.2, 0.01, 2.0), (0.4, 0.03, 8.0), (179.0, 0.40, 60.0))]
    drawer = [SampleResult("drawer", "capt", 1.0, 1.0, (JointResult(0, "prismatic", 3.0, None, None, s),))
              for s in (0.01, 0.02, 0.09)]
    s = summarise(door)
    assert s["pos_median_m"] == [pytest.approx(0.03)] and s["state_median"] == [pytest.approx(8.0)]
    assert math.isnan(summarise(drawer)["pos_median_m"][0])
    lines = median_table_markdown(door + drawer).splitlines()
    assert lines[0] == "| Dataset | Method | Dir median (deg) | Flipped | Pos median (cm) | State median |"
    assert "| door | capt | 0.4 | 0.33 | 3.0 | 8.0 deg |" in lines
    assert "| drawer | capt | 3.0 | 0.00 | - | 0.020 m |" in lines
