"""PPO on a batched ManiSkill env (``vec_env: maniskill``): the batched ground-truth observation, the
SB3 vector env over it, and a short training run. ManiSkill's CPU simulation holds one sub-scene, so
the batching itself (masks, partial resets, episodes ending at different steps) is checked on a
small fake batched env, and the real env runs with one sub-scene."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest
import torch

import capt_env  # noqa: F401
from agents.ppo.config import PPOTrainConfig
from agents.ppo.maniskill_vec_env import ManiSkillVecEnv
from agents.ppo.policy import PPOPolicy
from agents.ppo.train import make_vec_env, train_ppo
from capt_common.typed_yaml import ConfigError, from_dict
from capt_env.env_factory import make_env
from capt_env.wrappers.batched_oracle_observation import BatchedOracleObservation, ground_truth
from capt_env.wrappers.joint_observation import OBSERVATION_SIZE, observation_layout
from perception.metrics import direction_error_deg, line_distance

LAYOUT = observation_layout()


class FakeBatchedEnv(gym.Env):
    """``n`` sub-scenes with one revolute joint about +z through the origin whose state is the
    sub-scene's step count; sub-scene i's episode is cut after ``limits[i]`` steps and it succeeds
    from step ``success_from`` on (terminating there). Resets honour ``env_idx``."""

    def __init__(self, limits: list[int], success_from: int = 10_000) -> None:
        self.num_envs, self.device = len(limits), torch.device("cpu")
        self.limits = torch.tensor(limits)
        self.success_from = success_from
        self.single_action_space = gym.spaces.Box(-1.0, 1.0, (7,), np.float32)
        self.action_space = self.single_action_space
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (self.num_envs, 3), np.float32)
        self.count = torch.zeros(self.num_envs, dtype=torch.long)
        self.resets: list[tuple[list[int], bool]] = []
        qpos = torch.zeros(self.num_envs, 9)
        tcp = SimpleNamespace(pose=SimpleNamespace(raw_pose=torch.zeros(self.num_envs, 7)))
        robot = SimpleNamespace(get_qpos=lambda: qpos, get_qvel=lambda: qpos)
        self.agent = SimpleNamespace(robot=robot, tcp=tcp)

    def _info(self) -> dict[str, torch.Tensor]:
        n = self.num_envs
        return {"joint_type": torch.zeros(n, 1, dtype=torch.long),
                "joint_axis": torch.tensor([0.0, 0.0, 1.0]).expand(n, 1, 3),
                "joint_pivot": torch.zeros(n, 1, 3), "joint_state": self.count.float().unsqueeze(-1),
                "target_joint": torch.zeros(n, dtype=torch.long),
                "grasp_point": torch.tensor([0.5, 0.0, 0.2]).expand(n, 3),
                "success": self.count >= self.success_from}

    def reset(self, *, seed=None, options=None):
        idx = (options or {}).get("env_idx")
        idx = list(range(self.num_envs)) if idx is None else torch.as_tensor(idx).tolist()
        self.resets.append((idx, bool((options or {}).get("reconfigure", False))))
        self.count[idx] = 0
        return torch.zeros(self.num_envs, 3), self._info()

    def step(self, action):
        assert action.shape == (self.num_envs, 7)
        self.count += 1
        info = self._info()
        return (torch.zeros(self.num_envs, 3), torch.ones(self.num_envs), info["success"].clone(),
                self.count >= self.limits, info)


def _state(obs: torch.Tensor | np.ndarray) -> np.ndarray:
    return np.asarray(obs)[:, LAYOUT["state"]].reshape(-1)


def test_batched_estimate_is_held_between_looks_and_partial_resets_restart_one_sub_scene():
    env = BatchedOracleObservation(FakeBatchedEnv([100, 100, 100]), {"source": "oracle", "every_k_steps": 3})
    obs, info = env.reset(seed=0)
    assert obs.shape == (3, OBSERVATION_SIZE) and obs.dtype == torch.float32
    assert env.observation_space.shape == (3, OBSERVATION_SIZE)
    assert info["perception_ran"].tolist() == [True] * 3
    seen = []
    for _ in range(4):
        obs, _, _, _, info = env.step(torch.zeros(3, 7))
        seen.append(_state(obs).tolist())
    assert seen == [[0, 0, 0], [0, 0, 0], [3, 3, 3], [3, 3, 3]]  # looks at steps 3, 6, ...
    obs, info = env.reset(options={"env_idx": torch.tensor([1])})
    assert _state(obs).tolist() == [3, 0, 3] and info["perception_ran"].tolist() == [False, True, False]
    for _ in range(2):
        obs, _, _, _, info = env.step(torch.zeros(3, 7))
    # sub-scenes 0 and 2 look at their step 6, sub-scene 1 will at its own step 3
    assert info["perception_ran"].tolist() == [True, False, True]
    assert _state(obs).tolist() == [6, 0, 6]
    obs, _, _, _, info = env.step(torch.zeros(3, 7))
    assert _state(obs).tolist() == [6, 3, 6] and info["perception_ran"].tolist() == [False, True, False]
    assert np.allclose(np.asarray(obs)[:, LAYOUT["direction"]], [0.0, 0.0, 1.0])
    assert np.allclose(np.asarray(obs)[:, LAYOUT["pivot"]], [0.0, 0.0, 0.2])  # closest to the grasp point


def test_vec_env_ends_each_episode_on_its_own():
    fake = FakeBatchedEnv([2, 3, 5], success_from=3)
    venv = ManiSkillVecEnv(BatchedOracleObservation(fake, {"source": "oracle"}), continue_after_success=False)
    venv.reset()
    done_at: dict[int, list[dict]] = {}
    for t in range(1, 7):
        venv.step_async(np.zeros((3, 7), np.float32))
        obs, rewards, dones, infos = venv.step_wait()
        assert obs.shape == (3, OBSERVATION_SIZE) and rewards.tolist() == [1.0] * 3
        for i in np.flatnonzero(dones):
            done_at.setdefault(int(i), []).append({"t": t, **infos[i]})
    # env 0 cut at 2 steps (and again at 4, 6), env 1 succeeds (terminates) at 3, env 2 at 3 too
    assert [d["t"] for d in done_at[0]] == [2, 4, 6]
    assert done_at[0][0]["episode"] == {"r": 2.0, "l": 2, "success": False}
    assert done_at[0][0]["TimeLimit.truncated"] is True
    assert done_at[1][0]["episode"]["success"] is True and done_at[1][0]["TimeLimit.truncated"] is False
    assert done_at[0][0]["terminal_observation"].shape == (OBSERVATION_SIZE,)
    assert _state(done_at[0][0]["terminal_observation"][None]).tolist() == [2.0]  # its last step's look
    assert fake.resets[1] == ([0], False)  # the first auto-reset is partial


def test_vec_env_success_does_not_end_training_episodes_and_reconfigure_cuts_all():
    fake = FakeBatchedEnv([4, 4], success_from=1)
    venv = ManiSkillVecEnv(BatchedOracleObservation(fake, {"source": "oracle"}), continue_after_success=True,
                           reconfigure_every=6)
    venv.reset()
    dones = []
    for _ in range(6):
        venv.step_async(np.zeros((2, 7), np.float32))
        _, _, done, infos = venv.step_wait()
        dones.append(done.tolist())
    assert dones == [[False, False]] * 3 + [[True, True]] + [[False, False], [True, True]]
    assert infos[0]["episode"] == {"r": 2.0, "l": 2, "success": True}  # cut by the reconfiguration
    assert infos[0]["TimeLimit.truncated"] is True
    assert fake.resets[-1] == ([0, 1], True)
    with pytest.raises(ValueError, match="reconfigure_every"):
        ManiSkillVecEnv(BatchedOracleObservation(fake), reconfigure_every=-1)


def test_a_seeded_vec_env_reset_rebuilds_so_instances_follow_the_seed():
    fake = FakeBatchedEnv([4, 4])
    venv = ManiSkillVecEnv(BatchedOracleObservation(fake, {"source": "oracle"}))
    venv.reset()
    venv.seed(7)
    venv.reset()
    assert fake.resets == [([0, 1], False), ([0, 1], True)]


def test_batched_wrapper_rejects_what_it_cannot_do():
    fake = FakeBatchedEnv([5])
    with pytest.raises(ConfigError, match="oracle"):
        BatchedOracleObservation(fake, {"source": "capt", "checkpoint": "x.pt"})
    with pytest.raises(ConfigError, match="flat"):
        BatchedOracleObservation(fake, {"obs_format": "dict"})
    with pytest.raises(ConfigError, match="every_k"):
        BatchedOracleObservation(fake, {"every_k_steps": 0})


@pytest.mark.render
def test_batched_oracle_observation_equals_the_single_env_wrapper():
    """One sub-scene of the real task on the CPU: the same seed and actions give the same 38 floats
    as CaptObservationWrapper with the oracle source, at reset and for 7 steps (looks every 5)."""
    cfg = {"source": "oracle", "every_k_steps": 5}
    single = make_env("drawer_cabinet", cfg)
    batched = BatchedOracleObservation(
        gym.make("CaptOpenDrawerCabinet-ms-v0", num_envs=1, obs_mode="state", task={"split": "test"}), cfg)
    try:
        o1, _ = single.reset(seed=7)
        o2, _ = batched.reset(seed=7)
        np.testing.assert_allclose(o2[0].numpy(), o1, atol=1e-6)
        rng = np.random.default_rng(0)
        for t in range(1, 8):
            action = rng.uniform(-1.0, 1.0, size=7).astype(np.float32)
            o1, r1, _, _, i1 = single.step(action)
            o2, r2, _, _, i2 = batched.step(torch.as_tensor(action)[None])
            np.testing.assert_allclose(o2[0].numpy(), o1, atol=1e-5)
            assert float(r2[0]) == pytest.approx(r1, abs=1e-6)
            assert bool(i2["perception_ran"][0]) == i1["perception_ran"] == (t % 5 == 0)
    finally:
        single.close()
        batched.close()


@pytest.mark.render
def test_batched_fixed_offset_noise_has_exact_sizes_held_for_the_episode():
    noise = {"model": "fixed_offset", "direction_rad": 0.1, "pivot_m": 0.0, "state": 0.05, "grasp_m": 0.01}
    env = BatchedOracleObservation(gym.make("CaptOpenLaptop-ms-v0", num_envs=1, obs_mode="state"),
                                   {"source": "noisy_oracle", "every_k_steps": 2, "noise": noise})
    try:
        signs, tilts = [], []
        for seed in (0, 1):
            obs, info = env.reset(seed=seed)
            for look in range(3):
                gt, est = ground_truth(info), env.estimate
                u, d = gt["direction"][0].numpy(), est["direction"][0].numpy()
                assert direction_error_deg(d, u) == pytest.approx(np.degrees(0.1), abs=1e-3)
                assert np.linalg.norm(est["grasp_point"][0].numpy() - gt["grasp_point"][0].numpy()) \
                    == pytest.approx(0.01, abs=1e-6)
                error = float(est["state"][0] - gt["state"][0])
                assert abs(error) == pytest.approx(0.05, abs=1e-5)
                assert float(obs[0, LAYOUT["state"]][0]) == pytest.approx(float(est["state"][0]))
                if look == 0:
                    signs.append(np.sign(error))
                    tilts.append(d - u)
                else:  # held: the same error until the next reset
                    assert np.sign(error) == signs[-1]
                    np.testing.assert_allclose(d - u, tilts[-1], atol=1e-4)
                for _ in range(2):
                    obs, _, _, _, info = env.step(torch.zeros(1, 7))
        assert not np.allclose(tilts[0], tilts[1], atol=1e-3)  # a new episode draws a new tilt
        env.close()
        env = BatchedOracleObservation(
            gym.make("CaptOpenLaptop-ms-v0", num_envs=1, obs_mode="state"),
            {"source": "noisy_oracle", "noise": {"model": "fixed_offset", "direction_rad": 0.0,
                                                 "pivot_m": 0.03, "state": 0.0, "grasp_m": 0.0}})
        _, info = env.reset(seed=3)
        gt, est = ground_truth(info), env.estimate
        assert line_distance(est["direction"][0].numpy(), est["pivot"][0].numpy(), gt["direction"][0].numpy(),
                             gt["pivot"][0].numpy()) == pytest.approx(0.03, abs=1e-5)
    finally:
        env.close()


TINY = {"category": "laptop", "perception": {"source": "noisy_oracle", "every_k_steps": 2},
        "n_envs": 1, "total_timesteps": 64, "seed": 3, "checkpoint_every_steps": 32,
        "max_episode_steps": 20, "vec_env": "maniskill",
        "ppo": {"n_steps": 32, "batch_size": 16, "n_epochs": 2, "net_arch": [16]}}


@pytest.mark.render
def test_ppo_trains_on_the_batched_env_and_its_policy_acts_on_the_single_env(tmp_path: Path):
    config = from_dict(PPOTrainConfig, TINY)
    summary = train_ppo(config, tmp_path / "run", log_to_stdout=False)
    assert summary["num_timesteps"] == 64
    assert summary["episodes_in_stats"] == 3  # cut at 20 steps: 20, 40, 60
    assert summary["mean_episode_length"] == 20 and summary["success_rate"] is not None
    policy = PPOPolicy.load(tmp_path / "run" / "final.zip")
    env = make_env("laptop", {"source": "oracle", "every_k_steps": 2})
    try:
        obs, info = env.reset(seed=0)
        action = policy.act(obs, info)
        assert action.shape == (7,) and np.all(np.abs(action) <= 1.0)
    finally:
        env.close()


@pytest.mark.parametrize(("changes", "match"), [
    ({"residual": {"enabled": True}}, "residual"),
    ({"perception": {"source": "capt", "checkpoint": "x.pt"}, "obs_mode": "pointcloud"}, "oracle"),
    ({"obs_mode": "pointcloud"}, "obs_mode"),
    ({"n_envs": 4, "sim_backend": "physx_cpu", "ppo": {"n_steps": 32, "batch_size": 16}}, "one sub-scene"),
    ({"sim_backend": "warp"}, "sim_backend"),
    ({"reconfigure_every_steps": -1}, "reconfigure_every_steps"),
])
def test_bad_maniskill_configs_are_rejected(changes: dict, match: str):
    with pytest.raises(ConfigError, match=match):
        from_dict(PPOTrainConfig, {**TINY, **changes}).validate()


@pytest.mark.skipif(torch.cuda.is_available(), reason="checks the message on a machine without CUDA")
def test_many_sub_scenes_without_cuda_say_what_to_do():
    config = from_dict(PPOTrainConfig, {**TINY, "n_envs": 4})
    config.validate()
    assert config.resolved_sim_backend() == "physx_cuda"
    with pytest.raises(ConfigError, match="no CUDA device"):
        make_vec_env(config)


@pytest.mark.gpu
@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")
def test_ppo_on_gpu_simulation(tmp_path: Path):
    config = from_dict(PPOTrainConfig, {**TINY, "n_envs": 16, "total_timesteps": 1024,
                                        "reconfigure_every_steps": 40})
    summary = train_ppo(config, tmp_path / "gpu")
    assert summary["num_timesteps"] >= 1024 and summary["episodes_in_stats"] > 0
