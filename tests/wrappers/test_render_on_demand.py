"""The wrapper renders only on perception steps; episodes and observations are the same as when the
cameras render on every step."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from agents.scripted.opener import ScriptedOpener
from capt_env.env_factory import make_env

CHECKPOINT = Path(__file__).resolve().parents[2] / "perception" / "checkpoints" / "drawer_cabinet.pt"


def _episode(render_every_step: bool, steps: int = 12) -> tuple[list[np.ndarray], list[float], int]:
    env = make_env("drawer_cabinet", {"source": "capt", "checkpoint": str(CHECKPOINT), "every_k_steps": 4},
                   obs_mode="pointcloud", task={"cameras": [{"width": 64, "height": 64}]})
    base = env.unwrapped
    renders = 0
    original = base._rendered_obs

    def counted(info, unflattened):
        nonlocal renders
        renders += 1
        return original(info, unflattened)

    base._rendered_obs = counted
    if render_every_step:
        base.get_obs = lambda info=None, unflattened=False: counted(info, unflattened)
    opener = ScriptedOpener()
    try:
        obs, info = env.reset(seed=7)
        opener.reset()
        observations, opened = [obs], []
        for _ in range(steps):
            obs, _, _, _, info = env.step(opener.act(obs, info))
            observations.append(obs)
            opened.append(float(info["open_fraction"]))
    finally:
        env.close()
    return observations, opened, renders


def test_rendering_only_on_perception_steps_changes_nothing_the_policy_sees() -> None:
    lazy_obs, lazy_open, lazy_renders = _episode(render_every_step=False)
    full_obs, full_open, full_renders = _episode(render_every_step=True)
    assert all(np.array_equal(a, b) for a, b in zip(lazy_obs, full_obs, strict=True))
    assert lazy_open == full_open
    assert full_renders == 1 + 12  # the episode's reset, then every step
    assert lazy_renders == 1 + 3  # the reset, then steps 4, 8 and 12 only
