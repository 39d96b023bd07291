"""The k-th drawer from the bottom is found by its handle on a synthetic cabinet front."""

from __future__ import annotations

import numpy as np
import pytest

from capt_env.wrappers.stacked_parts import handle_groups, kth_handle_from_bottom

# a cabinet facing the robot (-x): front plane x = 0, drawers 0.12 m tall from z = 0.03, bars 3 cm out
HANDLE_Z = (0.09, 0.21, 0.33)


def _cabinet(rng: np.random.Generator,
             handles: tuple[float, ...] = HANDLE_Z) -> tuple[np.ndarray, np.ndarray]:
    """(all points, drawer-front points): a 0.4 x 0.36 m front at x = 0 with a carcass behind it,
    and one horizontal bar per height in ``handles`` standing 3 cm in front."""
    front = np.column_stack([rng.normal(0.0, 0.002, 900), rng.uniform(-0.2, 0.2, 900),
                             rng.uniform(0.03, 0.39, 900)])
    body = np.column_stack([rng.uniform(0.0, 0.4, 600), rng.choice([-0.2, 0.2], 600),
                            rng.uniform(0.03, 0.39, 600)])
    bars = [np.column_stack([rng.normal(-0.03, 0.002, 40), rng.uniform(-0.06, 0.06, 40),
                             rng.normal(z, 0.003, 40)]) for z in handles]
    return np.concatenate([front, body, *bars]), front


def test_handles_are_grouped_bottom_up_and_the_kth_is_picked() -> None:
    cloud, front = _cabinet(np.random.default_rng(0))
    groups = handle_groups(cloud, front)
    assert [round(float(g[:, 2].mean()), 2) for g in groups] == list(HANDLE_Z)
    for k, z in enumerate(HANDLE_Z):
        h = kth_handle_from_bottom(cloud, front, k)
        assert h is not None
        np.testing.assert_allclose(h, [-0.03, 0.0, z], atol=0.01)


def test_a_drawer_front_the_segmentation_missed_still_counts() -> None:
    cloud, front = _cabinet(np.random.default_rng(1))
    top_only = front[front[:, 2] > 0.27]  # CAPT labelled only the top drawer
    h = kth_handle_from_bottom(cloud, top_only, 0)
    assert h is not None and h[2] == pytest.approx(0.09, abs=0.01)


def test_too_few_handles_in_view_gives_none() -> None:
    cloud, front = _cabinet(np.random.default_rng(2), handles=(0.21,))
    assert kth_handle_from_bottom(cloud, front, 0) is not None
    assert kth_handle_from_bottom(cloud, front, 1) is None
    with pytest.raises(ValueError, match="k must be"):
        kth_handle_from_bottom(cloud, front, -1)
    blob = np.random.default_rng(3).normal(size=(200, 3)) * 0.1  # not flat: no front
    assert handle_groups(blob, blob) == []


def test_a_drawer_front_faces_along_the_slide_its_bottom_does_not() -> None:
    from capt_env.wrappers.moving_part_geometry import PartPlane, faces_along

    slide = np.array([-1.0, 0.05, 0.0])
    front = PartPlane(np.zeros(3), np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), np.array([-1.0, 0.0, 0.0]))
    bottom = PartPlane(np.zeros(3), np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), np.array([0.0, 0.0, -1.0]))
    assert faces_along(front, slide) and faces_along(front, -slide)  # the line, either sign
    assert not faces_along(bottom, slide)
    assert not faces_along(None, slide)


def test_a_bar_held_off_the_front_by_posts_is_gripped_at_the_bar_not_the_posts() -> None:
    """A drawer's bar 4 cm out on two posts: the posts' points run from the front to the bar, and a
    centroid over them would sit ~1 cm behind the bar, where closing fingers find nothing."""
    rng = np.random.default_rng(4)
    cloud, front = _cabinet(rng, handles=())
    bar = np.column_stack([rng.normal(-0.04, 0.002, 60), rng.uniform(-0.06, 0.06, 60),
                           rng.normal(0.21, 0.003, 60)])
    posts = [np.column_stack([rng.uniform(-0.04, -0.012, 40), rng.normal(y, 0.003, 40),
                              rng.normal(0.21, 0.003, 40)]) for y in (-0.05, 0.05)]
    cloud = np.concatenate([cloud, bar, *posts])
    h = kth_handle_from_bottom(cloud, front, 0)
    assert h is not None
    handle = np.concatenate([bar, *posts])
    assert h[0] < float(handle[:, 0].mean()) - 0.003  # out towards the bar, away from the posts' centroid
    assert h[0] == pytest.approx(-0.04, abs=0.006)
    np.testing.assert_allclose(h[1:], [0.0, 0.21], atol=0.01)
