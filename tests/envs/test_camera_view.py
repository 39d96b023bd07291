"""Whether a camera sees the part's grasp point, and the task's warning when none does."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest

import capt_env  # noqa: F401 - registers the env ids
from capt_env.registration import env_id
from capt_env.tasks.camera_view import in_picture, pixels, step_back_to_see
from capt_env.tasks.open_articulated import UnseenGraspPointWarning

K = np.array([[100.0, 0.0, 64.0], [0.0, 100.0, 64.0], [0.0, 0.0, 1.0]])
SIZE = 128


def looking_along_x(eye: np.ndarray) -> np.ndarray:
    """The OpenCV extrinsic (3, 4) of a camera at ``eye`` looking along world +x, world +z up."""
    rot = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])  # rows: right, down, forward
    return np.hstack([rot, (-rot @ eye)[:, None]])


def test_a_point_on_the_line_of_sight_is_seen_and_one_far_aside_is_not() -> None:
    ext = looking_along_x(np.zeros(3))
    points = np.array([[1.0, 0.0, 0.0], [1.0, 0.7, 0.0], [1.0, 0.0, -0.7], [-1.0, 0.0, 0.0]])
    assert in_picture(points, K, ext, SIZE, SIZE).tolist() == [True, False, False, False]
    assert np.allclose(pixels(points[:1], K, ext), [[64.0, 64.0]])
    assert step_back_to_see(points[:1], K, ext, SIZE, SIZE) == 0.0


@pytest.mark.parametrize("point", [(1.0, 0.7, 0.0), (1.0, -0.3, 0.9), (-0.5, 0.1, 0.0)])
def test_stepping_back_by_the_reported_distance_brings_a_point_just_into_the_picture(point: tuple) -> None:
    p = np.array([point])
    d = step_back_to_see(p, K, looking_along_x(np.zeros(3)), SIZE, SIZE)
    assert d > 0
    assert in_picture(p, K, looking_along_x(np.array([-d - 1e-6, 0.0, 0.0])), SIZE, SIZE)[0]
    assert not in_picture(p, K, looking_along_x(np.array([-d + 0.01, 0.0, 0.0])), SIZE, SIZE)[0]


def test_a_grasp_point_no_camera_sees_is_warned_about_once() -> None:
    narrow = {"name": "narrow", "eye": [-0.45, -0.35, 0.45], "width": 32, "height": 32, "fov": 0.1}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env = gym.make(env_id("laptop"), obs_mode="state", task={"cameras": [narrow], "split": "test"})
        try:
            env.reset(seed=0)
            env.reset(seed=1)
            views = env.unwrapped.grasp_point_views()
        finally:
            env.close()
    unseen = [w for w in caught if issubclass(w.category, UnseenGraspPointWarning)]
    assert len(unseen) == 1 and "narrow by" in str(unseen[0].message)
    assert [v.camera for v in views] == ["narrow"]
    assert not views[0].seen[0] and views[0].step_back_m[0] > 0.1


def test_the_default_cameras_see_a_procedural_part_s_grasp_point() -> None:
    cameras = [{"name": "left", "eye": [-0.45, 0.35, 0.45], "width": 32, "height": 32},
               {"name": "right", "eye": [-0.45, -0.35, 0.45], "width": 32, "height": 32}]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env = gym.make(env_id("cabinet_door"), obs_mode="state", task={"cameras": cameras, "split": "test"})
        try:
            for seed in range(3):
                env.reset(seed=seed)
                assert all(v.seen[0] and v.step_back_m[0] == 0.0 for v in env.unwrapped.grasp_point_views())
        finally:
            env.close()
    assert not [w for w in caught if issubclass(w.category, UnseenGraspPointWarning)]


def test_the_unseen_grasp_warning_can_be_turned_off() -> None:
    # dataset generation turns it off: a random view that misses the handle is a training sample
    narrow = {"name": "narrow", "eye": [-0.45, -0.35, 0.45], "width": 32, "height": 32, "fov": 0.1}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnseenGraspPointWarning)
        env = gym.make(env_id("laptop"), obs_mode="state", task={"cameras": [narrow], "split": "test"})
    try:
        base = env.unwrapped
        for on in (False, True):
            base.warn_unseen_grasp_point, base._warned_unseen_grasp = on, False  # re-armed
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                env.reset(seed=0)
            assert len([w for w in caught if issubclass(w.category, UnseenGraspPointWarning)]) == int(on)
    finally:
        env.close()
