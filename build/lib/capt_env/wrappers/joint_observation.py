"""The joint-axis observation: proprioception plus one joint estimate, as a flat vector or a dict.

Layout of the flat ``float32`` vector (world frame, metres, radians; see :func:`observation_layout`):

=============  ========  ================================================================
name           slice     content
=============  ========  ================================================================
qpos           0:9       Panda joint positions (7 arm joints rad, 2 finger joints m)
qvel           9:18      Panda joint velocities (rad/s, m/s)
tcp_pose       18:25     tool-centre-point pose: position (3, m) then quaternion wxyz (4)
joint_type     25:27     one-hot: [revolute, prismatic]
direction      27:30     estimated unit joint axis; +state opens the part
pivot          30:33     the point of the estimated axis closest to the grasp point (m)
state          33:34     estimated joint state (rad or m; 0 = closed)
grasp_point    34:37     grasp point on the moving part (handle or far edge, m)
confidence     37:38     estimate confidence in [0, 1]
=============  ========  ================================================================

The dict variant has one entry per row above, with the same shapes.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from capt_env.wrappers.estimate import JOINT_TYPES, JointAxisEstimate

_FIELDS: tuple[tuple[str, int], ...] = (
    ("qpos", 9),
    ("qvel", 9),
    ("tcp_pose", 7),
    ("joint_type", 2),
    ("direction", 3),
    ("pivot", 3),
    ("state", 1),
    ("grasp_point", 3),
    ("confidence", 1),
)
OBSERVATION_SIZE: int = sum(n for _, n in _FIELDS)


def observation_layout() -> dict[str, slice]:
    """Name -> slice of every field of the flat observation (the table in the module docstring)."""
    out, start = {}, 0
    for name, n in _FIELDS:
        out[name] = slice(start, start + n)
        start += n
    return out


def _bounds(name: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    if name == "joint_type" or name == "confidence":
        return np.zeros(n, np.float32), np.ones(n, np.float32)
    if name == "direction":
        return -np.ones(n, np.float32), np.ones(n, np.float32)
    return np.full(n, -np.inf, np.float32), np.full(n, np.inf, np.float32)


def flat_space() -> spaces.Box:
    """The declared Box of the flat observation, shape (OBSERVATION_SIZE,), float32."""
    lows, highs = zip(*(_bounds(name, n) for name, n in _FIELDS), strict=True)
    return spaces.Box(np.concatenate(lows), np.concatenate(highs), dtype=np.float32)


def dict_space() -> spaces.Dict:
    """The declared Dict of the dict observation (same fields and shapes as the flat layout)."""
    return spaces.Dict({name: spaces.Box(*_bounds(name, n), dtype=np.float32) for name, n in _FIELDS})


def build_dict(qpos: np.ndarray, qvel: np.ndarray, tcp_pose: np.ndarray,
               estimate: JointAxisEstimate) -> dict[str, np.ndarray]:
    """The dict observation from proprioception ((9,), (9,), (7,)) and a world-frame estimate."""
    one_hot = np.zeros(2, np.float32)
    one_hot[JOINT_TYPES.index(estimate.joint_type)] = 1.0
    values = {
        "qpos": qpos, "qvel": qvel, "tcp_pose": tcp_pose, "joint_type": one_hot,
        "direction": np.clip(estimate.direction, -1.0, 1.0), "pivot": estimate.pivot,
        "state": [estimate.state], "grasp_point": estimate.grasp_point,
        "confidence": [np.clip(estimate.confidence, 0.0, 1.0)],
    }
    out = {}
    for name, n in _FIELDS:
        arr = np.asarray(values[name], dtype=np.float32).reshape(-1)
        if arr.shape != (n,):
            raise ValueError(f"observation field {name!r} needs {n} values, got {arr.shape}")
        out[name] = arr
    return out


def flatten(obs: dict[str, np.ndarray]) -> np.ndarray:
    """Dict observation -> flat float32 vector in :func:`observation_layout` order."""
    return np.concatenate([np.asarray(obs[name], np.float32).reshape(-1) for name, _ in _FIELDS])


def decode_observation(obs: np.ndarray | dict[str, np.ndarray]
                       ) -> tuple[dict[str, np.ndarray], JointAxisEstimate]:
    """Split a flat or dict observation into proprioception (qpos, qvel, tcp_pose) and the estimate."""
    if not isinstance(obs, dict):
        vec = np.asarray(obs, dtype=np.float64).reshape(-1)
        if vec.shape != (OBSERVATION_SIZE,):
            raise ValueError(f"flat observation must have {OBSERVATION_SIZE} values, got {vec.shape}")
        obs = {name: vec[s] for name, s in observation_layout().items()}
    get = {k: np.asarray(v, dtype=np.float64).reshape(-1) for k, v in obs.items()}
    estimate = JointAxisEstimate(
        joint_type=JOINT_TYPES[int(np.argmax(get["joint_type"]))],
        direction=get["direction"], pivot=get["pivot"], state=float(get["state"][0]),
        grasp_point=get["grasp_point"], confidence=float(get["confidence"][0]),
    )
    proprio = {k: get[k] for k in ("qpos", "qvel", "tcp_pose")}
    return proprio, estimate
