"""Play one episode of a policy in a wrapped capt_env env (``run_episode``) and report it
(``EpisodeResult``). The env comes from :func:`capt_env.make_env`; ``capt rollout`` runs many episodes
and reports success rates."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from agents.scripted.failure_cause import failure_cause
from agents.scripted.opener import Phase
from capt_env.wrappers.perception_wrapper import CaptObservationWrapper


@dataclass(frozen=True)
class EpisodeResult:
    """One episode: the seed, instance, success (task's criterion at the end), final open fraction,
    steps taken, the opener's last phase, its phase log (``ScriptedOpener.phase_log``: one
    ``{"step", "phase", "why"}`` per phase entered, a pull's with its ``"grip"``) and the failure cause
    named from it (:func:`~agents.scripted.failure_cause.failure_cause`; None for a success or a
    policy without a phase log)."""

    seed: int
    instance_id: int
    success: bool
    open_fraction: float
    steps: int
    phase: str
    phase_log: list[dict[str, Any]] = field(default_factory=list)
    cause: str | None = None


def run_episode(env: CaptObservationWrapper, opener: Any, seed: int, max_steps: int = 200,
                settle_steps: int = 10) -> EpisodeResult:
    """One episode of any policy with ``reset()`` and ``act(obs, info)`` (the scripted opener or a PPO
    policy); with the scripted opener it ends ``settle_steps`` after the opener is done (so the part
    comes to rest)."""
    obs, info = env.reset(seed=seed)
    opener.reset()
    steps, done_for = 0, 0
    for steps in range(1, max_steps + 1):  # noqa: B007
        obs, _, terminated, truncated, info = env.step(opener.act(obs, info))
        done_for = done_for + 1 if getattr(opener, "phase", None) == Phase.DONE else 0
        if done_for >= settle_steps or truncated:
            break
    obj = env.unwrapped.object
    success = bool(info["success"])
    log = [dict(entry) for entry in getattr(opener, "phase_log", [])]
    return EpisodeResult(seed, int(obj.instance_id), success, float(info["open_fraction"]),
                         steps, getattr(getattr(opener, "phase", None), "value", "policy"), log,
                         failure_cause(log, success))
