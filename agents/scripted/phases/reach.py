"""Reaching the grasp: the pre-grasp (turn the hand to the grasp orientation, move outside the grasp
point), the approach (in along the approach axis), and the same two moves of the lift from below (a
lid whose lip is wider than the open fingers: the closed fingertips line up in front of the lip, then
slide in under it). The grasp orientation is chosen as a grasp's pre-grasp starts, and again early in
it when the perceived grasp point or part kind changes (``approach.rechoose_*``), together with the
part-kind strategy (:mod:`agents.scripted.part_strategies`) the grasp keeps: it says where the TCP
grips, how the hand is turned, the approach gap and whether the finger orders are rehearsed."""

from __future__ import annotations

import numpy as np

from agents.scripted.geometry import axis_angle_matrix, out_of_sweep
from agents.scripted.grasp_pose import SWAP_FINGERS, quarter_turn
from agents.scripted.grasp_rehearsal import Rehearsal, rehearse
from agents.scripted.panda_kinematics import base_in_world, pose_matrix
from agents.scripted.part_strategies import Lid, PartStrategy, strategy_for
from agents.scripted.phases import grasp, pull, release
from agents.scripted.phases.base import (
    GRIPPER_CLOSE,
    GRIPPER_OPEN,
    OpenerPhase,
    Phase,
    goto,
    gripper_action,
    hold,
    reached,
)
from agents.scripted.phases.context import OpenerContext
from capt_env.wrappers.estimate import JointAxisEstimate, unit


def pregrasp(ctx: OpenerContext, why: str) -> OpenerPhase:
    """The pre-grasp of a new grasp: :class:`LiftLineUp` once a lid is lifted from below, else
    :class:`PreGrasp`."""
    return LiftLineUp(why) if ctx.lift else PreGrasp(why)


class _Reach(OpenerPhase):
    """A move to a pose by the grasp point (see :class:`PreGrasp`, :class:`Approach`)."""

    def step(self, ctx: OpenerContext) -> tuple[np.ndarray, OpenerPhase]:
        cfg, look, choice = ctx.cfg, ctx.now, ctx.grasp
        assert look is not None
        est, p, r = look.est, look.p, look.r
        if falling_on_its_own(ctx, est):
            # the door is falling open ahead of the hand (brushed by it while turning, or let go
            # short of open): reaching for its handle would push it back, so clear its sweep and
            # wait; if it stops short of falling_door.done_above it is grasped anew
            ctx.pull.grasp_p = np.array(est.grasp_point, dtype=np.float64)
            ctx.grasp_again, choice.target_r = True, None
            ctx.retreat_from, ctx.settle = p.copy(), []
            return hold(GRIPPER_OPEN), release.WaitForFall("falling_open")
        if self.phase == Phase.PREGRASP:
            choice.pregrasp_steps += 1
            if choice.pregrasp_steps <= cfg.approach.rechoose_steps and (
                    grasp_point_moved(ctx, est) or part_kind_changed(ctx, est)):
                # a different grasp point or part kind: choose again and start the move over (early in
                # the move only: a part seen open jumps about from look to look, and each start over
                # turns the hand first)
                ctx.phase_steps = 1
        if choice.target_r is None or self.phase == Phase.PREGRASP and ctx.phase_steps == 1:
            choose_grasp(ctx, est, p, r, look.arm_qpos)
        assert choice.target_r is not None
        goal, gripper = self.goal(ctx, est)
        action, perr, rerr = goto(ctx, p, r, goal, choice.target_r, gripper)
        if (self.phase == Phase.PREGRASP and rerr > cfg.approach.rotate_first_above
                and ctx.phase_steps <= cfg.approach.rotate_first_steps):
            # turn the hand where it is first: turned while travelling, the IK ends low and far
            # with the wrist at its limit, from where it cannot hold the grasp pose; in the sweep of
            # a door that falls open, move out of it first, unturned
            clear = out_of_fall_sweep(ctx, ctx.grip(est), est, p)
            if clear is None:
                action[:3] = 0.0
            else:
                action, _, _ = goto(ctx, p, r, clear, r, gripper)
            return action, self
        if reached(ctx, p, perr, rerr):
            return action, self.next(ctx, est)
        return action, self

    def goal(self, ctx: OpenerContext, est: JointAxisEstimate) -> tuple[np.ndarray, float]:
        """TCP goal position (3,) and gripper action; may also set ``ctx.grasp.target_r``."""
        raise NotImplementedError

    @staticmethod
    def along_approach(ctx: OpenerContext, est: JointAxisEstimate, depth: float) -> tuple[np.ndarray, float]:
        """The point the grasp's strategy grips (a lid's front lip) moved ``depth`` m along the approach
        axis (negative: outside the part), with the gripper's action for its approach gap."""
        choice, grip = ctx.grasp, ctx.grip(est)
        assert choice.target_r is not None
        goal = grip.grasp_target(est) + choice.target_r[:, 2] * depth
        return keep_along_axis(ctx, est, goal, grip.along_slack(est)), gripper_action(grip.gap)

    def next(self, ctx: OpenerContext, est: JointAxisEstimate) -> OpenerPhase:
        """The phase after the move ended (``ctx.move.reach_why`` says how)."""
        raise NotImplementedError


class PreGrasp(_Reach):
    """Open the gripper to the approach gap, turn the hand in place to the grasp orientation and move to
    ``approach.pregrasp_offset`` outside the grasp point along the approach axis."""

    phase = Phase.PREGRASP

    def goal(self, ctx: OpenerContext, est: JointAxisEstimate) -> tuple[np.ndarray, float]:
        return self.along_approach(ctx, est, -ctx.cfg.approach.pregrasp_offset)

    def next(self, ctx: OpenerContext, est: JointAxisEstimate) -> OpenerPhase:
        return LiftSlideUnder(ctx.move.reach_why) if ctx.lift else Approach(ctx.move.reach_why)


class Approach(_Reach):
    """Advance ``approach.grasp_depth`` past the grasp point; then close."""

    phase = Phase.APPROACH

    def goal(self, ctx: OpenerContext, est: JointAxisEstimate) -> tuple[np.ndarray, float]:
        return self.along_approach(ctx, est, ctx.cfg.approach.grasp_depth)

    def next(self, ctx: OpenerContext, est: JointAxisEstimate) -> OpenerPhase:
        return grasp.Close(ctx.move.reach_why)


class _Lift:
    """The lift from below's goal: the closed fingertips, pointing at the hinge and steeply down
    (:meth:`~agents.scripted.part_strategies.Lid.lift_pose`: once a lid's lip proved wider than the
    open fingers, every grasp of the episode lifts, whatever a later look shows); the plain grasp's
    goal when the grasp point lies on the hinge line."""

    under = False

    def lift_goal(self, ctx: OpenerContext, est: JointAxisEstimate) -> tuple[np.ndarray, float] | None:
        assert ctx.now is not None
        lid = Lid(ctx.cfg)
        lift = lid.lift_pose(est, ctx.now.r, under=self.under)
        if lift is None:
            return None
        goal, ctx.grasp.target_r = lift
        return keep_along_axis(ctx, est, goal, lid.along_slack(est)), GRIPPER_CLOSE


class LiftLineUp(_Lift, PreGrasp):
    """Lift from below, first move: the closed fingertips line up ``lid.lift.front`` in front of the lip."""

    def goal(self, ctx: OpenerContext, est: JointAxisEstimate) -> tuple[np.ndarray, float]:
        return self.lift_goal(ctx, est) or super().goal(ctx, est)


class LiftSlideUnder(_Lift, Approach):
    """Lift from below, second move: the fingertips slide in under the lip; then push it open (a pull)."""

    under = True

    def goal(self, ctx: OpenerContext, est: JointAxisEstimate) -> tuple[np.ndarray, float]:
        self._lifting = self.lift_goal(ctx, est)
        return self._lifting or super().goal(ctx, est)

    def next(self, ctx: OpenerContext, est: JointAxisEstimate) -> OpenerPhase:
        if self._lifting is not None:  # the closed fingertips are under the lid: push it open
            assert ctx.now is not None
            return pull.start_pull(ctx, ctx.now.p, ctx.now.r, est, "under")
        return super().next(ctx, est)


def keep_along_axis(ctx: OpenerContext, est: JointAxisEstimate, goal: np.ndarray, slack: float) -> np.ndarray:
    """``goal`` (3,) m moved along the estimated joint axis to the hand's own place there, by at most
    ``slack`` m: where the grip is a line along the axis (a lid's lip), a grasp point that slides along
    it from look to look does not drag the hand sideways."""
    if slack <= 0.0 or ctx.now is None:
        return goal
    u = unit(est.direction)
    offset = float((ctx.now.p - goal) @ u)
    return goal + u * float(np.clip(offset, -slack, slack))


def choose_grasp(ctx: OpenerContext, est: JointAxisEstimate, p: np.ndarray, r: np.ndarray,
                 arm_qpos: np.ndarray | None) -> None:
    """Choose the grasp for ``est`` (a new grasp when none is chosen): its part-kind strategy
    (:func:`~agents.scripted.part_strategies.strategy_for`, kept in ``ctx.grasp.strategy``) and the TCP
    rotation it gives, across the handle, the finger order nearer the hand's rotation unless the
    rehearsal prefers the other, turned a quarter or half turn as recoveries asked."""
    cfg, choice = ctx.cfg, ctx.grasp
    if choice.target_r is None:  # a new grasp (not a new choice for this one)
        choice.swap_this_grasp, choice.other_fingers = choice.other_fingers, False
        choice.pregrasp_steps = 1
    side = robot_side(ctx, est, p, r, arm_qpos)
    kind = strategy_for(est, cfg, side)
    target = kind.grasp_rotation(est, r, side)
    if choice.quarter:
        target = quarter_turn(target, r)
    if cfg.grasp.rehearse_fingers and arm_qpos is not None and kind.rehearses:
        target = rehearsed_fingers(ctx, kind, est, p, r, arm_qpos, target)
    if choice.swap_this_grasp:
        target = target @ SWAP_FINGERS
    choice.target_r = target
    choice.target_for = np.array(est.grasp_point, dtype=np.float64)
    choice.looks = [choice.target_for.copy()]
    choice.strategy, choice.kinds = kind, []


def robot_side(ctx: OpenerContext, est: JointAxisEstimate, p: np.ndarray, r: np.ndarray,
               arm_qpos: np.ndarray | None) -> np.ndarray:
    """Direction (3,) from ``est``'s grasp point to the robot's base: the base's position is recovered
    from the arm's joint angles and the TCP pose (``p`` (3,), ``r`` (3, 3)) and kept; without joint
    angles, the direction to the TCP (the hand comes from the robot's side)."""
    if arm_qpos is not None and ctx.base is None:
        ctx.base = base_in_world(np.asarray(arm_qpos, dtype=np.float64), pose_matrix(p, r))[:3, 3]
    towards = ctx.base if ctx.base is not None else p
    return np.asarray(towards, dtype=np.float64) - np.asarray(est.grasp_point, dtype=np.float64)


def grasp_point_moved(ctx: OpenerContext, est: JointAxisEstimate) -> bool:
    """Whether ``est``'s grasp point is more than ``approach.rechoose_grasp_m`` from the one the grasp
    orientation was chosen for, on each of the last ``approach.rechoose_looks`` looks (distinct
    estimates), which agree with each other within that distance (False before one is chosen or with
    ``rechoose_grasp_m`` 0)."""
    cfg, choice = ctx.cfg.approach, ctx.grasp
    if cfg.rechoose_grasp_m <= 0 or choice.target_r is None or choice.target_for is None:
        return False
    point = np.asarray(est.grasp_point, dtype=np.float64)
    if not choice.looks or float(np.linalg.norm(point - choice.looks[-1])) > 1e-9:
        # a new look; only the last rechoose_looks are ever compared
        choice.looks = [*choice.looks, point.copy()][-cfg.rechoose_looks:]
    recent = choice.looks
    if len(recent) < cfg.rechoose_looks:
        return False
    target_for = choice.target_for
    return all(float(np.linalg.norm(q - target_for)) > cfg.rechoose_grasp_m for q in recent) and all(
        float(np.linalg.norm(q - recent[-1])) <= cfg.rechoose_grasp_m for q in recent)


def out_of_fall_sweep(ctx: OpenerContext, kind: PartStrategy, est: JointAxisEstimate,
                      p: np.ndarray) -> np.ndarray | None:
    """Where the hand about to turn in place at TCP position ``p`` (3,) should move to first, unturned:
    for a grasp of strategy ``kind`` on a door that falls open
    (:attr:`~agents.scripted.part_strategies.PartStrategy.falls_open`), the point
    ``falling_door.clearance`` beyond the grasp radius about the estimated hinge, straight out from it,
    when ``p`` is nearer the hinge than that by more than ``move.pos_tolerance`` (None otherwise: turn
    in place). The robot's rest pose can put the hand against such a door's handle: turning there
    knocks the door, which falls onto the arm."""
    cfg = ctx.cfg.falling_door
    if cfg.done_above <= 0.0 or not kind.falls_open:
        return None
    goal = out_of_sweep(p, unit(est.direction), est.pivot, kind.grasp_target(est), cfg.clearance)
    if goal is None or float(np.linalg.norm(goal - p)) <= ctx.cfg.move.pos_tolerance:
        return None
    return goal


def part_kind_changed(ctx: OpenerContext, est: JointAxisEstimate) -> bool:
    """Whether, with ``approach.rechoose_part_kind``, ``est`` shows a part grasped otherwise (another
    ``grasp_kind`` of :func:`~agents.scripted.part_strategies.strategy_for`) than the grasp's strategy,
    on each of the last ``approach.rechoose_looks`` looks (a first look can tilt a door's hinge into a
    lid's)."""
    cfg, choice = ctx.cfg, ctx.grasp
    if not cfg.approach.rechoose_part_kind or choice.strategy is None:
        return False
    key = np.concatenate([est.grasp_point, est.direction]).astype(np.float64)
    if choice.kind_key is None or float(np.abs(key - choice.kind_key).max()) > 1e-9:  # a new look
        choice.kind_key = key
        choice.kinds = [*choice.kinds, strategy_for(est, cfg).grasp_kind][-cfg.approach.rechoose_looks:]
    chosen = choice.strategy.grasp_kind
    return len(choice.kinds) >= cfg.approach.rechoose_looks and all(k != chosen for k in choice.kinds)


def falling_on_its_own(ctx: OpenerContext, est: JointAxisEstimate) -> bool:
    """Whether, before its grasp, a part that ``est`` shows is a
    :class:`~agents.scripted.part_strategies.FallingDoor` is seen falling open: at least
    ``falling_door.settle_above`` open and risen by ``falling_door.progress`` over the last
    ``falling_door.window`` steps (``falling_door.watch`` and ``done_above`` > 0; never while lifting a
    lid)."""
    cfg = ctx.cfg.falling_door
    if not cfg.watch or cfg.done_above <= 0.0 or ctx.lift or not strategy_for(est, ctx.cfg).falls_open:
        ctx.watch = []
        return False
    ctx.watch.append(float(est.state))
    return ctx.watch[-1] >= cfg.settle_above and release.risen(ctx, ctx.watch)


def rehearse_grasp(ctx: OpenerContext, kind: PartStrategy, est: JointAxisEstimate, p: np.ndarray,
                   r: np.ndarray, arm_qpos: np.ndarray, rotation: np.ndarray) -> Rehearsal:
    """Grasp and pull with TCP ``rotation`` (3, 3) rehearsed on the arm's kinematic model, the pull
    to ``kind``'s target, the hand turning (and rolling, :meth:`~agents.scripted.part_strategies.
    PartStrategy.pull_rotation`) as ``kind`` turns it; first out of a falling door's sweep, as the
    pre-grasp moves (:func:`out_of_fall_sweep`)."""
    cfg = ctx.cfg
    approach = rotation[:, 2]
    point = est.grasp_point
    grasp_at = point + approach * cfg.approach.grasp_depth
    u = unit(est.direction)
    path: list[tuple[np.ndarray, np.ndarray]] = []
    revolute = est.joint_type == "revolute"
    target = kind.pull_target(revolute)
    if revolute:
        for delta in np.arange(0.05, max(target - float(est.state), 0.0) + 1e-9, 0.05):
            path.append((est.pivot + axis_angle_matrix(u, delta) @ (grasp_at - est.pivot),
                         kind.pulling_rotation(est, False, rotation, u, delta, delta)))
    else:
        for delta in np.arange(0.01, max(target - float(est.state), 0.0) + 1e-9, 0.01):
            path.append((grasp_at + u * delta, rotation))
    pregrasp_at = point - approach * cfg.approach.pregrasp_offset
    move = cfg.move
    return rehearse(arm_qpos, pose_matrix(p, r), rotation, pregrasp_at, grasp_at, path,
                    clear_at=out_of_fall_sweep(ctx, kind, est, p),
                    max_step_m=move.max_step_m, max_step_rad=move.max_step_rad,
                    rotate_first_above=cfg.approach.rotate_first_above,
                    rotate_first_steps=cfg.approach.rotate_first_steps, move_timeout=move.timeout_steps,
                    pos_tolerance=move.pos_tolerance, rot_tolerance=move.rot_tolerance,
                    pull_tolerance_m=cfg.grasp.rehearse_track_m,
                    pull_tolerance_rad=cfg.grasp.rehearse_track_rad)


def rehearsed_fingers(ctx: OpenerContext, kind: PartStrategy, est: JointAxisEstimate, p: np.ndarray,
                      r: np.ndarray, arm_qpos: np.ndarray, nearer: np.ndarray) -> np.ndarray:
    """``nearer`` (3, 3), or the same approach with the fingers swapped if the rehearsal says the arm
    reaches and pulls clearly better that way (``grasp.rehearse_fingers``): the other order reaches the
    grasp and follows either the whole pull while the nearer one does not, or at least
    ``grasp.rehearse_margin`` more of it. The second case is a hand pinned by a wrist joint early in
    both orders' pulls but at different places: about a vertical hinge, a grasp pitched down turns
    the hand partly about its approach axis, which only joint 7 gives; an order that starts with
    joint 7 near its limit (after a quarter turn, say) lets the hand's roll lag the door within a few
    tenths of a radian, and a lever held across the fingers twists out of them, while the other order
    starts half a turn away from that limit and follows most of the pull."""
    cfg = ctx.cfg
    other = nearer @ SWAP_FINGERS

    def reaches(x: Rehearsal) -> bool:
        return (x.grasp_error_m <= 2 * cfg.move.pos_tolerance
                and x.grasp_error_rad <= 2 * cfg.move.rot_tolerance)

    a = rehearse_grasp(ctx, kind, est, p, r, arm_qpos, nearer)
    b = rehearse_grasp(ctx, kind, est, p, r, arm_qpos, other)
    ctx.rehearsals = (a, b)
    if reaches(b) and ((b.pull_share >= 1.0 and not reaches(a))
                       or b.pull_share - a.pull_share >= cfg.grasp.rehearse_margin):
        return other
    return nearer
