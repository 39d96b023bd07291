"""The scripted opener opens real instances with oracle perception, from the estimate alone."""

from __future__ import annotations

import numpy as np
import pytest

import capt_env  # noqa: F401
from agents.scripted import ScriptedOpener, ScriptedOpenerConfig
from agents.scripted.geometry import axis_angle_matrix, swept_angle
from agents.scripted.opener import outward_normal
from agents.scripted.rollout import make_env, run_episode
from capt_env.wrappers.estimate import JointAxisEstimate
from perception.yaml_config import ConfigError, from_dict


def test_outward_normal_of_a_door_points_at_the_robot() -> None:
    # hinge along +z at y = -0.2, handle at y = +0.2 on the front face x = -0.1: opens towards -x
    est = JointAxisEstimate("revolute", np.array([0.0, 0.0, 1.0]), np.array([-0.1, -0.2, 0.3]), 0.0,
                            np.array([-0.1, 0.2, 0.3]))
    np.testing.assert_allclose(outward_normal(est), [-1.0, 0.0, 0.0], atol=1e-9)


def test_swept_angle_is_signed_and_ignores_travel_along_the_axis() -> None:
    axis, pivot = np.array([0.0, 0.0, 1.0]), np.array([0.5, -0.2, 0.0])
    start = pivot + np.array([0.0, 0.4, 0.3])
    for angle in (0.3, -1.2, 2.5):
        now = pivot + axis_angle_matrix(axis, angle) @ (start - pivot) + np.array([0.0, 0.0, 0.1])
        assert swept_angle(axis, pivot, start, now) == pytest.approx(angle, abs=1e-9)
    assert swept_angle(axis, pivot, start, pivot + np.array([0.0, 0.0, 0.2])) == 0.0


def test_bad_opener_config_is_rejected() -> None:
    with pytest.raises(ConfigError, match="close_steps"):
        from_dict(ScriptedOpenerConfig, {"close_steps": 0})


def test_opens_a_washing_machine_door_with_oracle_perception() -> None:
    env = make_env("washing_machine", {"source": "oracle"})
    try:
        result = run_episode(env, ScriptedOpener(), seed=0, max_steps=150)
    finally:
        env.close()
    assert result.success, result
    assert result.open_fraction >= 0.75


@pytest.mark.slow
def test_opens_a_drawer_with_noisy_oracle_perception() -> None:
    env = make_env("drawer_cabinet", {"source": "noisy_oracle"})
    try:
        result = run_episode(env, ScriptedOpener(), seed=0, max_steps=200)
    finally:
        env.close()
    assert result.success, result
