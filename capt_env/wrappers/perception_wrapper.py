"""``CaptObservationWrapper``: a capt_env single env -> joint-axis observations for policies.

Per perception run (on reset, then every ``every_k_steps`` steps): isolate the object's points of
the world-frame cloud (``isolation.mode``), downsample them to ``num_points`` (seeded), estimate the
target joint with the configured source, and keep the estimate. Every step the observation is the
proprioception of that step plus the latest estimate (layout: :mod:`capt_env.wrappers.joint_observation`).
For the CAPT sources these are the stages of :mod:`~capt_env.wrappers.estimate_pipeline`: this
wrapper runs the first (isolate) and the last (observe), the source the ones between.

``info`` gains ``perception_ran`` (bool, perception ran on this step) and ``object_points`` (int,
isolated object points of the last run; -1 when the source reads no cloud). The wall-clock time of
the last run (isolation + estimate, ms) is the attribute ``last_perception_latency_ms``, not an
``info`` entry, so that a step's info depends only on the seed and the actions (Gymnasium's
determinism check).
Oracle sources work with any obs mode; ``capt_raw`` and ``capt`` need ``obs_mode="pointcloud"``. The
cameras render only on the steps perception looks at them (never for oracle sources): the base env repeats its
last observation in between, which changes nothing the wrapper returns.
"""

from __future__ import annotations

import time
from typing import Any

import gymnasium as gym
import numpy as np

from capt_common.typed_yaml import from_dict
from capt_env.wrappers.config import PerceptionWrapperConfig
from capt_env.wrappers.estimate import JointAxisEstimate
from capt_env.wrappers.estimate_pipeline import isolate_object, network_input, observe
from capt_env.wrappers.joint_observation import dict_space, flat_space
from capt_env.wrappers.object_isolation import camera_viewpoint
from capt_env.wrappers.perception_sources import PerceptionSource, make_source
from capt_env.wrappers.robot_filter import RobotPointFilter


class CaptObservationWrapper(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Joint-axis observations (flat Box or Dict, float32) from a capt_env ``-v0`` env.

    :param env: a ``CaptOpen*-v0`` env (numpy, one sub-scene).
    :param config: a :class:`PerceptionWrapperConfig` or a dict of its fields (validated).
    """

    def __init__(self, env: gym.Env, config: PerceptionWrapperConfig | dict | None = None) -> None:
        gym.utils.RecordConstructorArgs.__init__(self, config=config)
        gym.Wrapper.__init__(self, env)
        cfg = from_dict(PerceptionWrapperConfig, config or {}, where="perception_wrapper")
        cfg.validate()
        self.config = cfg
        self.source: PerceptionSource = make_source(cfg)
        obs_mode = getattr(env.unwrapped, "obs_mode", None)
        if self.source.needs_points and obs_mode != "pointcloud":
            raise ValueError(
                f"perception source {cfg.source!r} needs obs_mode='pointcloud', got {obs_mode!r}")
        self.observation_space = flat_space() if cfg.obs_format == "flat" else dict_space()
        self._rng = np.random.default_rng(cfg.seed)
        self._robot_filter: RobotPointFilter | None = None
        self._estimate: JointAxisEstimate | None = None
        self._steps = 0
        self._object_points = -1
        self.last_perception_latency_ms = 0.0  # wall-clock ms of the last perception run

    @property
    def estimate(self) -> JointAxisEstimate | None:
        """The latest estimate (world frame), None before the first reset."""
        return self._estimate

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[Any, dict]:
        obs, info = self.env.reset(seed=seed, options=options)
        if seed is not None:
            self._rng = np.random.default_rng([self.config.seed, seed])
            if hasattr(self.source, "rng"):
                self.source.rng = np.random.default_rng([self.config.seed, seed, 1])
        if hasattr(self.source, "reset"):
            self.source.reset()
        self._robot_filter = None  # the robot is rebuilt on reconfiguration
        self._steps = 0
        self._estimate = None
        latency = self._perceive(obs, info)
        return self._observation(), self._info(info, True, latency)

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict]:
        ran = (self._steps + 1) % self.config.every_k_steps == 0
        base = self.env.unwrapped
        if hasattr(base, "sensors_on_next_obs"):  # render only when the cameras are looked at
            base.sensors_on_next_obs = ran and self.source.needs_points
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._steps += 1
        latency = self._perceive(obs, info) if ran else 0.0
        out_info = self._info(info, ran, latency)
        return self._observation(), float(reward), bool(terminated), bool(truncated), out_info

    # ----------------------------------------------------------------- parts
    def _perceive(self, obs: Any, info: dict) -> float:
        t0 = time.perf_counter()
        if self.source.needs_points:
            points = self._object_cloud(obs)
            if len(points) < 32:  # nothing to see: keep the last estimate
                if self._estimate is None:
                    self._estimate = JointAxisEstimate("revolute", np.array([0.0, 0.0, 1.0]), np.zeros(3),
                                                       0.0, np.zeros(3), 0.0)
                return (time.perf_counter() - t0) * 1000.0
            fed = network_input(points, self.config.num_points, self._rng)
            self._estimate = self.source.estimate(fed, info, dense_points=points,
                                                  viewpoint=camera_viewpoint(obs))
        else:
            self._estimate = self.source.estimate(None, info)
        return (time.perf_counter() - t0) * 1000.0

    def _object_cloud(self, obs: Any) -> np.ndarray:
        cloud = obs["pointcloud"]
        if self.config.isolation.mode == "geometric" and self._robot_filter is None:
            self._robot_filter = RobotPointFilter(self.env.unwrapped.agent.robot)
        points = isolate_object(cloud, self.config.isolation, self._robot_filter)
        self._object_points = len(points)
        return points

    def proprioception(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Panda qpos (9,), qvel (9,) and TCP pose (7,: position m, quaternion wxyz), world frame."""
        agent = self.env.unwrapped.agent

        def first(t: Any) -> np.ndarray:
            return np.asarray(t.cpu().numpy() if hasattr(t, "cpu") else t, dtype=np.float32).reshape(
                -1, t.shape[-1])[0]

        return first(agent.robot.get_qpos()), first(agent.robot.get_qvel()), first(agent.tcp.pose.raw_pose)

    def _observation(self) -> Any:
        assert self._estimate is not None
        return observe(*self.proprioception(), self._estimate, self.config.obs_format)

    def _info(self, info: dict, ran: bool, latency: float) -> dict:
        if ran:
            self.last_perception_latency_ms = float(latency)
        out = dict(info)
        out["perception_ran"] = bool(ran)
        out["object_points"] = int(self._object_points)
        return out
