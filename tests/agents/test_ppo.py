"""PPO on joint-axis observations: a short run trains, saves, reloads, resumes, and is seeded."""

from __future__ import annotations

import csv
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import torch
import yaml

import capt_env  # noqa: F401
from agents.ppo.config import PPOTrainConfig
from agents.ppo.policy import PPOPolicy
from agents.ppo.train import ContinueAfterSuccess, latest_checkpoint, train_ppo
from agents.scripted.config import ScriptedOpenerConfig, legacy_value
from capt_common.typed_yaml import ConfigError, from_dict, load_yaml
from capt_env.env_factory import make_env

ROOT = Path(__file__).resolve().parents[2]
TINY = {"category": "laptop", "perception": {"source": "noisy_oracle", "every_k_steps": 2},
        "n_envs": 1, "total_timesteps": 64, "seed": 3, "checkpoint_every_steps": 32,
        "max_episode_steps": 20, "ppo": {"n_steps": 32, "batch_size": 16, "n_epochs": 2, "net_arch": [16]}}


def tiny(**changes: object) -> PPOTrainConfig:
    return from_dict(PPOTrainConfig, {**TINY, **changes})


# the opener options each shipped residual policy was trained (and measured) with, pinned in its
# run config so that later changes to the opener's defaults do not change the policy
SHIPPED_OPENERS = {
    "laptop": {"arc_fit": True, "regrasp_other_fingers": True, "quarter_turn": False, "approach_gap": 0.06,
               "wrist_limit_margin": 0.05, "lid_lift_inward": 0.02, "lid_lift_lead": 0.2,
               "fall_open_done": 1.3, "revolute_stop_above": 0.0, "rehearse_fingers": False,
               "rechoose_grasp_m": 0.0, "watch_falling": False, "prismatic_approach_pitch": 0.55,
               "prismatic_stop_above": 0.0, "rechoose_part_kind": False},
    # retrained in session 53 on that session's opener, which its run config records in full
    "drawer_cabinet": {"arc_fit": True, "regrasp_other_fingers": True, "quarter_turn": True,
                       "approach_gap": 0.06,
                       "wrist_limit_margin": 0.05, "lid_lift_lead": 0.2, "fall_open_done": 1.3,
                       "revolute_stop_above": 1.4, "rehearse_fingers": True,
                       "rechoose_grasp_m": 0.05, "watch_falling": True,
                       "prismatic_approach_pitch": 0.3, "prismatic_stop_above": 0.15,
                       "rechoose_part_kind": False, "lid.lift.press": 0.01, "lid.lift.slip_behind": 0.3},
}


@pytest.mark.parametrize("category", sorted(SHIPPED_OPENERS))
def test_shipped_residual_policies_run_the_opener_they_were_trained_with(category: str) -> None:
    """Loading a shipped residual policy gives its scripted opener the options it was trained with,
    whatever the opener's defaults are today."""
    from agents.ppo.policy import PPOPolicy

    policy = PPOPolicy.load(ROOT / "agents" / "ppo" / "policies" / category / "final.zip")
    assert policy.residual is not None
    cfg = policy.residual.opener.cfg
    for key, value in SHIPPED_OPENERS[category].items():
        assert legacy_value(cfg, key) == pytest.approx(value), key
    assert cfg.pull.revolute.target == ScriptedOpenerConfig().pull.revolute.target  # not pinned: the default


def test_shipped_configs_load() -> None:
    paths = sorted((ROOT / "configs" / "ppo").glob("*.yaml"))
    assert {p.stem for p in paths} >= {"laptop", "drawer_cabinet", "drawer_cabinet_residual"}
    for path in paths:
        cfg = load_yaml(PPOTrainConfig, path)
        assert path.stem.startswith(cfg.category)
        assert cfg.perception.source == "noisy_oracle"
        assert cfg.residual.enabled == path.stem.endswith("_residual")


@pytest.mark.parametrize(("changes", "match"), [
    ({"learning_rat": 1e-3}, "learning_rat"),
    ({"ppo": {"n_step": 8}}, "n_step"),
    ({"n_envs": 0}, "n_envs"),
    ({"ppo": {"n_steps": 32, "batch_size": 64}}, "batch_size"),
    ({"ppo": {"gamma": 1.5}}, "gamma"),
    ({"category": "toaster"}, "category"),
    ({"max_episode_steps": 500}, "max_episode_steps"),
    ({"task": {"split": "test"}}, "split"),
    ({"task": {"yaw_nois": 0.1}}, "yaw_nois"),
    ({"perception": {"source": "capt", "checkpoint": "x.pt"}}, "pointcloud"),
    ({"perception": {"source": "capt_raw", "checkpoint": "x.pt"}}, "pointcloud"),
    ({"device": "tpu"}, "device"),
    ({"residual": {"enabled": True, "scale": 0.0}}, "residual.scale"),
    ({"residual": {"enable": True}}, "enable"),
    ({"ppo": {"log_std_init": 3.0}}, "log_std_init"),
    ({"residual": {"enabled": True, "opener": {"arc_fit_min_angle": 0.0}}}, "arc_fit.min_angle"),
    ({"residual": {"enabled": True, "opener": {"arcfit": False}}}, "arcfit"),
])
def test_bad_config_values_are_rejected(changes: dict, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        tiny(**changes)


def _progress_rows(log_dir: str) -> list[dict[str, str]]:
    with open(Path(log_dir) / "progress.csv") as fh:
        return list(csv.DictReader(fh))


def test_train_save_reload_resume(tmp_path: Path) -> None:
    env = make_env("laptop", {"source": "oracle"}, max_episode_steps=20)  # test split
    try:
        obs, info = env.reset(seed=11)
    finally:
        env.close()
    in_memory: dict[str, np.ndarray] = {}

    def keep_action(model, venv) -> None:  # noqa: ANN001 - SB3 objects
        in_memory["action"], _ = model.predict(venv.normalize_obs(obs), deterministic=True)
        in_memory["params"] = torch.nn.utils.parameters_to_vector(model.policy.parameters()).detach()

    run = tmp_path / "run"
    first = train_ppo(tiny(), run, on_trained=keep_action)
    assert first["num_timesteps"] == 64 and first["steps_this_run"] == 64 and first["resumed_from"] is None
    assert first["episodes_in_stats"] == 3  # 64 steps of 20-step episodes
    assert 0.0 <= first["success_rate"] <= 1.0 and np.isfinite(first["mean_episode_reward"])
    assert (run / "final.zip").is_file() and (run / "vecnormalize.pkl").is_file()
    assert latest_checkpoint(run)[1] == 64
    assert (run / "checkpoints" / "ppo_32_steps.zip").is_file()
    assert (run / "checkpoints" / "ppo_vecnormalize_32_steps.pkl").is_file()
    rows = _progress_rows(first["log_dir"])
    assert len(rows) == 2  # one row per rollout
    assert 0.0 <= float(rows[-1]["rollout/success_rate"]) <= 1.0

    # reload: the same deterministic action as the in-memory model, without an env
    policy = PPOPolicy.load(run / "final.zip")
    policy.reset()
    action = policy.act(obs, info)
    assert action.shape == (7,) and action.dtype == np.float32
    np.testing.assert_allclose(action, in_memory["action"], rtol=0, atol=1e-6)
    assert np.all(np.abs(action) <= 1.0)
    params_64 = in_memory["params"]

    # resume to a larger total: continues from step 64, stops at the requested total
    second = train_ppo(tiny(total_timesteps=128), run, on_trained=keep_action)
    assert second["resumed_from"].endswith("ppo_64_steps.zip")
    assert second["start_timesteps"] == 64 and second["num_timesteps"] == 128
    assert second["steps_this_run"] == 64
    assert latest_checkpoint(run)[1] == 128
    assert not torch.equal(in_memory["params"], params_64)  # it trained on
    # already at the total: nothing more to learn
    assert train_ppo(tiny(total_timesteps=128), run)["steps_this_run"] == 0
    # a run saved before a config field existed resumes with that field's default
    saved = yaml.safe_load((run / "config.yaml").read_text())
    del saved["continue_after_success"], saved["perception"]["refiners"]
    (run / "config.yaml").write_text(yaml.safe_dump(saved))
    assert train_ppo(tiny(total_timesteps=128), run)["steps_this_run"] == 0
    # a resume may not change what is trained
    with pytest.raises(ConfigError, match="seed"):
        train_ppo(tiny(total_timesteps=192, seed=4), run)

    # seeded: a fresh run with the same config reproduces the first 64 steps exactly
    train_ppo(tiny(), tmp_path / "again", on_trained=keep_action)
    assert torch.equal(in_memory["params"], params_64)


class _EndsEpisode(gym.Env):
    """Terminates every step, with or without success."""

    observation_space = gym.spaces.Box(-1, 1, (1,))
    action_space = gym.spaces.Box(-1, 1, (1,))

    def __init__(self, success: bool) -> None:
        self.success = success

    def reset(self, *, seed=None, options=None):  # noqa: ANN001, ANN201
        return np.zeros(1, np.float32), {}

    def step(self, action):  # noqa: ANN001, ANN201
        return np.zeros(1, np.float32), 1.0, True, False, {"success": self.success}


def test_training_episodes_continue_after_success_only() -> None:
    assert ContinueAfterSuccess(_EndsEpisode(success=True)).step(np.zeros(1))[2] is False
    assert ContinueAfterSuccess(_EndsEpisode(success=False)).step(np.zeros(1))[2] is True
    assert tiny().continue_after_success and not tiny(continue_after_success=False).continue_after_success


def _pickled_modules(blob: bytes) -> set[str]:
    """The modules a pickle imports (its GLOBAL / STACK_GLOBAL opcodes' module names)."""
    import pickletools

    modules, strings = set(), []
    for op, arg, _ in pickletools.genops(blob):
        if op.name in ("SHORT_BINUNICODE", "BINUNICODE", "UNICODE"):
            strings.append(arg)
        elif op.name == "GLOBAL":
            modules.add(str(arg).split(" ")[0])
        elif op.name == "STACK_GLOBAL" and len(strings) >= 2:
            modules.add(strings[-2])
    return modules


@pytest.mark.parametrize("category", sorted(SHIPPED_OPENERS))
def test_shipped_policies_unpickle_under_numpy_1_and_2(category: str) -> None:
    """The shipped policies' pickles (VecNormalize statistics, the SB3 zip's serialised objects) name
    no module that only numpy 2 has (``numpy._core``): saved under numpy 1, both numpy 1 and 2 load
    them, so an environment with numpy < 2 (mplib, ManiSkill's motion planner) runs them too."""
    import base64
    import json
    import zipfile

    folder = ROOT / "agents" / "ppo" / "policies" / category
    blobs = [(folder / "vecnormalize.pkl").read_bytes()]
    with zipfile.ZipFile(folder / "final.zip") as archive:
        data = json.loads(archive.read("data"))
    blobs += [base64.b64decode(item[":serialized:"]) for item in data.values()
              if isinstance(item, dict) and ":serialized:" in item]
    modules = set().union(*(_pickled_modules(b) for b in blobs))
    assert any(m.startswith("numpy") for m in modules)  # the check sees numpy's objects at all
    assert not [m for m in modules if m.startswith("numpy._core")], modules
