"""Scripted opening policy for any 1-DoF part, driven only by the joint-axis estimate.

Control mode: ``pd_ee_delta_pose`` (Panda). Actions are bounded per-step pose increments (0.1 m and
0.1 rad per unit action, translation and rotation in world-aligned axes about the TCP; note that
ManiSkill 3.0.1 negates the rotation part, see ``ACTION_SCALE_RAD``), so every
step is closed-loop on the measured TCP pose and on the latest estimate, large jumps of a noisy
estimate cannot produce large motions, and the same actions work with CPU and GPU simulation.
(``pd_ee_pose`` would need a reachable absolute target each step and gives no speed bound.)

Strategy, per episode:

1. ``PREGRASP``: open the gripper to ``approach_gap``, turn the hand in place to the grasp
   orientation (while it is more than ``rotate_first_above`` rad away, for at most
   ``rotate_first_steps`` steps), and move to ``pregrasp_offset`` outside the
   grasp point along the part's outward normal ``n`` (revolute: the opening direction of the grasp point,
   ``axis x (grasp - pivot)``; prismatic: the axis, or, for a part sliding across its face, the
   direction to the robot's base across the axis: :func:`~agents.scripted.grasp_pose.approach_normal`),
   with the TCP approach axis along ``-n`` and the fingers closing perpendicular to the handle
   (revolute: along the radius from the axis, so a bar parallel to the hinge is enclosed; prismatic:
   vertically, or along the slide of a part sliding across its face). Fingers that close on nothing
   at the handle grasp again a quarter turn on (``quarter_turn``). The approach is pitched below
   horizontal by at least ``vertical_hinge_pitch`` (doors), ``prismatic_approach_pitch`` (drawers)
   or ``approach_pitch`` (other parts), as the Panda's wrist cannot point level near the table. A
   lid (its grasp point opens upwards) is gripped from above, the fingers closing along the hinge
   across its front lip (``is_lid``).
   Of the two finger orders the one nearer the hand's rotation is taken, unless a rehearsal on the
   arm's kinematic model says only the other reaches the grasp and holds it through the pull
   (``rehearse_fingers``; :mod:`agents.scripted.grasp_rehearsal`).
2. ``APPROACH``: advance to ``grasp_depth`` past the grasp point. 3. ``CLOSE`` the gripper. If a
   lid's fingers closed on nothing (its lip is wider than the open fingers), the hand backs off and
   lifts the lid from below instead (:func:`~agents.scripted.grasp_pose.lift_pose`): fingers
   closed, pointing at the hinge and steeply down, the fingertips slide in under the grasp point,
   then push along the arc as in 4.
4. ``PULL``: the part's state is measured by the hand itself while it holds the part (the grasp-time
   estimate plus the TCP's swept angle about the estimated axis, or its travel along it), every
   step and free of the perceived state's noise. About a hinge, once the holding hand's path is
   long enough, the centre of the circle it follows replaces the estimated pivot (``arc_fit``).
   The target TCP position is the grasp position moved
   with the part to state ``state_now + lead``: rotated about the estimated axis (revolute) or
   shifted along it (prismatic); the hand turns fully with a door on a vertical hinge and by
   ``wrist_follow`` of the angle about other hinges. The estimate is re-read every step, so
   re-estimation corrects the path.
5. ``RELEASE`` when that state reaches the target (or stops growing: a limit; a part that rises as
   it opens is held there instead, ``DONE`` with the fingers closed: let go, it falls shut), open, and
   ``RETREAT`` back along the approach axis (until there, blocked or timed out); then ``DONE``
   (hold still, gripper open).
If the TCP stays away from the part's grasp point for ``slip_steps`` while pulling and the fingers
have closed on nothing (their gap, from the Panda's qpos, below ``hold_gap``), it goes back to 1;
if pulling stalls short of the target (a slipping grip, or the arm's range), it releases, retreats
and goes back to 1 from the part's new pose (re-grasps are bounded by ``max_regrasps``). A prismatic
part that brakes the pulling hand (see ``limit_slowdown``) has reached its end stop: the hand
releases, retreats and is done; so has one that slips from the hand past ``prismatic_stop_above``.
A door that gravity opens (:func:`~agents.scripted.grasp_pose.falls_open`, an oven door) is not
grasped again once the hand loses it past ``fall_open_done``; short of that, the open hand moves
out of the door's sweep and waits while it falls, then is done or grasps again (``RETREAT``).

Every phase change is recorded in ``phase_log`` (the step, the phase entered and why; a pull also
records whether its fingers held the part), from which
:func:`agents.scripted.failure_cause.failure_cause` names why a failed episode failed.
"""

from __future__ import annotations

import enum
from dataclasses import replace
from typing import Any

import numpy as np

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.geometry import (
    axis_angle_matrix,
    clip_norm,
    fit_circle,
    off_axis,
    quat_to_matrix,
    rotation_error,
    swept_angle,
)
from agents.scripted.grasp_pose import (
    SWAP_FINGERS,
    falls_open,
    grasp_rotation,
    grasp_target,
    is_lid,
    is_vertical_hinge,
    lift_pose,
    part_kind,
    quarter_turn,
)
from agents.scripted.grasp_rehearsal import Rehearsal, rehearse
from agents.scripted.motion_axis import MotionAxis, fit_motion_axis
from agents.scripted.panda_kinematics import PANDA_LOWER, PANDA_UPPER, base_in_world, pose_matrix
from capt_env.wrappers.estimate import JointAxisEstimate, canonical_pivot, unit
from capt_env.wrappers.joint_observation import decode_observation

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


def gripper_action(gap: float) -> float:
    """Gripper action in [-1, 1] that holds the fingers ``gap`` metres apart."""
    finger = 0.5 * gap
    return float(np.clip(2.0 * (finger - _FINGER_LOW) / (_FINGER_HIGH - _FINGER_LOW) - 1.0, -1.0, 1.0))


class Phase(enum.Enum):
    PREGRASP = "pregrasp"
    APPROACH = "approach"
    CLOSE = "close"
    PULL = "pull"
    RELEASE = "release"
    RETREAT = "retreat"
    DONE = "done"



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


class ScriptedOpener:
    """Opens the estimated joint. ``act(obs, info)`` takes the wrapper's flat or dict observation.

    The policy reads only the TCP pose and the estimate in ``obs``; ``info`` is accepted for the
    common policy signature and is not used.
    """

    def __init__(self, config: ScriptedOpenerConfig | None = None) -> None:
        self.cfg = config or ScriptedOpenerConfig()
        self.cfg.validate()
        self.reset()

    def reset(self) -> None:
        """Start a new episode."""
        self.phase = Phase.PREGRASP
        self.phase_steps = 0
        self.steps = 0  # act_on calls this episode (control steps)
        # one entry per phase entered: {"step", "phase", "why"}, and a pull's "grip" (see _grip)
        self.phase_log: list[dict[str, Any]] = [{"step": 0, "phase": Phase.PREGRASP.value, "why": "start"}]
        self._reach_why = ""  # how the last move ended: "reached", "timeout" or "blocked"
        self.regrasps = 0
        self._grasp_p: np.ndarray | None = None
        self._grasp_r: np.ndarray | None = None
        self._grasp_state = 0.0
        self._grasp_u: np.ndarray | None = None
        self._target_r: np.ndarray | None = None
        self._target_for: np.ndarray | None = None  # the grasp point _target_r was chosen for
        self._looks: list[np.ndarray] = []  # the last rechoose_looks grasp points seen, one per new estimate
        self._kind_for: str | None = None  # the part_kind _target_r was chosen for
        self._kinds: list[str] = []  # the part_kind of the last rechoose_looks looks since then
        self._kind_key: np.ndarray | None = None  # the last look's grasp point and direction
        self._swap_this_grasp = False  # this grasp turns the fingers the other way round
        self._pregrasp_steps = 0  # steps this grasp has spent in PREGRASP, moves started over included
        self._lid = False
        self._lift = False
        self._history: list[float] = []
        self._pulled: list[np.ndarray] = []  # TCP positions of this pull, every step
        self._held: list[np.ndarray] = []  # those while the fingers held the part
        self._hinge_fit: np.ndarray | None = None  # the hinge pivot fitted to the held path
        self._part_path: list[np.ndarray] = []  # estimated grasp points while held, every pull
        self._motion: MotionAxis | None = None  # the axis fitted to them (motion_axis), kept
        self._motion_type = ""  # the joint type it was fitted for
        self._slip_count = 0
        self._retreat_from: np.ndarray | None = None
        self._grasp_again = False
        self._falls = False  # the part being pulled falls open when let go (see falls_open)
        self._let_go_state = 0.0  # the part's state (rad or m) when a pull last let go of it
        self._settle: list[float] | None = None  # perceived states while waiting for a falling part
        self._watch: list[float] = []  # perceived states of a part that falls open, before its grasp
        self._other_fingers = False  # the next grasp turns the fingers the other way round
        self._quarter = False  # grasps turn the fingers a quarter turn about the approach (quarter_turn)
        self.rehearsals: tuple[Rehearsal, Rehearsal] | None = None  # the last finger-order rehearsal
        self._still = 0
        self._last_p: np.ndarray | None = None
        self._last_err = (0.0, 0.0)
        self._base: np.ndarray | None = None  # the robot's base position (m), once joint angles are seen
        # DONE holds the part at this TCP pose (position, rotation), fingers closed: let go, it
        # would fall back closed (see _falls_back)
        self._hold_at: tuple[np.ndarray, np.ndarray] | None = None

    # --------------------------------------------------------------- helpers
    def _goto(self, p: np.ndarray, r: np.ndarray, p_des: np.ndarray, r_des: np.ndarray,
              gripper: float) -> tuple[np.ndarray, float, float]:
        dp = clip_norm(p_des - p, self.cfg.max_step_m)
        dr = clip_norm(rotation_error(r_des, r), self.cfg.max_step_rad)
        action = np.concatenate([dp / ACTION_SCALE_M, dr / ACTION_SCALE_RAD, [gripper]])
        return (np.clip(action, -1.0, 1.0).astype(np.float32), float(np.linalg.norm(p_des - p)),
                float(np.linalg.norm(rotation_error(r_des, r))))

    def _set(self, phase: Phase, why: str) -> None:
        """Enter ``phase`` for the reason ``why`` (a word, recorded in ``phase_log``)."""
        if phase != Phase.APPROACH:
            self._watch = []
        self.phase_log.append({"step": self.steps, "phase": phase.value, "why": why})
        self.phase = phase
        self.phase_steps = 0
        self._still = 0
        self._last_p = None

    def _robot_side(self, est: JointAxisEstimate, p: np.ndarray, r: np.ndarray,
                    arm_qpos: np.ndarray | None) -> np.ndarray:
        """Direction (3,) from ``est``'s grasp point to the robot's base: the base's position is
        recovered from the arm's joint angles and the TCP pose (``p`` (3,), ``r`` (3, 3)) and kept;
        without joint angles, the direction to the TCP (the hand comes from the robot's side)."""
        if arm_qpos is not None and self._base is None:
            self._base = base_in_world(np.asarray(arm_qpos, dtype=np.float64), pose_matrix(p, r))[:3, 3]
        towards = self._base if self._base is not None else p
        return np.asarray(towards, dtype=np.float64) - np.asarray(est.grasp_point, dtype=np.float64)

    def _grasp_point_moved(self, est: JointAxisEstimate) -> bool:
        """Whether ``est``'s grasp point is more than ``rechoose_grasp_m`` m from the one the grasp
        orientation was chosen for, on each of the last ``rechoose_looks`` looks (distinct
        estimates), which agree with each other within ``rechoose_grasp_m`` (False before one is
        chosen or with ``rechoose_grasp_m`` 0)."""
        cfg = self.cfg
        if cfg.rechoose_grasp_m <= 0 or self._target_r is None or self._target_for is None:
            return False
        point = np.asarray(est.grasp_point, dtype=np.float64)
        if not self._looks or float(np.linalg.norm(point - self._looks[-1])) > 1e-9:
            # a new look; only the last rechoose_looks are ever compared
            self._looks = [*self._looks, point.copy()][-cfg.rechoose_looks:]
        recent = self._looks
        if len(recent) < cfg.rechoose_looks:
            return False
        target_for = self._target_for
        return all(float(np.linalg.norm(q - target_for)) > cfg.rechoose_grasp_m for q in recent) and all(
            float(np.linalg.norm(q - recent[-1])) <= cfg.rechoose_grasp_m for q in recent)

    def _part_kind_changed(self, est: JointAxisEstimate) -> bool:
        """Whether, with ``rechoose_part_kind``, ``est`` shows another :func:`part_kind` than the
        estimate the grasp orientation was chosen for, on each of the last ``rechoose_looks`` looks
        (a first look can tilt a door's hinge into a lid's: the hand then went for the door's top
        edge, cabinet door seed 3)."""
        if not self.cfg.rechoose_part_kind or self._kind_for is None:
            return False
        key = np.concatenate([est.grasp_point, est.direction]).astype(np.float64)
        if self._kind_key is None or float(np.abs(key - self._kind_key).max()) > 1e-9:  # a new look
            self._kind_key = key
            self._kinds = [*self._kinds, part_kind(est, self.cfg)][-self.cfg.rechoose_looks:]
        return len(self._kinds) >= self.cfg.rechoose_looks and all(k != self._kind_for for k in self._kinds)

    def _reached(self, p: np.ndarray, perr: float, rerr: float) -> bool:
        """A move ends at the goal, on timeout, or when blocked (TCP still for ``blocked_steps``)."""
        moved = self._last_p is None or abs(perr - self._last_err[0]) > 0.002 or (
            abs(rerr - self._last_err[1]) > 0.01)
        self._still = 0 if moved or self.phase_steps <= 3 else self._still + 1
        self._last_p, self._last_err = p.copy(), (perr, rerr)
        if perr < self.cfg.pos_tolerance and rerr < self.cfg.rot_tolerance:
            self._reach_why = "reached"
        elif self.phase_steps >= self.cfg.move_timeout:
            self._reach_why = "timeout"
        elif self._still >= self.cfg.blocked_steps:
            self._reach_why = "blocked"
        else:
            return False
        return True

    # ------------------------------------------------------------------- act
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
        of at least ``hold_gap`` means the fingers still hold something, so the hand is not slipped
        whatever the perceived grasp point says (a part turned far from its first pose is often
        segmented worse). ``arm_qpos``: the arm's seven joint angles (rad), when known; a pull that
        stalls with a wrist joint at its limit grasps again with the fingers the other way round.
        """
        cfg = self.cfg
        p = np.asarray(tcp_pose[:3], dtype=np.float64)
        r = quat_to_matrix(tcp_pose[3:7])
        self.phase_steps += 1
        self.steps += 1
        if self._motion is not None and est.joint_type == self._motion_type:
            est = self._with_motion_axis(est)  # every phase (re-grasps too) goes by the measured axis

        if self.phase in (Phase.PREGRASP, Phase.APPROACH):
            if self._falling_on_its_own(est):
                # the door is falling open ahead of the hand (brushed by it while turning, or let go
                # short of open): reaching for its handle would push it back, so clear its sweep and
                # wait (see RETREAT); if it stops short of fall_open_done it is grasped anew
                self._grasp_p = np.array(est.grasp_point, dtype=np.float64)
                self._grasp_again, self._target_r = True, None
                self._retreat_from, self._settle = p.copy(), []
                self._set(Phase.RETREAT, "falling_open")
                return hold(GRIPPER_OPEN)
            if self.phase == Phase.PREGRASP:
                self._pregrasp_steps += 1
                if self._pregrasp_steps <= cfg.rechoose_steps and (
                        self._grasp_point_moved(est) or self._part_kind_changed(est)):
                    # a different grasp point or part kind: choose again and start the move over (early in the
                    # move only: a part seen open jumps about from look to look, and each start over
                    # turns the hand first)
                    self.phase_steps = 1
            if self._target_r is None or self.phase == Phase.PREGRASP and self.phase_steps == 1:
                if self._target_r is None:  # a new grasp (not a new choice for this one)
                    self._swap_this_grasp, self._other_fingers = self._other_fingers, False
                    self._pregrasp_steps = 1
                self._target_r = grasp_rotation(est, r, cfg, self._robot_side(est, p, r, arm_qpos))
                if self._quarter:
                    self._target_r = quarter_turn(self._target_r, r)
                if cfg.rehearse_fingers and arm_qpos is not None and not is_lid(est, cfg):
                    self._target_r = self._rehearsed_fingers(est, p, r, arm_qpos, self._target_r)
                if self._swap_this_grasp:
                    self._target_r = self._target_r @ SWAP_FINGERS
                self._target_for = np.array(est.grasp_point, dtype=np.float64)
                self._looks = [self._target_for.copy()]
                self._kind_for, self._kinds = part_kind(est, cfg), []
                self._lid = self._kind_for == "lid"
            lift = lift_pose(est, r, cfg, under=self.phase != Phase.PREGRASP) if self._lift else None
            if lift is not None:
                goal, self._target_r = lift
                gripper = GRIPPER_CLOSE
            else:
                approach = self._target_r[:, 2]
                point = grasp_target(est, cfg) if self._lid else est.grasp_point
                if self.phase == Phase.PREGRASP:
                    goal = point - approach * cfg.pregrasp_offset
                else:
                    goal = point + approach * cfg.grasp_depth
                gripper = gripper_action(cfg.lid_approach_gap if self._lid else cfg.approach_gap)
            action, perr, rerr = self._goto(p, r, goal, self._target_r, gripper)
            if (self.phase == Phase.PREGRASP and rerr > cfg.rotate_first_above
                    and self.phase_steps <= cfg.rotate_first_steps):
                # turn the hand where it is first: turned while travelling, the IK ends low and far
                # with the wrist at its limit (drawers), from where it cannot hold the grasp pose
                action[:3] = 0.0
                return action
            if self._reached(p, perr, rerr):
                if self.phase == Phase.PREGRASP:
                    self._set(Phase.APPROACH, self._reach_why)
                elif lift is not None:  # the closed fingertips are under the lid: push it open
                    self._start_pull(p, r, est, "under")
                else:
                    self._set(Phase.CLOSE, self._reach_why)
            return action

        if self.phase == Phase.CLOSE:
            action = hold(GRIPPER_CLOSE)
            if self.phase_steps >= cfg.close_steps:
                if (self._lid and cfg.lid_lift and not self._lift and finger_gap is not None
                        and finger_gap < cfg.hold_gap):
                    # the fingers closed on nothing across the lid's lip (wider than the open
                    # fingers): back off, then lift the lid from below
                    self._lift = self._grasp_again = True
                    self._set(Phase.RELEASE, "empty")
                elif (not self._lid and cfg.regrasp_other_fingers and finger_gap is not None
                        and finger_gap < cfg.hold_gap and self.regrasps < cfg.max_regrasps):
                    # the fingers closed on nothing: back off and grasp again. If the
                    # approach timed out or a wrist joint is at its limit, the arm stopped short of the
                    # handle (a low handle can put one there in one of the two finger orders): the
                    # fingers the other way round. Otherwise the hand is at the handle (there, or
                    # stopped by touching it), which does not lie across the fingers (a lever or bar
                    # at right angles to the one expected): the fingers a quarter turn on
                    self.regrasps += 1
                    self._grasp_again = True
                    short = self._reach_why == "timeout" or wrist_at_limit(arm_qpos, cfg.wrist_limit_margin)
                    if not cfg.quarter_turn or short:
                        self._other_fingers = True
                    else:
                        self._quarter = not self._quarter
                    self._set(Phase.RELEASE, "empty")
                    self.phase_log[-1]["gap"] = round(finger_gap, 4)
                else:
                    empty = finger_gap is not None and finger_gap < cfg.hold_gap
                    self._start_pull(p, r, est, "empty" if empty else "closed")
                    if finger_gap is not None:
                        self.phase_log[-1]["gap"] = round(finger_gap, 4)
            return action

        if self.phase == Phase.PULL:
            return self._pull(est, p, r, finger_gap, arm_qpos)

        if self.phase == Phase.RELEASE:
            action = hold(GRIPPER_OPEN)
            if self.phase_steps >= cfg.release_steps:
                self._retreat_from = p.copy()
                self._set(Phase.RETREAT, "released")
            return action

        if self.phase == Phase.RETREAT:
            assert self._retreat_from is not None
            if self._settle is not None:
                return self._settle_step(est, p, r)
            goal = self._retreat_from - r[:, 2] * cfg.retreat_distance
            action, perr, _ = self._goto(p, r, goal, r, GRIPPER_OPEN)
            if self._reached(p, perr, 0.0):  # there, timed out, or blocked (the arm's range)
                # (a pull's end sets the state it let go at; fingers that closed on nothing do not)
                let_go, self._let_go_state = self._let_go_state, 0.0
                if self._lets_fall() and let_go >= cfg.settle_above:
                    self._settle = []  # clear the door's sweep, wait while it falls, then decide
                elif self._grasp_again:
                    self._grasp_again = False
                    self._target_r = None
                    self._set(Phase.PREGRASP, "regrasp")
                else:
                    self._set(Phase.DONE, "retreated")
            return action

        if self._hold_at is not None:  # keep the hand, and the part it holds, where the pull ended
            return self._goto(p, r, *self._hold_at, GRIPPER_CLOSE)[0]
        return hold(GRIPPER_OPEN)

    def _falls_back(self, u: np.ndarray, revolute: bool) -> bool:
        """Whether a prismatic part opening along unit ``u`` (3,) rises more than
        ``hold_rising_above`` rad above horizontal, so that gravity slides it back closed once let go
        (a window sliding up; 0: never)."""
        rise = self.cfg.hold_rising_above
        return not revolute and rise > 0.0 and float(u[2]) > float(np.sin(rise))

    def _rehearse(self, est: JointAxisEstimate, p: np.ndarray, r: np.ndarray, arm_qpos: np.ndarray,
                  rotation: np.ndarray) -> Rehearsal:
        """Grasp and pull with TCP ``rotation`` (3, 3) rehearsed on the arm's kinematic model."""
        cfg = self.cfg
        approach = rotation[:, 2]
        point = est.grasp_point
        grasp = point + approach * cfg.grasp_depth
        u = unit(est.direction)
        path: list[tuple[np.ndarray, np.ndarray]] = []
        if est.joint_type == "revolute":
            follow = 1.0 if is_vertical_hinge(est, cfg) else cfg.wrist_follow
            for delta in np.arange(0.05, max(cfg.revolute_target - float(est.state), 0.0) + 1e-9, 0.05):
                path.append((est.pivot + axis_angle_matrix(u, delta) @ (grasp - est.pivot),
                             axis_angle_matrix(u, follow * delta) @ rotation))
        else:
            for delta in np.arange(0.01, max(cfg.prismatic_target - float(est.state), 0.0) + 1e-9, 0.01):
                path.append((grasp + u * delta, rotation))
        pregrasp = point - approach * cfg.pregrasp_offset
        return rehearse(arm_qpos, pose_matrix(p, r), rotation, pregrasp, grasp, path,
                        max_step_m=cfg.max_step_m, max_step_rad=cfg.max_step_rad,
                        rotate_first_above=cfg.rotate_first_above,
                        rotate_first_steps=cfg.rotate_first_steps, move_timeout=cfg.move_timeout,
                        pos_tolerance=cfg.pos_tolerance, rot_tolerance=cfg.rot_tolerance,
                        pull_tolerance_m=cfg.rehearse_track_m)

    def _rehearsed_fingers(self, est: JointAxisEstimate, p: np.ndarray, r: np.ndarray,
                           arm_qpos: np.ndarray, nearer: np.ndarray) -> np.ndarray:
        """``nearer`` (3, 3), or the same approach with the fingers swapped if the rehearsal says the
        arm reaches and pulls clearly better that way (see ``rehearse_fingers`` in the config)."""
        cfg = self.cfg
        other = nearer @ SWAP_FINGERS

        def reaches(x: Rehearsal) -> bool:
            return x.grasp_error_m <= 2 * cfg.pos_tolerance and x.grasp_error_rad <= 2 * cfg.rot_tolerance

        a = self._rehearse(est, p, r, arm_qpos, nearer)
        b = self._rehearse(est, p, r, arm_qpos, other)
        self.rehearsals = (a, b)
        if reaches(b) and b.pull_share >= 1.0 and (
                not reaches(a) or a.pull_share <= 1.0 - cfg.rehearse_margin):
            return other
        return nearer

    def _start_pull(self, p: np.ndarray, r: np.ndarray, est: JointAxisEstimate, why: str) -> None:
        self._grasp_p, self._grasp_r, self._grasp_state = p.copy(), r.copy(), est.state
        self._grasp_u = unit(est.direction)
        self._falls = falls_open(est, self.cfg)
        self._history = []
        self._pulled = [p.copy()]
        self._held = [p.copy()]
        self._hinge_fit = None
        self._slip_count = 0
        self._set(Phase.PULL, why)
        # a hand lifting from below holds with closed fingers; unknown gaps count as holding
        self.phase_log[-1]["grip"] = "held" if self._lift else "none"

    def _braked(self) -> bool:
        """Whether the hand, pulling at a cruising speed (median step of this pull, at least
        ``limit_min_speed_m`` m), moved less than ``limit_slowdown`` of it in each of the last
        ``limit_window`` steps under the same command: something stopped the part."""
        cfg = self.cfg
        steps = np.diff(self._history)
        if len(steps) < cfg.limit_window + 5:
            return False
        cruise = float(np.median(steps[:-cfg.limit_window]))
        recent = steps[-cfg.limit_window:]
        return cruise >= cfg.limit_min_speed_m and bool(np.all(recent < cfg.limit_slowdown * cruise))

    def _hinge_pivot(self, u: np.ndarray, pivot: np.ndarray, p: np.ndarray,
                     finger_gap: float | None) -> np.ndarray:
        """The pivot (3,) to pull about: the centre of the circle the holding hand's path follows
        about unit axis ``u`` when ``arc_fit`` accepts it (see the config), else the estimated
        ``pivot``. ``p``: the TCP position now, added to the path while the fingers hold."""
        cfg = self.cfg
        if not cfg.arc_fit or finger_gap is None or finger_gap < cfg.hold_gap:
            return pivot
        if self._hinge_fit is not None:
            return self._hinge_fit
        self._held.append(p.copy())
        path = np.asarray(self._held)
        if (np.linalg.norm(path - path[0], axis=1).max() < cfg.arc_fit_min_chord
                or abs(swept_angle(u, pivot, path[0], p)) < cfg.arc_fit_min_angle):
            return pivot
        fit = fit_circle(path, u)
        if fit is None or fit[2] > cfg.arc_fit_max_rms:
            return pivot
        offset = fit[0] - pivot
        if np.linalg.norm(off_axis(offset, u)) > cfg.arc_fit_max_shift:
            return pivot
        # kept for the rest of the pull: a hand that later slips off the handle leaves the arc
        self._hinge_fit = fit[0]
        return fit[0]

    def _hand_state(self, u: np.ndarray, pivot: np.ndarray, p: np.ndarray, revolute: bool) -> float:
        """The part's state (rad or m) by the hand's own measure: the state at the grasp plus the
        TCP's travel from the grasp position to ``p`` about (revolute) or along unit axis ``u``."""
        assert self._grasp_p is not None
        if revolute:
            return self._grasp_state + swept_angle(u, pivot, self._grasp_p, p)
        return self._grasp_state + float((p - self._grasp_p) @ u)

    def _motion_axis(self, est: JointAxisEstimate, u: np.ndarray, p: np.ndarray, r: np.ndarray,
                     finger_gap: float | None, revolute: bool) -> np.ndarray:
        """The axis direction to pull along (``motion_axis``): the one fitted to the path of the
        estimated grasp point while held (:func:`fit_motion_axis`), once it fits, else ``u``. The
        first accepted fit is kept for the episode (later pulls too) and starts this pull over from
        where the hand is, so the arc or line it follows does not jump."""
        cfg = self.cfg
        holding = finger_gap is not None and finger_gap >= cfg.hold_gap
        gp = np.asarray(est.grasp_point, dtype=np.float64)
        if holding and (not self._part_path or np.linalg.norm(gp - self._part_path[-1]) > 1e-3):
            self._part_path.append(gp.copy())  # a new estimate (they repeat between looks)
        if self._motion is None and holding:
            pivot = self._hinge_fit if self._hinge_fit is not None else est.pivot
            fit = fit_motion_axis(np.asarray(self._part_path), u, pivot, revolute,
                                  cfg.motion_axis_min_travel, cfg.motion_axis_min_angle,
                                  cfg.motion_axis_max_rms, cfg.motion_axis_max_turn,
                                  cfg.motion_axis_max_ratio,
                                  cfg.motion_axis_hinge_points if revolute else 3)
            if fit is not None:
                self._grasp_state = self._hand_state(u, pivot, p, revolute)
                self._grasp_p, self._grasp_r, self._grasp_u = p.copy(), r.copy(), fit.direction
                self._pulled, self._held, self._hinge_fit = [p.copy()], [p.copy()], None
                self._motion, self._motion_type = fit, est.joint_type
        if self._motion is None:
            return u
        direction = self._motion.direction
        return direction if float(direction @ u) >= 0.0 else -direction

    def _with_motion_axis(self, est: JointAxisEstimate) -> JointAxisEstimate:
        """``est`` with the axis fitted to the part's motion (signed like ``est``'s direction; a
        revolute pivot moved to the point of the fitted line closest to the grasp point)."""
        assert self._motion is not None
        direction = self._motion.direction
        if float(direction @ est.direction) < 0.0:
            direction = -direction
        pivot = est.pivot
        if est.joint_type == "revolute":
            grasp = np.asarray(est.grasp_point, dtype=np.float64)
            pivot = canonical_pivot(direction, self._motion.pivot, grasp)
        return replace(est, direction=direction, pivot=pivot)

    def _falling_on_its_own(self, est: JointAxisEstimate) -> bool:
        """Whether, before its grasp, a part that :func:`falls_open` is seen falling open: at least
        ``settle_above`` rad open and risen by ``settle_progress`` rad over the last ``settle_window``
        steps (``watch_falling`` and ``fall_open_done`` > 0; never while lifting a lid)."""
        cfg = self.cfg
        if not cfg.watch_falling or cfg.fall_open_done <= 0.0 or self._lift or not falls_open(est, cfg):
            self._watch = []
            return False
        self._watch.append(float(est.state))
        return self._watch[-1] >= cfg.settle_above and self._risen(self._watch)

    def _risen(self, states: list[float]) -> bool:
        """Whether the last of ``states`` (rad, one per step) is ``settle_progress`` above the one
        ``settle_window`` steps before (False with fewer states than that)."""
        window = self.cfg.settle_window
        return len(states) > window and states[-1] - states[-1 - window] >= self.cfg.settle_progress

    def _lets_fall(self) -> bool:
        """Whether to let the part being pulled fall open when the hand loses it: it
        :func:`falls_open` by the estimate the pull began with (one of a door near level, its handle
        hidden by the hand, can be far off) and ``fall_open_done`` > 0."""
        return self.cfg.fall_open_done > 0.0 and self._falls

    def _settle_step(self, est: JointAxisEstimate, p: np.ndarray, r: np.ndarray) -> np.ndarray:
        """After letting go of a door that falls open, at least ``settle_above`` rad open: move the
        open hand out of its sweep, to ``settle_clearance`` m beyond the grasp radius about the
        estimated hinge, and wait while the perceived state still rises (by ``settle_progress`` rad
        over ``settle_window`` steps; at most ``settle_max_steps``). Then grasp again if the pull
        ended short of its target and the state is still short of ``fall_open_done`` rad, else done."""
        cfg = self.cfg
        assert self._settle is not None and self._grasp_p is not None
        u = unit(est.direction)
        radial = off_axis(p - est.pivot, u)
        radius = float(np.linalg.norm(radial))
        goal = p
        if radius > 1e-6:
            clear = float(np.linalg.norm(off_axis(self._grasp_p - est.pivot, u))) + cfg.settle_clearance
            goal = p + max(clear - radius, 0.0) * radial / radius
        action, _, _ = self._goto(p, r, goal, r, GRIPPER_OPEN)
        self._settle.append(float(est.state))
        states = self._settle
        rising = len(states) <= cfg.settle_window or self._risen(states)
        if rising and len(states) < cfg.settle_max_steps:
            return action
        self._settle = None
        again, self._grasp_again = self._grasp_again and est.state < cfg.fall_open_done, False
        if again:
            self._target_r = None
            self._set(Phase.PREGRASP, "regrasp")
        else:
            self._set(Phase.DONE, "settled")
        return action

    def _grip(self, holding: bool, unknown: bool) -> None:
        """Record in this pull's ``phase_log`` entry whether the fingers hold the part: its
        ``"grip"`` is ``"none"`` until the finger gap first reads at least ``hold_gap`` (``holding``),
        then ``"held"``, and ``"lost"`` once the fingers have closed on nothing after holding (or
        the slip check fires on a hand lifting from below, whose closed fingers tell no gap). Without
        a gap (``unknown``) a pull counts as held."""
        entry = self.phase_log[-1]
        if unknown:
            if entry.get("grip") == "none":
                entry["grip"] = "held"
        elif holding:
            entry["grip"] = "held"
        elif entry.get("grip") == "held" and not self._lift:
            entry["grip"] = "lost"

    def _pull(self, est: JointAxisEstimate, p: np.ndarray, r: np.ndarray,
              finger_gap: float | None = None, arm_qpos: np.ndarray | None = None) -> np.ndarray:
        cfg = self.cfg
        assert self._grasp_p is not None and self._grasp_r is not None
        revolute = est.joint_type == "revolute"
        u = unit(est.direction)
        if self._grasp_u is not None and float(u @ self._grasp_u) < 0.0:
            # the part opens the way it did when the pull began: a re-estimate that flips the axis
            # (the sign is what a single view gets wrong most) would read the opening as closing
            u = -u
        if cfg.motion_axis:
            u = self._motion_axis(est, u, p, r, finger_gap, revolute)
        # while the hand holds the part, its own travel along the estimated arc or line measures the
        # part's state every step; the perceived state is noisier and only as fresh as the last estimate
        if self._motion is not None:
            pivot = self._motion.pivot
        else:
            pivot = self._hinge_pivot(u, est.pivot, p, finger_gap) if revolute else est.pivot
        state = self._hand_state(u, pivot, p, revolute)
        self._history.append(state)
        self._pulled.append(p.copy())
        # a drawer runs freely up to its end stop, where the hand brakes before the handle slides out
        # of the fingers: that is the limit, and grasping again would chase a part that is open
        at_limit = not revolute and self._braked()
        if revolute:
            target = cfg.lid_revolute_target if self._lid else cfg.revolute_target
        else:
            target = cfg.prismatic_target
        min_progress = cfg.stall_progress if revolute else cfg.stall_progress_m
        # progress over the last stall_steps, measured about the pivot in use now (arc_fit may
        # have moved it, which changes the state read along the whole path, not the part's motion)
        stalled = False
        if len(self._pulled) > cfg.stall_steps + 1:
            before = self._pulled[-1 - cfg.stall_steps]
            progress = (swept_angle(u, pivot, before, p) if revolute else float((p - before) @ u))
            stalled = progress < min_progress
        holding = finger_gap is not None and finger_gap >= cfg.hold_gap
        self._grip(holding, finger_gap is None)
        falls = self._lets_fall()
        if state >= target or stalled or at_limit:
            # short of the target the grip slipped or the arm ran out of range: grasp again from here
            self._grasp_again = state < target and not at_limit and self.regrasps < cfg.max_regrasps
            wrist_stuck = stalled and wrist_at_limit(arm_qpos, cfg.wrist_limit_margin)
            if falls and min(state, float(est.state)) >= cfg.fall_open_done:
                # a door that falls open, past fall_open_done: grasping it again pushes it back. Both
                # the hand and the perception must say so: fingers slipping along the handle carry
                # the hand round the arc ahead of the door (hand 1.6 rad, door 1.0: oven seed 11)
                self._grasp_again = False
            if (stalled and revolute and not self._lid and not falls and holding and not wrist_stuck
                    and 0.0 < cfg.revolute_stop_above <= state):
                # held far open and the arm still in range: the part is at its end stop, and
                # reaching for the handle again would knock it back
                self._grasp_again = False
            self.regrasps += int(self._grasp_again)
            self._let_go_state = state
            if not self._grasp_again and holding and self._falls_back(u, revolute):
                # let go, a part lifted against gravity slides back closed: hold it where it is
                self._hold_at = (p.copy(), r.copy())
                self._set(Phase.DONE, "target" if state >= target else "stall" if stalled else "limit")
                return hold(GRIPPER_CLOSE)
            if self._grasp_again and wrist_stuck:
                # the arm ran out of range with this finger order: the other one turns the wrist
                # the other way
                self._other_fingers = True
            self._set(Phase.RELEASE, "target" if state >= target else "stall" if stalled else "limit")
            return hold(GRIPPER_CLOSE)
        away = p - np.asarray(est.grasp_point, dtype=np.float64)
        if self._lid and cfg.lid_slip_off_axis:  # a lid is revolute (part_kind)
            away = off_axis(away, u)  # along its hinge, a lid's far edge is all the same to the hand
        far = float(np.linalg.norm(away)) > cfg.slip_distance and not holding
        self._slip_count = self._slip_count + 1 if far else 0
        if self._slip_count >= cfg.slip_steps and self.phase_log[-1].get("grip") == "held":
            self.phase_log[-1]["grip"] = "lost"  # (a lift's closed fingers tell no gap)
        if self._slip_count >= cfg.slip_steps and falls and est.state >= cfg.settle_above:
            # off the handle of a door that falls open: let go, clear it and wait (see RETREAT)
            # instead of reaching for a handle on the move; past fall_open_done it is left open
            self._grasp_again = est.state < cfg.fall_open_done and self.regrasps < cfg.max_regrasps
            self.regrasps += int(self._grasp_again)
            self._let_go_state = float(est.state)
            self._set(Phase.RELEASE, "slip")
            return hold(GRIPPER_OPEN)
        if self._slip_count >= cfg.slip_steps and not revolute and 0.0 < cfg.prismatic_stop_above <= state:
            # off the handle of a drawer pulled far out: it ran to its end stop and the brake was
            # missed; reaching for the handle again would push the open drawer back in
            self._grasp_again = False
            self._let_go_state = state
            self._set(Phase.RELEASE, "slip")
            return hold(GRIPPER_OPEN)
        if self._slip_count >= cfg.slip_steps and self.regrasps < cfg.max_regrasps:
            self.regrasps += 1
            self._target_r = None
            self._set(Phase.PREGRASP, "slip")
            return hold(GRIPPER_OPEN)
        if revolute:
            lifting = self._lid and self._lift
            delta = state - self._grasp_state + (cfg.lid_lift_lead if lifting else cfg.revolute_lead)
            p_des = pivot + axis_angle_matrix(u, delta) @ (self._grasp_p - pivot)
            if lifting and cfg.lid_lift_inward > 0.0:
                # lifting from below, the fingertips slide towards the hinge as the lid turns: off
                # the lid's own arc (an estimated hinge a centimetre or two off), they stay under it
                radial = off_axis(p_des - pivot, u)
                radius = float(np.linalg.norm(radial))
                if radius > 1e-6:
                    p_des = p_des - min(cfg.lid_lift_inward * max(delta, 0.0), 0.5 * radius) * radial / radius
            if is_vertical_hinge(est, cfg):
                follow = 1.0
            elif self._lid:
                follow = cfg.lid_lift_wrist_follow if self._lift else cfg.lid_wrist_follow
            else:
                follow = cfg.wrist_follow
            r_des = axis_angle_matrix(u, follow * delta) @ self._grasp_r
        else:
            delta = state - self._grasp_state + cfg.prismatic_lead
            p_des = self._grasp_p + u * delta
            r_des = self._grasp_r
        action, _, _ = self._goto(p, r, p_des, r_des, GRIPPER_CLOSE)
        return action
