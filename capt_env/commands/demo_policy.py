"""The demo's second half: the scripted opener acting on CAPT estimates, recorded as an MP4."""

from __future__ import annotations

from pathlib import Path


def open_with_capt(category: str | None, checkpoint: str | Path, seed: int, out_dir: Path, tag: str,
                   video: bool = True, every_k_steps: int = 5, max_steps: int = 200,
                   task: dict | None = None) -> dict:
    """Run one episode (same seed, so the same unseen instance as the estimate) and return the outcome:
    success, final open fraction, steps, and the MP4 path when ``video``. ``task`` holds TaskConfig
    overrides (e.g. the cameras); with ``category`` None, ``task["object"]`` is the user file."""
    import imageio.v2 as imageio
    import numpy as np

    from agents.scripted.opener import Phase, ScriptedOpener
    from capt_env.env_factory import make_env

    wrapper = {"source": "capt", "checkpoint": str(checkpoint), "every_k_steps": every_k_steps}
    env = make_env(category, wrapper, task=task, obs_mode="pointcloud",
                   render_mode="rgb_array" if video else None)
    policy = ScriptedOpener()
    frames = []
    try:
        obs, info = env.reset(seed=seed)
        policy.reset()
        done_for, steps = 0, 0
        for steps in range(1, max_steps + 1):  # noqa: B007 - steps is reported after the loop
            obs, _, _, truncated, info = env.step(policy.act(obs, info))
            if video and steps % 2 == 0:
                frame = np.asarray(env.render())
                frames.append(frame[0] if frame.ndim == 4 else frame)
            done_for = done_for + 1 if policy.phase == Phase.DONE else 0
            if done_for >= 10 or truncated:
                break
    finally:
        env.close()
    row = {"success": bool(info["success"]), "open_fraction": float(info["open_fraction"]), "steps": steps}
    if video and frames:
        path = out_dir / f"{tag}.mp4"
        path.parent.mkdir(parents=True, exist_ok=True)
        imageio.mimwrite(path, frames, fps=10, macro_block_size=1)
        row["mp4"] = str(path)
    return row
