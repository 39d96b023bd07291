"""Gymnasium wrappers that turn a capt_env point-cloud env into joint-axis observations.

- :mod:`~capt_env.wrappers.object_isolation`: keep the object's points of a world-frame cloud.
- :mod:`~capt_env.wrappers.robot_filter`: drop points on the robot, from its link poses and shapes.
- :mod:`~capt_env.wrappers.estimate`: the per-joint estimate the observation and the agents use.
- :mod:`~capt_env.wrappers.estimate_pipeline`: the CAPT estimate's stages, in order: isolate ->
  network -> refiners (:mod:`~capt_env.wrappers.refiners`, one module each) -> fuse -> observation.
- :mod:`~capt_env.wrappers.perception_sources`: oracle, noisy oracle and the CAPT sources (``capt_raw``:
  the network alone; ``capt``: refined and fused).
- :mod:`~capt_env.wrappers.joint_observation`: the flat / dict observation and its layout.
- :mod:`~capt_env.wrappers.perception_wrapper`: :class:`CaptObservationWrapper`, tying them together.
- :mod:`~capt_env.wrappers.batched_oracle_observation`: :class:`BatchedOracleObservation`, the same
  observation from ground truth for a batched ManiSkill env (GPU simulation), as torch tensors.
"""

from capt_env.wrappers.batched_oracle_observation import BatchedOracleObservation
from capt_env.wrappers.config import IsolationConfig, NoiseConfig, PerceptionWrapperConfig
from capt_env.wrappers.estimate import JointAxisEstimate
from capt_env.wrappers.joint_observation import (
    OBSERVATION_SIZE,
    decode_observation,
    observation_layout,
)
from capt_env.wrappers.perception_wrapper import CaptObservationWrapper

__all__ = [
    "OBSERVATION_SIZE",
    "BatchedOracleObservation",
    "CaptObservationWrapper",
    "IsolationConfig",
    "JointAxisEstimate",
    "NoiseConfig",
    "PerceptionWrapperConfig",
    "decode_observation",
    "observation_layout",
]
