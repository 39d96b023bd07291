"""Where joint estimates come from: ground truth (oracle), ground truth plus noise, or CAPT.

Every source maps (object points, env info) to a world-frame :class:`JointAxisEstimate` of the target
joint. Only :class:`CaptSource` (``capt_raw`` and ``capt``) needs the points; it runs the stages of
:mod:`~capt_env.wrappers.estimate_pipeline` and imports ``perception.inference`` lazily, on the
first estimate, so the oracle sources work without torch models or checkpoints.
"""

from __future__ import annotations

from dataclasses import asdict
from typing import Any, Protocol

import numpy as np

from capt_env.wrappers.config import NoiseConfig, PerceptionWrapperConfig
from capt_env.wrappers.estimate import (
    JOINT_TYPES,
    JointAxisEstimate,
    away_from_joint,
    canonical_pivot,
    unit,
)
from capt_env.wrappers.estimate_fusion import EstimateFusion
from capt_env.wrappers.estimate_pipeline import EstimatePipeline, Look, look
from capt_env.wrappers.refiners import build_refiners


class PerceptionSource(Protocol):
    """Anything that estimates the target joint. ``needs_points``: whether it reads the cloud."""

    needs_points: bool

    def estimate(self, points: np.ndarray | None, info: dict[str, Any],
                 dense_points: np.ndarray | None = None,
                 viewpoint: np.ndarray | None = None) -> JointAxisEstimate:
        """Estimate from object points (M, 3) world frame metres (or None) and the env's info.
        ``dense_points`` (K, 3), K >= M: all isolated object points before downsampling, for
        geometry that needs more than the model's input; ``viewpoint`` (3,): where the cameras look
        from (their mean position), world frame (a source may ignore both)."""
        ...


def _target(info: dict[str, Any]) -> int:
    return int(np.asarray(info["target_joint"]).reshape(-1)[0])


def _target_hint(info: dict[str, Any]) -> np.ndarray | None:
    """The task's ``target_link_pos`` (3,) (the target part's centre of mass, world frame), or None
    when the env gives none."""
    if "target_link_pos" not in info:
        return None
    return np.asarray(info["target_link_pos"], dtype=np.float64).reshape(-1, 3)[0]


def ground_truth_estimate(info: dict[str, Any]) -> JointAxisEstimate:
    """The target joint's ground truth from a capt_env info dict (world frame), pivot made canonical."""
    k = _target(info)
    axis = unit(np.asarray(info["joint_axis"], dtype=np.float64)[k])
    grasp = np.asarray(info["grasp_point"], dtype=np.float64).reshape(3)
    pivot = canonical_pivot(axis, np.asarray(info["joint_pivot"], dtype=np.float64)[k], grasp)
    return JointAxisEstimate(
        joint_type=JOINT_TYPES[int(np.asarray(info["joint_type"])[k])], direction=axis, pivot=pivot,
        state=float(np.asarray(info["joint_state"])[k]), grasp_point=grasp, confidence=1.0,
    )


class OracleSource:
    """Ground truth from ``info`` (the simulator's joints and grasp point)."""

    needs_points = False

    def estimate(self, points: np.ndarray | None, info: dict[str, Any],
                 dense_points: np.ndarray | None = None,
                 viewpoint: np.ndarray | None = None) -> JointAxisEstimate:
        return ground_truth_estimate(info)


def _perpendicular(u: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The unit component of ``r`` (3,) perpendicular to the unit ``u`` (3,)."""
    return unit(r - (r @ u) * u)


def tilt(direction: np.ndarray, angle: float, rng: np.random.Generator) -> np.ndarray:
    """``direction`` (3,) rotated by ``angle`` radians about a uniformly random perpendicular axis."""
    u = unit(direction)
    perp = _perpendicular(u, rng.normal(size=3))
    return np.cos(angle) * u + np.sin(angle) * perp


class NoisyOracleSource:
    """Ground truth plus noise of the magnitudes in :class:`NoiseConfig`, seeded (see its models).

    ``gaussian``: the direction is tilted by ``|N(0, direction_rad)|`` radians, the pivot, state and
    grasp point get Gaussian offsets, all redrawn at every estimate. ``fixed_offset``: errors of
    exactly the configured sizes, their directions and signs drawn at the first estimate after
    :meth:`reset` and held until the next. In both, the grasp point moves ``grasp_outward_m`` along
    :func:`~capt_env.wrappers.estimate.away_from_joint`, and the noisy pivot is then made canonical
    again (closest to the noisy grasp point), so only the off-axis part of the pivot noise remains.
    """

    needs_points = False

    def __init__(self, noise: NoiseConfig, seed: int = 0) -> None:
        self.noise = noise
        self.rng = np.random.default_rng(seed)
        self._held: dict[str, Any] | None = None  # fixed_offset: this episode's random directions

    def reset(self) -> None:
        """A new episode: ``fixed_offset`` draws new error directions at the next estimate."""
        self._held = None

    def estimate(self, points: np.ndarray | None, info: dict[str, Any],
                 dense_points: np.ndarray | None = None,
                 viewpoint: np.ndarray | None = None) -> JointAxisEstimate:
        gt = ground_truth_estimate(info)
        n, rng = self.noise, self.rng
        outward = n.grasp_outward_m * away_from_joint(gt)
        if n.model == "fixed_offset":
            if self._held is None:
                self._held = {"tilt": rng.normal(size=3), "pivot": rng.normal(size=3),
                              "grasp": unit(rng.normal(size=3)), "sign": float(rng.choice([-1.0, 1.0]))}
            h, u = self._held, unit(gt.direction)
            direction = np.cos(n.direction_rad) * u + np.sin(n.direction_rad) * _perpendicular(u, h["tilt"])
            grasp = gt.grasp_point + outward + n.grasp_m * h["grasp"]
            shifted = gt.pivot + n.pivot_m * _perpendicular(u, h["pivot"])
            state = gt.state + h["sign"] * n.state
        else:
            direction = tilt(gt.direction, abs(float(rng.normal(0.0, n.direction_rad))), rng)
            grasp = gt.grasp_point + outward + rng.normal(0.0, n.grasp_m, size=3)
            shifted = gt.pivot + rng.normal(0.0, n.pivot_m, size=3)
            state = gt.state + float(rng.normal(0.0, n.state))
        pivot = canonical_pivot(direction, shifted, grasp)
        return JointAxisEstimate(gt.joint_type, direction, pivot, state, grasp, confidence=1.0)


class CaptSource:
    """CAPT (``perception.inference.ArticulationEstimator`` of ``checkpoint``, loaded on the first
    call) on the isolated object points, through ``pipeline``
    (:class:`~capt_env.wrappers.estimate_pipeline.EstimatePipeline`: network, refiners, fusion).
    ``name``: the source's name in tables (``capt_raw`` or ``capt``). The target joint's channel is
    the env's target joint index; the env's ``target_link_pos`` (the target part's centre of mass),
    when given, chooses a double door's leaf (``refiners.handle.target_leaf_handle``). ``last_look``
    is the latest run's input and network output (None before the first), so other refiner lists can
    be scored on the same look.
    :meth:`reset` starts a new episode (forgets the fused looks).
    """

    needs_points = True

    def __init__(self, name: str, checkpoint: str, seed: int, pipeline: EstimatePipeline) -> None:
        self.name = name
        self.checkpoint = checkpoint
        self.seed = seed
        self.pipeline = pipeline
        self.last_look: Look | None = None
        self._estimator: Any = None

    def reset(self) -> None:
        """Forget the previous episode's estimates."""
        self.pipeline.reset()

    @property
    def estimator(self) -> Any:
        """The :class:`perception.inference.ArticulationEstimator` of ``checkpoint`` (loaded on first
        use)."""
        return self._load()

    def _load(self) -> Any:
        if self._estimator is None:
            from perception.inference import ArticulationEstimator  # lazy: only the capt sources

            self._estimator = ArticulationEstimator.from_checkpoint(self.checkpoint, seed=self.seed)
        return self._estimator

    def estimate(self, points: np.ndarray | None, info: dict[str, Any],
                 dense_points: np.ndarray | None = None,
                 viewpoint: np.ndarray | None = None) -> JointAxisEstimate:
        if points is None:
            raise ValueError(f"the {self.name} source needs the object's points")
        self.last_look = look(self._load(), points, _target(info), dense_points, viewpoint,
                              _target_hint(info))
        return self.pipeline.estimate(self.last_look)


def capt_pipeline(config: PerceptionWrapperConfig) -> EstimatePipeline:
    """The pipeline of ``config.source``: none of the refiners and no fusion for ``capt_raw``; the
    refiners ``config.refiners`` with ``config.refiner_settings`` and fusion for ``capt``."""
    if config.source == "capt_raw":
        return EstimatePipeline((), None)
    if config.source == "capt":
        return EstimatePipeline(build_refiners(config.refiners, config.refiner_settings),
                                EstimateFusion(**asdict(config.fusion)))
    raise ValueError(f"{config.source!r} is not a CAPT source")


def make_source(config: PerceptionWrapperConfig) -> PerceptionSource:
    """The source ``config.source`` names ("oracle", "noisy_oracle", "capt_raw", "capt")."""
    if config.source == "oracle":
        return OracleSource()
    if config.source == "noisy_oracle":
        return NoisyOracleSource(config.noise, config.seed)
    if config.source in ("capt_raw", "capt"):
        if config.checkpoint is None:
            raise ValueError(f"source '{config.source}' needs a checkpoint path")
        return CaptSource(config.source, config.checkpoint, config.seed, capt_pipeline(config))
    raise ValueError(f"unknown perception source {config.source!r}")
