"""Wilson interval against hand-computed values."""

import pytest

from agents.success_stats import wilson_interval


def test_known_values() -> None:
    lo, hi = wilson_interval(8, 10)
    assert lo == pytest.approx(0.4902, abs=1e-3) and hi == pytest.approx(0.9433, abs=1e-3)
    lo, hi = wilson_interval(0, 50)
    assert lo == 0.0 and hi == pytest.approx(0.0713, abs=1e-3)
    assert wilson_interval(0, 0) == (0.0, 1.0)


def test_bad_counts() -> None:
    with pytest.raises(ValueError):
        wilson_interval(11, 10)
