"""The 7:2:1 instance split: ratios, purity, disjointness."""

from __future__ import annotations

import pytest

from capt_env.objects.registry import CATEGORIES
from capt_env.objects.sampling import NUM_INSTANCES
from capt_env.objects.splits import SPLITS, instance_ids, split_of


@pytest.mark.parametrize("category", CATEGORIES)
def test_ratios_within_three_percent(category: str) -> None:
    counts = {s: len(instance_ids(category, s)) for s in SPLITS}
    assert sum(counts.values()) == NUM_INSTANCES == 1000
    for split, share in zip(SPLITS, (0.7, 0.2, 0.1), strict=True):
        assert abs(counts[split] / NUM_INSTANCES - share) <= 0.03, counts


def test_split_is_a_pure_function_and_partition() -> None:
    first = [split_of("oven", i) for i in range(NUM_INSTANCES)]
    assert first == [split_of("oven", i) for i in range(NUM_INSTANCES)]
    ids = {s: set(instance_ids("oven", s)) for s in SPLITS}
    assert (
        not (ids["train"] & ids["val"])
        and not (ids["train"] & ids["test"])
        and not (ids["val"] & ids["test"])
    )
    assert all(split_of("oven", i) == s for s in SPLITS for i in ids[s])
    assert first != [split_of("laptop", i) for i in range(NUM_INSTANCES)]  # categories differ


def test_limit_and_errors() -> None:
    assert instance_ids("laptop", "test", limit=5) == instance_ids("laptop", "test")[:5]
    with pytest.raises(ValueError, match="split"):
        instance_ids("laptop", "holdout")
    with pytest.raises(ValueError, match="instance_id"):
        split_of("laptop", -1)
