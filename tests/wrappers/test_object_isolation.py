"""Label-free (geometric) object isolation keeps the object and drops table and robot, on fixed scenes."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import capt_env  # noqa: F401
from capt_env.wrappers.config import IsolationConfig
from capt_env.wrappers.object_isolation import (
    fit_plane_ransac,
    geometric_mask,
    isolation_quality,
    statistical_inliers,
)
from capt_env.wrappers.robot_filter import RobotPointFilter


def test_ransac_finds_a_tilted_table_and_outliers_are_dropped() -> None:
    rng = np.random.default_rng(0)
    xy = rng.uniform(-0.5, 0.5, (2000, 2))
    table = np.column_stack([xy, 0.05 * xy[:, 0] + rng.normal(0, 0.001, 2000)])
    box = rng.uniform([0, 0, 0.05], [0.2, 0.2, 0.3], (500, 3))
    plane = fit_plane_ransac(np.concatenate([table, box]), 100, 0.004, seed=0)
    assert plane is not None
    np.testing.assert_allclose(plane.normal, np.array([-0.05, 0, 1]) / np.linalg.norm([-0.05, 0, 1]),
                               atol=0.01)
    cloud = np.concatenate([box, [[3.0, 3.0, 3.0]]])
    keep = statistical_inliers(cloud, 8, 3.0)
    assert not keep[-1] and keep[:-1].mean() > 0.98


@pytest.mark.parametrize("category", ["cabinet_door", "drawer_cabinet"])
def test_geometric_isolation_meets_recall_and_precision(category: str) -> None:
    env = gym.make("CaptOpenArticulated-v0", obs_mode="pointcloud", control_mode="pd_ee_delta_pose",
                   task={"category": category, "split": "test", "object_xy": (0.3, 0.0)})
    try:
        obs, _ = env.reset(seed=0)
        for _ in range(8):  # bring the hand next to the object so the robot filter matters
            obs, *_ = env.step(np.array([0.5, 0.0, -0.3, 0, 0, 0, 1.0], np.float32))
        cloud = obs["pointcloud"]
        robot = RobotPointFilter(env.unwrapped.agent.robot)
        mask = geometric_mask(cloud["xyzw"], IsolationConfig(mode="geometric", seed=0), robot)
        q = isolation_quality(mask, cloud["part_label"])
        assert q.recall >= 0.95, q
        assert q.non_object_share <= 0.05, q
        robot_ids = [int(link.per_scene_id.reshape(-1)[0]) for link in env.unwrapped.agent.robot.links]
        on_robot = np.isin(cloud["segmentation"][:, 0], robot_ids)
        assert on_robot.sum() > 100 and not (mask & on_robot).any()
    finally:
        env.close()
