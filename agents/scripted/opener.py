"""Scripted opening policy for any 1-DoF part, driven only by the joint-axis estimate.

Control mode: ``pd_ee_delta_pose`` (Panda). Actions are bounded per-step pose increments (0.1 m and
0.1 rad per unit action, translation and rotation in world-aligned axes about the TCP; note that
ManiSkill 3.0.1 negates the rotation part, see ``ACTION_SCALE_RAD``), so every step is closed-loop on
the measured TCP pose and on the latest estimate, large jumps of a noisy estimate cannot produce large
motions, and the same actions work with CPU and GPU simulation. (``pd_ee_pose`` would need a reachable
absolute target each step and gives no speed bound.)

:class:`ScriptedOpener` owns the episode's state (:class:`~agents.scripted.phases.context.OpenerContext`)
and runs the current phase; each phase (:mod:`agents.scripted.phases`) is a small class whose
``step(ctx)`` returns the action and the next phase:

1. :class:`~agents.scripted.phases.reach.PreGrasp`: open the gripper to the approach gap, turn the hand
   in place to the grasp orientation and move outside the grasp point along the part's outward normal,
   the fingers closing across the handle, as the part-kind strategy chosen with the grasp says
   (:mod:`agents.scripted.part_strategies`: lid, side door, door that falls open, other hinge,
   drawer, sliding panel; the finger order checked on the arm's kinematic model,
   :mod:`agents.scripted.grasp_rehearsal`).
2. :class:`~agents.scripted.phases.reach.Approach` to the grasp point, then
   :class:`~agents.scripted.phases.grasp.Close`.
3. :class:`~agents.scripted.phases.pull.Pull`: the part's state measured by the hand's own travel, the
   TCP led along the estimated arc or line.
4. :class:`~agents.scripted.phases.release.Release`, :class:`~agents.scripted.phases.release.Retreat`,
   then :class:`~agents.scripted.phases.release.Done`.

Recoveries: fingers that close on nothing, a pull that slips or stalls short of its target grasp again
(release, retreat, a fresh pre-grasp: :func:`~agents.scripted.phases.release.regrasp`), a lid's lip
too wide for the open fingers is lifted from below (:class:`~agents.scripted.phases.reach.LiftLineUp`,
:class:`~agents.scripted.phases.reach.LiftSlideUnder`, then a pull), and a door that gravity opens is
left to fall while the hand waits out of its sweep
(:class:`~agents.scripted.phases.release.WaitForFall`).

Every phase change is recorded in ``phase_log`` (the step, the phase entered and why; a pull also
records whether its fingers held the part), from which
:func:`agents.scripted.failure_cause.failure_cause` names why a failed episode failed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.geometry import quat_to_matrix
from agents.scripted.grasp_rehearsal import Rehearsal
from agents.scripted.phases.base import (
    ACTION_SCALE_M,
    ACTION_SCALE_RAD,
    GRIPPER_CLOSE,
    GRIPPER_OPEN,
    Look,
    OpenerPhase,
    Phase,
    gripper_action,
    hold,
    wrist_at_limit,
)
from agents.scripted.phases.context import OpenerContext
from agents.scripted.phases.pull import with_motion_axis
from agents.scripted.phases.reach import PreGrasp
from capt_env.wrappers.estimate import JointAxisEstimate
from capt_env.wrappers.joint_observation import decode_observation

__all__ = ["ACTION_SCALE_M", "ACTION_SCALE_RAD", "GRIPPER_CLOSE", "GRIPPER_OPEN", "Phase", "ScriptedOpener",
           "gripper_action", "hold", "wrist_at_limit"]


class ScriptedOpener:
    """Opens the estimated joint. ``act(obs, info)`` takes the wrapper's flat or dict observation.

    The policy reads only the TCP pose, the fingers, the arm's joint angles and the estimate in
    ``obs``; ``info`` is accepted for the common policy signature and is not used.
    """

    def __init__(self, config: ScriptedOpenerConfig | None = None) -> None:
        self.cfg = config or ScriptedOpenerConfig()
        self.cfg.validate()
        self.reset()

    def reset(self) -> None:
        """Start a new episode."""
        self.ctx = OpenerContext(self.cfg)
        self.current: OpenerPhase = PreGrasp("start")
        self.ctx.enter(self.current)

    def enter(self, phase: OpenerPhase) -> None:
        """Make ``phase`` the current phase, as a phase's step does (logged, its step count from 0)."""
        self.ctx.enter(phase)
        self.current = phase

    @property
    def phase(self) -> Phase:
        """The current phase's name."""
        return self.current.phase

    @property
    def phase_log(self) -> list[dict[str, Any]]:
        """One entry per phase entered: ``{"step", "phase", "why"}``, a pull's with its ``"grip"``."""
        return self.ctx.phase_log

    @property
    def steps(self) -> int:
        """``act_on`` calls this episode (control steps)."""
        return self.ctx.steps

    @property
    def phase_steps(self) -> int:
        """Control steps in the current phase."""
        return self.ctx.phase_steps

    @property
    def regrasps(self) -> int:
        """Grasps after the first this episode."""
        return self.ctx.regrasps

    @property
    def rehearsals(self) -> tuple[Rehearsal, Rehearsal] | None:
        """The last finger-order rehearsal (nearer order, other order), if any."""
        return self.ctx.rehearsals

    def act(self, obs: np.ndarray | dict[str, np.ndarray], info: dict[str, Any] | None = None) -> np.ndarray:
        """Action (7,) in [-1, 1] for ``pd_ee_delta_pose`` from a joint-axis observation."""
        proprio, est = decode_observation(obs)
        qpos = np.asarray(proprio["qpos"], dtype=np.float64).reshape(-1)
        return self.act_on(est, proprio["tcp_pose"], finger_gap=float(qpos[7] + qpos[8]),
                           arm_qpos=qpos[:7])

    def act_on(self, est: JointAxisEstimate, tcp_pose: np.ndarray,
               finger_gap: float | None = None, arm_qpos: np.ndarray | None = None) -> np.ndarray:
        """Action (7,) from an estimate and the TCP pose (7,) (position m, quaternion wxyz), world frame.

        ``finger_gap``: the distance between the Panda's fingers (m), when known. While pulling, a gap
        of at least ``grasp.hold_gap`` means the fingers still hold something, so the hand is not
        slipped whatever the perceived grasp point says. ``arm_qpos``: the arm's seven joint angles
        (rad), when known; a pull that stalls with a wrist joint at its limit grasps again with the
        fingers the other way round.
        """
        ctx = self.ctx
        p = np.asarray(tcp_pose[:3], dtype=np.float64)
        r = quat_to_matrix(tcp_pose[3:7])
        ctx.phase_steps += 1
        ctx.steps += 1
        if ctx.axis.motion is not None and est.joint_type == ctx.axis.motion_type:
            est = with_motion_axis(ctx, est)  # every phase (re-grasps too) goes by the measured axis
        ctx.now = Look(est, p, r, finger_gap, arm_qpos)
        action, following = self.current.step(ctx)
        if following is not self.current:
            self.enter(following)
        return action
