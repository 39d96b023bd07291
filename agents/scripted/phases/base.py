"""What every phase of the scripted opener shares: the action conventions of ``pd_ee_delta_pose``, one
step's inputs (:class:`Look`), the phase interface (:class:`OpenerPhase`) and the straight move towards a
goal pose that every phase makes (:func:`goto`, :func:`reached`)."""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from agents.scripted.geometry import clip_norm, rotation_error
from agents.scripted.panda_kinematics import PANDA_LOWER, PANDA_UPPER
from capt_env.wrappers.estimate import JointAxisEstimate

if TYPE_CHECKING:
    from agents.scripted.phases.context import OpenerContext

GRIPPER_OPEN = 1.0
GRIPPER_CLOSE = -1.0
ACTION_SCALE_M = 0.1  # pd_ee_delta_pose: metres per unit translation action
# ManiSkill 3.0.1's PDEEPoseController multiplies rotation actions by ``rot_lower`` (-0.1 for the Panda),
# so a unit rotation action turns by -0.1 rad (XYZ Euler ~ rotation vector at these small angles).
ACTION_SCALE_RAD = -0.1
# the Panda's wrist joints 5, 6 and 7 (rad), from its URDF
_WRIST_LOWER, _WRIST_UPPER = PANDA_LOWER[4:], PANDA_UPPER[4:]
# ManiSkill's Panda gripper maps action [-1, 1] linearly to each finger's position [-0.01, 0.04] m.
_FINGER_LOW, _FINGER_HIGH = -0.01, 0.04


class Phase(enum.Enum):
    """The phase names the policy reports (``ScriptedOpener.phase``) and logs (``phase_log``)."""

    PREGRASP = "pregrasp"
    APPROACH = "approach"
    CLOSE = "close"
    PULL = "pull"
    RELEASE = "release"
    RETREAT = "retreat"
    DONE = "done"


def gripper_action(gap: float) -> float:
    """Gripper action in [-1, 1] that holds the fingers ``gap`` metres apart."""
    finger = 0.5 * gap
    return float(np.clip(2.0 * (finger - _FINGER_LOW) / (_FINGER_HIGH - _FINGER_LOW) - 1.0, -1.0, 1.0))


def hold(gripper: float) -> np.ndarray:
    """Action (7,) that keeps the hand where it is and drives the gripper to ``gripper`` (-1 closed,
    1 open)."""
    action = np.zeros(7, np.float32)
    action[6] = gripper
    return action


def wrist_at_limit(arm_qpos: np.ndarray | None, margin: float) -> bool:
    """Whether one of the Panda's wrist joints (5, 6, 7) in ``arm_qpos`` (7,) rad is within ``margin``
    rad of its limit; False for no joint angles or a margin of 0 (off)."""
    if arm_qpos is None or margin <= 0.0:
        return False
    wrist = np.asarray(arm_qpos, dtype=np.float64).reshape(-1)[4:7]
    return bool(np.any(wrist < _WRIST_LOWER + margin) or np.any(wrist > _WRIST_UPPER - margin))


@dataclass
class Look:
    """One control step's inputs, world frame: the joint-axis estimate, the TCP position ``p`` (3,) m
    and rotation ``r`` (3, 3), the distance between the fingers (m) and the arm's seven joint angles
    (rad), the last two None when unknown."""

    est: JointAxisEstimate
    p: np.ndarray
    r: np.ndarray
    finger_gap: float | None = None
    arm_qpos: np.ndarray | None = None


class OpenerPhase:
    """One phase of the opener. ``step(ctx)`` returns the action (7,) for this control step and the phase
    for the next: ``self`` to stay, or a new phase, entered for the reason ``why`` (a word, logged in
    ``ctx.phase_log`` with ``log_extra``; a phase whose ``why`` is None continues the one before it in
    the log, its step count running on)."""

    phase: Phase

    def __init__(self, why: str | None = None, **log_extra: Any) -> None:
        self.why = why
        self.log_extra: dict[str, Any] = dict(log_extra)

    def step(self, ctx: OpenerContext) -> tuple[np.ndarray, OpenerPhase]:
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.why!r})"


@dataclass
class MoveTracker:
    """How the current straight move is going (reset on entering a phase): ``still`` steps without TCP
    motion, the last TCP position (m) and (position m, rotation rad) errors, and how the last finished
    move ended (``reach_why``: ``"reached"``, ``"timeout"`` or ``"blocked"``)."""

    still: int = 0
    last_p: np.ndarray | None = None
    last_err: tuple[float, float] = (0.0, 0.0)
    reach_why: str = ""


def goto(ctx: OpenerContext, p: np.ndarray, r: np.ndarray, p_des: np.ndarray, r_des: np.ndarray,
         gripper: float) -> tuple[np.ndarray, float, float]:
    """Action (7,) that moves the TCP at ``p`` (3,), ``r`` (3, 3) one capped step towards ``p_des``,
    ``r_des`` with the gripper at ``gripper``, and the position (m) and rotation (rad) errors left."""
    move = ctx.cfg.move
    dp = clip_norm(p_des - p, move.max_step_m)
    dr = clip_norm(rotation_error(r_des, r), move.max_step_rad)
    action = np.concatenate([dp / ACTION_SCALE_M, dr / ACTION_SCALE_RAD, [gripper]])
    return (np.clip(action, -1.0, 1.0).astype(np.float32), float(np.linalg.norm(p_des - p)),
            float(np.linalg.norm(rotation_error(r_des, r))))


def reached(ctx: OpenerContext, p: np.ndarray, perr: float, rerr: float) -> bool:
    """Whether the current move ends: at the goal (``move.pos_tolerance``, ``move.rot_tolerance``), on
    timeout, or blocked (the TCP still for ``move.blocked_steps``); ``ctx.move.reach_why`` says which."""
    cfg, track = ctx.cfg.move, ctx.move
    moved = track.last_p is None or abs(perr - track.last_err[0]) > 0.002 or (
        abs(rerr - track.last_err[1]) > 0.01)
    track.still = 0 if moved or ctx.phase_steps <= 3 else track.still + 1
    track.last_p, track.last_err = p.copy(), (perr, rerr)
    if perr < cfg.pos_tolerance and rerr < cfg.rot_tolerance:
        track.reach_why = "reached"
    elif ctx.phase_steps >= cfg.timeout_steps:
        track.reach_why = "timeout"
    elif track.still >= cfg.blocked_steps:
        track.reach_why = "blocked"
    else:
        return False
    return True
