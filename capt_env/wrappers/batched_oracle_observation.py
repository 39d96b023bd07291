"""``BatchedOracleObservation``: joint-axis observations for a batched ManiSkill env (GPU simulation).

The batched counterpart of :class:`~capt_env.wrappers.perception_wrapper.CaptObservationWrapper` for
the ground-truth sources, so PPO can train on ManiSkill's GPU simulation (``CaptOpen*-ms-v0`` with
``num_envs`` in the hundreds and ``sim_backend="physx_cuda"``): everything stays a torch tensor on the
env's device, one row per sub-scene, in the flat layout of :mod:`capt_env.wrappers.joint_observation`
((num_envs, 38) float32, world frame, metres, radians).

- ``oracle``: each sub-scene's target joint's ground truth from the task's ``info``, the pivot made
  canonical (the axis point closest to the grasp point), confidence 1. With ``num_envs > 1`` the
  sub-scenes hold different instances (:mod:`capt_env.tasks.object_batch`), so the target joint is
  read per row (``info["target_joint"]``, a slot of the padded joint arrays).
- ``noisy_oracle``: the same plus :class:`~capt_env.wrappers.config.NoiseConfig` noise of the same
  distributions as :class:`~capt_env.wrappers.perception_sources.NoisyOracleSource` (``gaussian``
  redrawn at every look; ``fixed_offset`` of exact sizes drawn at a sub-scene's reset and held for
  its episode), from a torch generator seeded by ``config.seed`` and the reset seed. The draws are
  not the numpy source's draws.

Each sub-scene looks at its reset and then every ``every_k_steps`` of its own steps; in between it
keeps its last estimate. A partial reset (``options={"env_idx": ...}``, as auto-resetting vector
envs do) restarts only those sub-scenes' counters and noise. ``info`` gains ``perception_ran``
((num_envs,) bool). The ``capt`` source is not batched: it runs in the single-env wrapper.

The helpers here (``canonical_pivot``, ``away_from_joint``, ``perpendicular``) are batched torch
twins of the numpy ones in :mod:`capt_env.wrappers.estimate` and ``perception_sources``; the test
that this observation equals the single-env wrapper's keeps them in step.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import torch

from capt_common.typed_yaml import ConfigError, from_dict
from capt_env.wrappers.config import NoiseConfig, PerceptionWrapperConfig
from capt_env.wrappers.joint_observation import OBSERVATION_SIZE, flat_space

_EPS = 1e-9


def _unit(v: torch.Tensor) -> torch.Tensor:
    return v / v.norm(dim=-1, keepdim=True).clamp_min(_EPS)


def _dot(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    return (a * b).sum(dim=-1, keepdim=True)


def perpendicular(u: torch.Tensor, r: torch.Tensor) -> torch.Tensor:
    """Unit component of ``r`` (b, 3) perpendicular to the unit ``u`` (b, 3)."""
    return _unit(r - _dot(r, u) * u)


def canonical_pivot(direction: torch.Tensor, pivot: torch.Tensor, grasp: torch.Tensor) -> torch.Tensor:
    """The point of each line (``pivot``, ``direction``) closest to ``grasp``; all (b, 3), metres."""
    u = _unit(direction)
    return pivot + _dot(grasp - pivot, u) * u


def ground_truth(info: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """The target joint of every sub-scene from a batched capt_env ``info``: ``prismatic`` (b,) bool,
    ``direction`` (b, 3) unit (+state opens), ``pivot`` (b, 3) canonical, ``state`` (b,) rad or m,
    ``grasp_point`` (b, 3) metres; world frame."""
    k = info["target_joint"].long().reshape(-1)
    rows = torch.arange(k.shape[0], device=k.device)
    direction = _unit(info["joint_axis"][rows, k].float())
    grasp = info["grasp_point"].float().reshape(-1, 3)
    return {"prismatic": info["joint_type"][rows, k] == 1, "direction": direction,
            "pivot": canonical_pivot(direction, info["joint_pivot"][rows, k].float(), grasp),
            "state": info["joint_state"][rows, k].float(), "grasp_point": grasp}


def away_from_joint(gt: dict[str, torch.Tensor]) -> torch.Tensor:
    """(b, 3) unit direction away from the joint at the grasp point: along the axis (prismatic) or
    the radius from it (revolute; zeros where the grasp point lies on the axis)."""
    u = gt["direction"]
    radial = gt["grasp_point"] - gt["pivot"]
    radial = radial - _dot(radial, u) * u
    norm = radial.norm(dim=-1, keepdim=True)
    radial = torch.where(norm > _EPS, radial / norm.clamp_min(_EPS), torch.zeros_like(radial))
    return torch.where(gt["prismatic"].unsqueeze(-1), u, radial)


def masked_update(old: dict[str, torch.Tensor] | None, new: dict[str, torch.Tensor], mask: torch.Tensor
                  ) -> dict[str, torch.Tensor]:
    """``new``'s rows where ``mask`` (b,) is set, ``old``'s elsewhere, for every (b,) or (b, n) entry;
    ``new`` itself when there is no ``old``."""
    if old is None:
        return dict(new)
    return {key: torch.where(mask if value.dim() == 1 else mask.unsqueeze(-1), value, old[key])
            for key, value in new.items()}


class BatchedOracleObservation(gym.Wrapper):
    """Flat joint-axis observations (num_envs, 38) from a batched ``CaptOpen*-ms-v0`` env.

    :param env: a ManiSkill env of this package (``gym.make("CaptOpenDrawerCabinet-ms-v0", num_envs=N,
        obs_mode="state")``), any ``sim_backend``.
    :param config: a :class:`PerceptionWrapperConfig` or a dict of its fields, ``source`` ``oracle``
        or ``noisy_oracle`` and ``obs_format`` ``flat``; the isolation and CAPT fields are unused.
    """

    def __init__(self, env: gym.Env, config: PerceptionWrapperConfig | dict | None = None) -> None:
        super().__init__(env)
        cfg = config if isinstance(config, PerceptionWrapperConfig) else from_dict(
            PerceptionWrapperConfig, config or {}, where="perception_wrapper")
        cfg.validate()
        if cfg.source not in ("oracle", "noisy_oracle"):
            raise ConfigError(f"perception_wrapper.source: the batched wrapper takes 'oracle' or "
                              f"'noisy_oracle', got {cfg.source!r} (CAPT runs in CaptObservationWrapper)")
        if cfg.obs_format != "flat":
            raise ConfigError(f"perception_wrapper.obs_format: the batched wrapper gives 'flat', "
                              f"got {cfg.obs_format!r}")
        self.config = cfg
        base = env.unwrapped
        self.num_envs: int = int(base.num_envs)
        self.device = torch.device(base.device)
        self.single_observation_space = flat_space()
        self.observation_space = gym.vector.utils.batch_space(self.single_observation_space, self.num_envs)
        self.single_action_space = base.single_action_space
        self._gen = torch.Generator(device=self.device)
        self._gen.manual_seed(cfg.seed)
        self._steps = torch.zeros(self.num_envs, dtype=torch.long, device=self.device)
        self._estimate: dict[str, torch.Tensor] | None = None
        self._held: dict[str, torch.Tensor] | None = None

    @property
    def estimate(self) -> dict[str, torch.Tensor] | None:
        """The latest estimate of every sub-scene (``ground_truth``'s keys), None before reset."""
        return self._estimate

    def reset(self, *, seed: int | list[int] | None = None, options: dict | None = None
              ) -> tuple[torch.Tensor, dict]:
        _, info = self.env.reset(seed=seed, options=options)
        if seed is not None:
            first = int(seed[0]) if isinstance(seed, (list, tuple)) else int(seed)
            self._gen.manual_seed(self.config.seed * 1_000_003 + first)
        mask = self._mask(options)
        self._steps[mask] = 0
        if self.config.source == "noisy_oracle" and self.config.noise.model == "fixed_offset":
            self._draw_held(mask)
        self._look(info, mask)
        return self._observation(), self._info(info, mask)

    def step(self, action: Any) -> tuple[torch.Tensor, Any, Any, Any, dict]:
        _, reward, terminated, truncated, info = self.env.step(action)
        self._steps += 1
        ran = self._steps % self.config.every_k_steps == 0
        if bool(ran.any()):
            self._look(info, ran)
        return self._observation(), reward, terminated, truncated, self._info(info, ran)

    # ----------------------------------------------------------------- parts
    def _mask(self, options: dict | None) -> torch.Tensor:
        """(num_envs,) bool: the sub-scenes a reset with ``options`` resets (all without env_idx)."""
        mask = torch.zeros(self.num_envs, dtype=torch.bool, device=self.device)
        idx = (options or {}).get("env_idx")
        if idx is None:
            mask[:] = True
        else:
            mask[torch.as_tensor(idx, device=self.device).long()] = True
        return mask

    def _normal(self, *shape: int) -> torch.Tensor:
        return torch.randn(*shape, generator=self._gen, device=self.device)

    def _draw_held(self, mask: torch.Tensor) -> None:
        """``fixed_offset``: new random error directions and signs for the sub-scenes in ``mask``."""
        b = self.num_envs
        draw = {"tilt": self._normal(b, 3), "pivot": self._normal(b, 3), "grasp": _unit(self._normal(b, 3)),
                "sign": torch.where(torch.rand(b, generator=self._gen, device=self.device) < 0.5, -1.0, 1.0)}
        self._held = masked_update(self._held, draw, mask)

    def _noisy(self, gt: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
        n: NoiseConfig = self.config.noise
        b, u = self.num_envs, gt["direction"]
        grasp = gt["grasp_point"] + n.grasp_outward_m * away_from_joint(gt)
        if n.model == "fixed_offset":
            assert self._held is not None
            h = self._held
            angle = torch.full((b, 1), float(n.direction_rad), device=self.device)
            perp = perpendicular(u, h["tilt"])
            grasp = grasp + n.grasp_m * h["grasp"]
            shifted = gt["pivot"] + n.pivot_m * perpendicular(u, h["pivot"])
            state = gt["state"] + h["sign"] * n.state
        else:
            angle = (self._normal(b, 1) * n.direction_rad).abs()
            perp = perpendicular(u, self._normal(b, 3))
            grasp = grasp + self._normal(b, 3) * n.grasp_m
            shifted = gt["pivot"] + self._normal(b, 3) * n.pivot_m
            state = gt["state"] + self._normal(b) * n.state
        direction = torch.cos(angle) * u + torch.sin(angle) * perp
        return {"prismatic": gt["prismatic"], "direction": direction,
                "pivot": canonical_pivot(direction, shifted, grasp), "state": state, "grasp_point": grasp}

    def _look(self, info: dict[str, torch.Tensor], mask: torch.Tensor) -> None:
        """Estimate every sub-scene and keep the new estimate where ``mask`` is set."""
        gt = ground_truth(info)
        new = self._noisy(gt) if self.config.source == "noisy_oracle" else gt
        self._estimate = masked_update(self._estimate, new, mask)

    def _observation(self) -> torch.Tensor:
        assert self._estimate is not None
        e, agent = self._estimate, self.env.unwrapped.agent
        prismatic = e["prismatic"].float().unsqueeze(-1)
        obs = torch.cat([
            agent.robot.get_qpos().float(), agent.robot.get_qvel().float(), agent.tcp.pose.raw_pose.float(),
            1.0 - prismatic, prismatic, e["direction"].clamp(-1.0, 1.0), e["pivot"], e["state"].unsqueeze(-1),
            e["grasp_point"], torch.ones_like(prismatic),
        ], dim=-1)
        assert obs.shape == (self.num_envs, OBSERVATION_SIZE), obs.shape
        return obs

    def _info(self, info: dict, ran: torch.Tensor) -> dict:
        out = dict(info)
        out["perception_ran"] = ran.clone()
        return out
