"""The CAPT estimate pipeline, stage by stage: from a camera cloud to the observation a policy gets.

1. isolate  :func:`isolate_object`, :func:`network_input`: the object's points of the world-frame cloud
   (labels or geometry, :mod:`~capt_env.wrappers.object_isolation`), and the seeded draw of
   ``num_points`` of them the network is fed.
2. network  :func:`look`, :func:`network`: CAPT with double voting (``perception.inference``) on
   that draw, read as a :class:`~capt_env.wrappers.refiners.draft.Draft` of the target joint.
3. refine   :func:`refine`: the refiners, in order (:mod:`capt_env.wrappers.refiners`).
4. fuse     :func:`fuse`: with the episode's earlier looks (:mod:`~capt_env.wrappers.estimate_fusion`).
5. observe  :func:`observe`: proprioception and the estimate as the flat or dict observation
   (:mod:`~capt_env.wrappers.joint_observation`).

The ``capt_raw`` source runs stages 2 and 5 with no refiners and no fusion: the network's own
joint, its pivot moved to the line's point closest to the grasp point, the grasp point the far edge
of the part the network labels as moving. ``capt`` runs every stage with the refiners the wrapper
config names. :class:`~capt_env.wrappers.perception_wrapper.CaptObservationWrapper` runs stages 1
and 5; :class:`EstimatePipeline` (held by the CAPT sources) runs 2-4. World frame, metres, radians.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from capt_env.wrappers.config import IsolationConfig, ObsFormat
from capt_env.wrappers.estimate import JointAxisEstimate
from capt_env.wrappers.estimate_fusion import EstimateFusion
from capt_env.wrappers.joint_observation import build_dict, flatten
from capt_env.wrappers.object_isolation import isolate
from capt_env.wrappers.refiners.draft import Draft, Refiner, network_draft
from capt_env.wrappers.robot_filter import RobotPointFilter

if TYPE_CHECKING:
    from perception.inference import ArticulationEstimate


# ----------------------------------------------------------------------------------- 1. isolate
def isolate_object(cloud: dict[str, np.ndarray], isolation: IsolationConfig,
                   robot: RobotPointFilter | None) -> np.ndarray:
    """The object's points (N, 3) float64 of a ManiSkill point-cloud observation ``cloud``
    (``xyzw`` (P, 4), ``part_label`` (P,) in simulation), by ``isolation.mode``; world frame, metres."""
    mask = isolate(cloud["xyzw"], cloud.get("part_label"), isolation, robot)
    return np.asarray(cloud["xyzw"][mask, :3], dtype=np.float64)


def network_input(points: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """``num`` rows of ``points`` (M, 3): a random subset in their order, or all plus random repeats
    if M < num."""
    if len(points) >= num:
        return points[np.sort(rng.choice(len(points), num, replace=False))]
    extra = rng.choice(len(points), num - len(points), replace=True)
    return np.concatenate([points, points[extra]])


# ----------------------------------------------------------------------------------- 2. network
@dataclass(frozen=True)
class Look:
    """One run of the network: its input ``points`` (M, 3), all isolated ``dense_points`` (K, 3) (or
    None), the ``target`` joint index, the network's output ``result`` (part labels, joints after
    double voting), the ``model`` config it came from, the cameras' mean position ``viewpoint``
    (3,) and the task's ``target_hint`` (3,), the target part's centre of mass (each or None).
    World frame, metres."""

    points: np.ndarray
    dense_points: np.ndarray | None
    target: int
    result: ArticulationEstimate
    model: Any
    viewpoint: np.ndarray | None = None
    target_hint: np.ndarray | None = None


def look(estimator: Any, points: np.ndarray, target: int, dense_points: np.ndarray | None = None,
         viewpoint: np.ndarray | None = None, target_hint: np.ndarray | None = None) -> Look:
    """Run ``estimator`` (a ``perception.inference.ArticulationEstimator``) on ``points`` (M, 3)."""
    points = np.asarray(points, dtype=np.float64)
    view = None if viewpoint is None else np.asarray(viewpoint, dtype=np.float64).reshape(3)
    hint = None if target_hint is None else np.asarray(target_hint, dtype=np.float64).reshape(3)
    return Look(points, dense_points, int(target), estimator.predict(points), estimator.config.model, view,
                hint)


def network(seen: Look) -> Draft:
    """The network's own estimate of the target joint, as a draft the refiners can change."""
    return network_draft(seen.result, seen.points, seen.target, seen.model, seen.dense_points,
                         seen.viewpoint, seen.target_hint)


# ------------------------------------------------------------------------------------ 3. refine
def refine(draft: Draft, refiners: Sequence[Refiner]) -> Draft:
    """Run ``refiners`` on ``draft`` in order; each that changed it is appended to ``draft.fired``."""
    for refiner in refiners:
        if refiner.refine(draft):
            draft.fired.append(refiner.name)
    return draft


# -------------------------------------------------------------------------------------- 4. fuse
def fuse(draft: Draft, fusion: EstimateFusion | None) -> JointAxisEstimate:
    """The draft's settled estimate, fused with the episode's earlier ones (unless ``fusion`` is None)."""
    estimate = draft.estimate()
    return estimate if fusion is None else fusion.update(estimate, draft.from_handle)


# ----------------------------------------------------------------------------------- 5. observe
def observe(qpos: np.ndarray, qvel: np.ndarray, tcp_pose: np.ndarray, estimate: JointAxisEstimate,
            obs_format: ObsFormat) -> Any:
    """The observation of Panda ``qpos`` (9,), ``qvel`` (9,), TCP pose (7,: position m, quaternion
    wxyz) and ``estimate``: a float32 vector (``flat``) or a dict (layout:
    :mod:`~capt_env.wrappers.joint_observation`)."""
    obs = build_dict(qpos, qvel, tcp_pose, estimate)
    return flatten(obs) if obs_format == "flat" else obs


class EstimatePipeline:
    """Stages 2-4 for one CAPT source: the network's draft, ``refiners`` in order, then ``fusion``
    (None: none, as ``capt_raw``). ``last_draft`` is the latest look's refined draft (its ``fired``
    refiners), for inspection."""

    def __init__(self, refiners: Sequence[Refiner], fusion: EstimateFusion | None) -> None:
        self.refiners = tuple(refiners)
        self.fusion = fusion
        self.last_draft: Draft | None = None

    def reset(self) -> None:
        """A new episode: forget the earlier looks."""
        if self.fusion is not None:
            self.fusion.reset()

    def estimate(self, seen: Look) -> JointAxisEstimate:
        """Stages 2-4 on one look: network draft -> refiners -> fusion."""
        draft = refine(network(seen), self.refiners)
        self.last_draft = draft
        return fuse(draft, self.fusion)
