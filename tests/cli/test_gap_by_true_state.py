"""scripts/gap_by_true_state.py: clouds go into the bin of their true state, runs stay apart, and a
file that does not match the dataset is refused."""

from __future__ import annotations

import numpy as np
import pytest

from perception.paired_comparison import paired_differences


def _run(method_errors: dict[str, list[float]], instances: list[int]) -> dict:
    samples = [{"category": "oven", "method": m, "instance_id": instances[i],
                "joints": [{"joint_index": 0, "joint_type": "revolute", "direction_error_deg": 1.0,
                            "position_error": 0.01, "state_error": e}]}
               for m, errs in method_errors.items() for i, e in enumerate(errs)]
    return {"samples": samples}


def test_clouds_are_binned_by_true_state_and_the_gap_is_per_bin(load_script):
    gb = load_script("gap_by_true_state")
    states = np.array([5.0, 30.0, 60.0, 10.0, 80.0, 200.0])  # degrees; the last is outside every bin
    ids = np.array([1, 1, 2, 2, 3, 3])
    run = _run({"capt": [1, 5, 5, 1, 5, 9], "capt_plain": [2, 3, 3, 2, 3, 0]}, ids.tolist())
    samples = gb.binned_samples([run], states, ids, [0, 20, 90], "deg", None)
    assert len(samples) == 10  # 5 clouds in a bin, two methods
    labels = {s["category"] for s in samples}
    assert labels == {"true state 0-20 deg", "true state 20-90 deg"}
    assert all(s["run"] == 0 for s in samples)
    gaps = paired_differences(samples, "capt", draws=200, seed=0)["capt_plain"]
    low, high = gaps["true state 0-20 deg"]["state_deg"], gaps["true state 20-90 deg"]["state_deg"]
    assert low.difference == pytest.approx(-1.0) and (low.low, low.high) == pytest.approx((-1.0, -1.0))
    assert high.difference == pytest.approx(2.0) and (high.low, high.high) == pytest.approx((2.0, 2.0))
    only = gb.binned_samples([run], states, ids, [0, 20, 90], "deg", ["capt"])
    assert {s["method"] for s in only} == {"capt"}


def test_mismatched_files_and_bad_edges_are_named(load_script):
    gb = load_script("gap_by_true_state")
    states, ids = np.array([5.0, 30.0]), np.array([1, 2])
    run = _run({"capt": [1.0, 2.0]}, [1, 2])
    with pytest.raises(ValueError, match="increasing"):
        gb.binned_samples([run], states, ids, [10, 0], "deg", None)
    with pytest.raises(ValueError, match="instance 1, the split's cloud 0 instance 7"):
        gb.binned_samples([run], states, np.array([7, 2]), [0, 90], "deg", None)
    with pytest.raises(ValueError, match="scored {'capt': 2} clouds, the split holds 3"):
        gb.binned_samples([run], np.array([5.0, 30.0, 40.0]), np.array([1, 2, 3]), [0, 90], "deg", None)
    with pytest.raises(ValueError, match="no sample falls in any bin"):
        gb.binned_samples([run], states, ids, [100, 200], "deg", None)
