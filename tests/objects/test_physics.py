"""Physics sanity: with the base fixed, a part at 30 % of its range stays put under gravity for 1 s,
and a modest opening effort (2 N m / 10 N on the joint) opens it noticeably."""

from __future__ import annotations

import pytest

from capt_env.objects.physics_check import probe
from capt_env.objects.registry import CATEGORIES


@pytest.mark.parametrize("category", CATEGORIES)
def test_part_neither_swings_nor_sticks(category: str) -> None:
    for instance_id in (0, 500):
        moved = probe(category, instance_id, seconds=1.0, start_fraction=0.3)
        assert abs(moved["idle"]) < 0.05, moved
        assert moved["pushed"] > 0.1, moved


@pytest.mark.parametrize("category", CATEGORIES)
def test_part_neither_swings_nor_sticks_many_instances(category: str) -> None:
    for instance_id in range(0, 1000, 25):
        moved = probe(category, instance_id, seconds=1.0, start_fraction=0.3)
        assert abs(moved["idle"]) < 0.05, (instance_id, moved)
        assert moved["pushed"] > 0.08, (instance_id, moved)
