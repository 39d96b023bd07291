"""The demo's second half: the scripted opener acting on CAPT estimates, recorded as an MP4 by
ManiSkill's ``RecordEpisode`` (applied to the ManiSkill env through the ``wrappers=[...]`` option)."""

from __future__ import annotations

from pathlib import Path

VIDEO_FPS = 10
"""A frame every other control step (20 Hz), so the video plays in real time at half the renders."""


def open_with_capt(category: str | None, checkpoint: str | Path, seed: int, out_dir: Path, tag: str,
                   video: bool = True, every_k_steps: int = 5, max_steps: int = 200,
                   task: dict | None = None) -> dict:
    """Run one episode (same seed, so the same unseen instance as the estimate) and return the outcome:
    success, final open fraction, steps, and the MP4 path (``out_dir/tag.mp4``) when ``video``.
    ``task`` holds TaskConfig overrides (e.g. the cameras); with ``category`` None, ``task["object"]``
    is the user file."""
    from agents.scripted.opener import Phase, ScriptedOpener
    from capt_env.env_factory import make_env

    recorders = []

    def record(env):
        from mani_skill.utils.wrappers import RecordEpisode

        recorders.append(RecordEpisode(env, str(out_dir), save_trajectory=False, save_video=True,
                                       save_on_reset=False, video_fps=VIDEO_FPS,
                                       save_video_trigger=lambda elapsed_steps: elapsed_steps % 2 == 0))
        return recorders[-1]

    wrapper = {"source": "capt", "checkpoint": str(checkpoint), "every_k_steps": every_k_steps}
    extra = {"render_mode": "rgb_array", "wrappers": [record]} if video else {}
    env = make_env(category, wrapper, task=task, obs_mode="pointcloud", **extra)
    policy = ScriptedOpener()
    try:
        obs, info = env.reset(seed=seed)
        policy.reset()
        done_for, steps = 0, 0
        for steps in range(1, max_steps + 1):  # noqa: B007 - steps is reported after the loop
            obs, _, _, truncated, info = env.step(policy.act(obs, info))
            done_for = done_for + 1 if policy.phase == Phase.DONE else 0
            if done_for >= 10 or truncated:
                break
        if video:
            recorders[0].flush_video(name=tag)
    finally:
        env.close()
    row = {"success": bool(info["success"]), "open_fraction": float(info["open_fraction"]), "steps": steps}
    if video:
        row["mp4"] = str(out_dir / f"{tag}.mp4")
    return row
