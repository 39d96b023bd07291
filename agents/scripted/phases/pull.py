"""The pull: the held part is moved along its estimated arc (revolute) or line (prismatic), its state
measured by the hand's own travel every step (free of the perceived state's noise), the axis corrected
by the holding hand's path (``pull.arc_fit``) or the part's (``pull.motion_axis``). It ends at the
target, on a stall, at a prismatic part's end stop, or when the hand slips off. The grasp's part-kind
strategy (``ctx.grip``) gives the target, the lead, how far the hand turns, what counts towards a slip
and whether a stall far open is an end stop; the joint type the current look shows decides arc or
line."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from agents.scripted.geometry import axis_angle_matrix, fit_circle, off_axis, swept_angle
from agents.scripted.motion_axis import fit_motion_axis
from agents.scripted.part_strategies import PartStrategy, strategy_for
from agents.scripted.phases import grasp, reach, release
from agents.scripted.phases.base import (
    GRIPPER_CLOSE,
    GRIPPER_OPEN,
    OpenerPhase,
    Phase,
    goto,
    hold,
    wrist_at_limit,
)
from agents.scripted.phases.context import OpenerContext
from capt_env.wrappers.estimate import JointAxisEstimate, canonical_pivot, unit


def start_pull(ctx: OpenerContext, p: np.ndarray, r: np.ndarray, est: JointAxisEstimate, why: str) -> Pull:
    """Begin a pull from the TCP pose ``p`` (3,), ``r`` (3, 3) on ``est``: the phase to enter."""
    track = ctx.pull
    # the first pull counts from closed: a single view's state of a part no hand has moved yet can
    # read a closed door tens of degrees open, and the pull would stop that much short (tasks start
    # parts within a few percent of closed; one that starts open ends at its end stop instead)
    first = track.grasp_p is None
    track.grasp_p, track.grasp_r = p.copy(), r.copy()
    track.grasp_state = 0.0 if first else est.state
    track.grasp_u = unit(est.direction)
    track.grasp_pivot = np.asarray(est.pivot, dtype=np.float64).copy()
    track.grasp_seen = np.asarray(est.grasp_point, dtype=np.float64).copy()
    track.falls = strategy_for(est, ctx.cfg).falls_open
    track.history = []
    track.pulled = [p.copy()]
    track.held = [p.copy()]
    track.hinge_fit = None
    track.line_fit, track.line_gap, track.line_slipped = None, None, False
    track.slip_count = 0
    track.first_gap, track.prying = None, False
    track.step_share, track.last_q = 1.0, None
    # a hand lifting from below holds with closed fingers; unknown gaps count as holding
    return Pull(why, grip="held" if ctx.lift else "none")


class Pull(OpenerPhase):
    """Pull the part towards ``state now + lead`` every step; see the module docstring."""

    phase = Phase.PULL

    def step(self, ctx: OpenerContext) -> tuple[np.ndarray, OpenerPhase]:
        cfg, look, track = ctx.cfg, ctx.now, ctx.pull
        assert look is not None and track.grasp_p is not None and track.grasp_r is not None
        est, p, r, finger_gap, arm_qpos = look.est, look.p, look.r, look.finger_gap, look.arm_qpos
        grip = ctx.grip(est)
        revolute = est.joint_type == "revolute"
        u = unit(est.direction)
        if track.grasp_u is not None and float(u @ track.grasp_u) < 0.0:
            # the part opens the way it did when the pull began: a re-estimate that flips the axis
            # (the sign is what a single view gets wrong most) would read the opening as closing
            u = -u
        if not revolute:
            # one line per pull: a slide's line is fixed in the world, and the look before the hand
            # covered the part saw it best (later looks, the handle hidden, tilt it a few degrees,
            # and a hand pulling a few degrees off a sash's track slides off its bar), until the
            # holding hand's own path measures it
            u = held_line(ctx, u if track.grasp_u is None else track.grasp_u, p, finger_gap)
        if cfg.pull.motion_axis.enabled:
            u = motion_axis(ctx, est, u, p, r, finger_gap, revolute)
        # while the hand holds the part, its own travel along the estimated arc or line measures the
        # part's state every step; the perceived state is noisier and only as fresh as the last estimate
        # one arc per pull: the pivot the pull began with, replaced only by one the part's own motion
        # measures (arc_fit, motion_axis). A later look's pivot would re-read the whole path's angle
        # and move the arc's goal with it: a look that segments the lid as the base, half-way open,
        # puts the pivot 25 cm off and reads the lid at its target
        if ctx.axis.motion is not None:
            pivot = ctx.axis.motion.pivot
        else:
            assert track.grasp_pivot is not None
            pivot = hinge_pivot(ctx, u, track.grasp_pivot, p, finger_gap) if revolute else track.grasp_pivot
        state = hand_state(ctx, u, pivot, p, revolute)
        track.history.append(state)
        track.pulled.append(p.copy())
        # a drawer runs freely up to its end stop, where the hand brakes before the handle slides out
        # of the fingers: that is the limit, and grasping again would chase a part that is open
        at_limit = not revolute and braked(ctx)
        target = grip.pull_target(revolute)
        min_progress = cfg.pull.revolute.stall_progress if revolute else cfg.pull.prismatic.stall_progress
        # progress over the last stall_steps, measured about the pivot in use now (arc_fit may
        # have moved it, which changes the state read along the whole path, not the part's motion)
        stalled = False
        if len(track.pulled) > cfg.pull.stall_steps + 1:
            before = track.pulled[-1 - cfg.pull.stall_steps]
            progress = (swept_angle(u, pivot, before, p) if revolute else float((p - before) @ u))
            stalled = progress < min_progress
        holding = finger_gap is not None and finger_gap >= cfg.grasp.hold_gap
        record_grip(ctx, holding, finger_gap is None)
        note_prying(ctx, finger_gap if holding else None)
        falls = release.lets_fall(ctx)
        fall = cfg.falling_door
        if state >= target or stalled or at_limit:
            why = "target" if state >= target else "stall" if stalled else "limit"
            # short of the target the grip slipped or the arm ran out of range: grasp again from here
            ctx.grasp_again = state < target and not at_limit and ctx.regrasps < cfg.recovery.max_regrasps
            wrist_stuck = stalled and wrist_at_limit(arm_qpos, cfg.recovery.wrist_limit_margin)
            if falls and min(state, float(est.state)) >= fall.done_above:
                # a door that falls open, past done_above: grasping it again pushes it back. Both the
                # hand and the perception must say so: fingers slipping along the handle carry the
                # hand round the arc ahead of the door
                ctx.grasp_again = False
            stop_above, open_above = cfg.pull.revolute.stop_above, cfg.pull.revolute.open_above
            end_stop = (0.0 < stop_above <= state
                        and (not wrist_stuck if holding else stop_above <= float(est.state)))
            if (stalled and revolute and grip.stall_can_be_end_stop and not falls
                    and (end_stop or 0.0 < open_above <= min(state, float(est.state)))):
                # far open: the part is at its end stop, and reaching for the handle again would knock
                # it back. Held, the hand's measure says so unless a wrist joint at its limit stopped
                # the arm; let go, the hand carried on along the arc past the stopped part and slid
                # off its handle (pinning the wrist as it went), so the part as seen must say so too.
                # Past a quarter turn, by both measures, the part is open whatever stopped the arm
                ctx.grasp_again = False
            ctx.regrasps += int(ctx.grasp_again)
            ctx.let_go_state = state
            if not ctx.grasp_again and holding and falls_back(ctx, u, revolute):
                # let go, a part lifted against gravity slides back closed: hold it where it is
                ctx.hold_at = (p.copy(), r.copy())
                return hold(GRIPPER_CLOSE), release.Done(why)
            if ctx.grasp_again and wrist_stuck:
                # the arm ran out of range with this finger order: the other one turns the wrist the
                # other way
                ctx.grasp.other_fingers = True
            return hold(GRIPPER_CLOSE), release.Release(why)
        away = grip.slip_offset(p - np.asarray(est.grasp_point, dtype=np.float64), u)
        far = float(np.linalg.norm(away)) > cfg.pull.slip_distance and not holding
        behind = grip.slip_behind(ctx.lift)
        if far and behind > 0.0:
            # lifting, the closed fingers tell no gap: the perceived lid must also lag the hand
            far = state - float(est.state) > behind
        track.slip_count = track.slip_count + 1 if far else 0
        slipped = track.slip_count >= cfg.pull.slip_steps
        if slipped and ctx.phase_log[-1].get("grip") == "held":
            ctx.phase_log[-1]["grip"] = "lost"  # (a lift's closed fingers tell no gap)
        if slipped and falls and est.state >= fall.settle_above:
            # off the handle of a door that falls open: let go, clear it and wait instead of reaching
            # for a handle on the move; past done_above it is left open
            ctx.grasp_again = est.state < fall.done_above and ctx.regrasps < cfg.recovery.max_regrasps
            ctx.regrasps += int(ctx.grasp_again)
            ctx.let_go_state = float(est.state)
            return hold(GRIPPER_OPEN), release.Release("slip")
        if slipped and not revolute and 0.0 < cfg.pull.prismatic.stop_above <= state:
            # off the handle of a drawer pulled far out: it ran to its end stop and the brake was
            # missed; reaching for the handle again would push the open drawer back in
            ctx.grasp_again = False
            ctx.let_go_state = state
            return hold(GRIPPER_OPEN), release.Release("slip")
        if slipped and ctx.regrasps < cfg.recovery.max_regrasps:
            ctx.regrasps += 1
            ctx.grasp.target_r = None
            if unmoved(ctx, est) and grip.turns_fingers_on_miss and cfg.recovery.other_fingers:
                # the hand ran off while the part stayed put: the fingers held the end of a bar lying
                # along them, not the bar; grasp again turned, as after fingers closed on nothing
                grasp.turn_fingers(ctx, arm_qpos)
            return hold(GRIPPER_OPEN), reach.pregrasp(ctx, "slip")
        p_des, r_des = pull_pose(ctx, grip, est, u, pivot, state, revolute, p)
        action, _, _ = goto(ctx, p, r, p_des, r_des, GRIPPER_CLOSE)
        action[:6] *= step_share(ctx, arm_qpos)
        return action, self


def unmoved(ctx: OpenerContext, est: JointAxisEstimate) -> bool:
    """Whether the part's grasp point as seen in ``est`` lies within ``recovery.unmoved`` m of where it
    was seen when the pull began (0: never)."""
    limit, seen = ctx.cfg.recovery.unmoved, ctx.pull.grasp_seen
    if limit <= 0.0 or seen is None:
        return False
    return float(np.linalg.norm(np.asarray(est.grasp_point, dtype=np.float64) - seen)) < limit


def step_share(ctx: OpenerContext, arm_qpos: np.ndarray | None) -> float:
    """The share of the commanded TCP step this pull step moves by: 1, shrunk by ``pull.step_shrink``
    (down to ``pull.min_step_share``, kept for the rest of the pull) after each step that left every
    arm joint within ``pull.frozen_joints`` rad of where it was (``arm_qpos`` (7,) rad; None: unknown).
    A pull that leads the part near the edge of the arm's reach (a door swung far round, the elbow near
    straight) asks for a step the controller's IK does not converge on, and the controller holds the
    arm still, step after step; a shorter step converges."""
    cfg, track = ctx.cfg.pull, ctx.pull
    q = None if arm_qpos is None else np.asarray(arm_qpos, dtype=np.float64).reshape(-1)[:7]
    if (cfg.frozen_joints > 0.0 and q is not None and track.last_q is not None
            and float(np.abs(q - track.last_q).max()) < cfg.frozen_joints):
        track.step_share = max(track.step_share * cfg.step_shrink, cfg.min_step_share)
    track.last_q = q
    return track.step_share


def pull_pose(ctx: OpenerContext, grip: PartStrategy, est: JointAxisEstimate, u: np.ndarray,
              pivot: np.ndarray, state: float, revolute: bool,
              p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The TCP goal (position (3,), rotation (3, 3)) of a pull step: the grasp pose moved with the part
    to ``state + lead``, rotated about unit axis ``u`` through ``pivot`` (moved towards it by the
    strategy ``grip``'s inward slide and press from the hand's position ``p`` (3,); the hand turned by
    its share and then by the strategy's
    :meth:`~agents.scripted.part_strategies.PartStrategy.pull_rotation`) or shifted along ``u``."""
    cfg, track = ctx.cfg, ctx.pull
    assert track.grasp_p is not None and track.grasp_r is not None
    if not revolute:
        delta = state - track.grasp_state + cfg.pull.prismatic.lead
        return track.grasp_p + u * delta, track.grasp_r
    delta = state - track.grasp_state + grip.pull_lead(ctx.lift)
    p_des = pivot + axis_angle_matrix(u, delta) @ (track.grasp_p - pivot)
    inward = grip.inward(ctx.lift)
    if inward > 0.0:
        # lifting from below, the fingertips slide towards the hinge as the lid turns: off the lid's
        # own arc (an estimated hinge a centimetre or two off), they stay under it
        radial = off_axis(p_des - pivot, u)
        radius = float(np.linalg.norm(radial))
        if radius > 1e-6:
            p_des = p_des - min(inward * max(delta, 0.0), 0.5 * radius) * radial / radius
    press = grip.press(ctx.lift)
    if press > 0.0:
        # pushing from below, the fingertips stay pressed into the lid's front face from wherever
        # they are: the estimated arc alone runs off the face as the lid turns
        p_des = pressed(p_des, p, pivot, u, press)
    turned = state - track.grasp_state
    return p_des, grip.pulling_rotation(est, ctx.lift, track.grasp_r, u, delta, turned, track.prying)


def note_prying(ctx: OpenerContext, held_gap: float | None) -> None:
    """Latch ``ctx.pull.prying`` once the gap of the fingers holding the part (``held_gap`` m; None:
    not holding) is more than ``side_door.pry_gap`` wider than at the first held step of this pull:
    a bar turning between the pads pushes them apart before it levers out of them."""
    track, limit = ctx.pull, ctx.cfg.side_door.pry_gap
    if held_gap is None or limit <= 0.0:
        return
    if track.first_gap is None:
        track.first_gap = held_gap
    track.prying = track.prying or held_gap - track.first_gap > limit


def pressed(p_des: np.ndarray, p: np.ndarray, pivot: np.ndarray, u: np.ndarray, press: float) -> np.ndarray:
    """``p_des`` (3,) moved along its radius about the axis (unit ``u``, through ``pivot``) so that it
    lies at least ``press`` m nearer the axis than the hand ``p`` (3,) is now, and at most
    ``2 * press`` nearer than ``p_des`` was (world frame, metres)."""
    radial = off_axis(p_des - pivot, u)
    rho_des = float(np.linalg.norm(radial))
    if rho_des < 1e-6:
        return p_des
    rho_now = float(np.linalg.norm(off_axis(p - pivot, u)))
    rho = max(min(rho_des, rho_now - press), rho_des - 2.0 * press)
    return p_des + (rho - rho_des) * radial / rho_des


def record_grip(ctx: OpenerContext, holding: bool, unknown: bool) -> None:
    """Record in this pull's ``phase_log`` entry whether the fingers hold the part: its ``"grip"`` is
    ``"none"`` until the finger gap first reads at least ``grasp.hold_gap`` (``holding``), then
    ``"held"``, and ``"lost"`` once the fingers have closed on nothing after holding (or the slip check
    fires on a hand lifting from below, whose closed fingers tell no gap). Without a gap (``unknown``)
    a pull counts as held."""
    entry = ctx.phase_log[-1]
    if unknown:
        if entry.get("grip") == "none":
            entry["grip"] = "held"
    elif holding:
        entry["grip"] = "held"
    elif entry.get("grip") == "held" and not ctx.lift:
        entry["grip"] = "lost"


def falls_back(ctx: OpenerContext, u: np.ndarray, revolute: bool) -> bool:
    """Whether a prismatic part opening along unit ``u`` (3,) rises more than
    ``sliding_panel.hold_rising_above`` above horizontal, so that gravity slides it back closed once
    let go (a window sliding up; 0: never)."""
    rise = ctx.cfg.sliding_panel.hold_rising_above
    return not revolute and rise > 0.0 and float(u[2]) > float(np.sin(rise))


def braked(ctx: OpenerContext) -> bool:
    """Whether the hand, pulling at a cruising speed (median step of this pull, at least
    ``limit_min_speed_m``), moved less than ``limit_slowdown`` of it in each of the last
    ``limit_window`` steps under the same command (``pull.prismatic``): something stopped the part."""
    cfg = ctx.cfg.pull.prismatic
    steps = np.diff(ctx.pull.history)
    if len(steps) < cfg.limit_window + 5:
        return False
    cruise = float(np.median(steps[:-cfg.limit_window]))
    recent = steps[-cfg.limit_window:]
    return cruise >= cfg.limit_min_speed_m and bool(np.all(recent < cfg.limit_slowdown * cruise))


def hand_state(ctx: OpenerContext, u: np.ndarray, pivot: np.ndarray, p: np.ndarray, revolute: bool) -> float:
    """The part's state (rad or m) by the hand's own measure: the state at the grasp plus the TCP's
    travel from the grasp position to ``p`` about (revolute) or along unit axis ``u``."""
    track = ctx.pull
    assert track.grasp_p is not None
    if revolute:
        return track.grasp_state + swept_angle(u, pivot, track.grasp_p, p)
    return track.grasp_state + float((p - track.grasp_p) @ u)


def hinge_pivot(ctx: OpenerContext, u: np.ndarray, pivot: np.ndarray, p: np.ndarray,
                finger_gap: float | None) -> np.ndarray:
    """The pivot (3,) to pull about: the centre of the circle the holding hand's path follows about
    unit axis ``u`` when ``pull.arc_fit`` accepts it, else the estimated ``pivot``. ``p``: the TCP
    position now, added to the path while the fingers hold."""
    cfg, track = ctx.cfg.pull.arc_fit, ctx.pull
    if not cfg.enabled or finger_gap is None or finger_gap < ctx.cfg.grasp.hold_gap:
        return pivot
    if track.hinge_fit is not None:
        return track.hinge_fit
    track.held.append(p.copy())
    path = np.asarray(track.held)
    if (np.linalg.norm(path - path[0], axis=1).max() < cfg.min_chord
            or abs(swept_angle(u, pivot, path[0], p)) < cfg.min_angle):
        return pivot
    fit = fit_circle(path, u)
    if fit is None or fit[2] > cfg.max_rms:
        return pivot
    offset = fit[0] - pivot
    if np.linalg.norm(off_axis(offset, u)) > cfg.max_shift:
        return pivot
    # kept for the rest of the pull: a hand that later slips off the handle leaves the arc
    track.hinge_fit = fit[0]
    return fit[0]


def held_line(ctx: OpenerContext, u: np.ndarray, p: np.ndarray, finger_gap: float | None) -> np.ndarray:
    """The unit direction (3,) to pull a sliding part along: the line fitted to the path of the hand
    holding it (``p``, the TCP position (3,) m now, is added while the fingers hold) once it spans
    ``pull.prismatic.track_fit_travel`` and fits (:func:`~agents.scripted.motion_axis.fit_motion_axis`),
    signed like the estimated unit ``u``; before that, ``u``. The part's track carries the held hand
    along itself, so the path measures the track however far off the estimate was. The path counts
    until the finger gap jumps (``track_fit_max_gap_change``): the part slipping out of the fingers."""
    cfg, track = ctx.cfg.pull.prismatic, ctx.pull
    holding = finger_gap is not None and finger_gap >= ctx.cfg.grasp.hold_gap
    if holding and finger_gap is not None:
        if track.line_gap is not None and abs(finger_gap - track.line_gap) > cfg.track_fit_max_gap_change:
            track.line_slipped = True
        track.line_gap = finger_gap
    if cfg.track_fit_travel > 0.0 and holding and not track.line_slipped:
        track.held.append(p.copy())
        fit = fit_motion_axis(np.asarray(track.held), u, p, False, cfg.track_fit_travel, 0.0,
                              cfg.track_fit_max_rms, cfg.track_fit_max_turn)
        if fit is not None:
            track.line_fit = fit.direction
    if track.line_fit is None:
        return u
    return track.line_fit if float(track.line_fit @ u) >= 0.0 else -track.line_fit


def motion_axis(ctx: OpenerContext, est: JointAxisEstimate, u: np.ndarray, p: np.ndarray, r: np.ndarray,
                finger_gap: float | None, revolute: bool) -> np.ndarray:
    """The axis direction to pull along (``pull.motion_axis``): the one fitted to the path of the
    estimated grasp point while held (:func:`~agents.scripted.motion_axis.fit_motion_axis`), once it
    fits, else ``u``. The first accepted fit is kept for the episode (later pulls too) and starts this
    pull over from where the hand is, so the arc or line it follows does not jump."""
    cfg, track, axis = ctx.cfg.pull.motion_axis, ctx.pull, ctx.axis
    holding = finger_gap is not None and finger_gap >= ctx.cfg.grasp.hold_gap
    gp = np.asarray(est.grasp_point, dtype=np.float64)
    if holding and (not axis.part_path or np.linalg.norm(gp - axis.part_path[-1]) > 1e-3):
        axis.part_path.append(gp.copy())  # a new estimate (they repeat between looks)
    if axis.motion is None and holding:
        pivot = track.hinge_fit if track.hinge_fit is not None else track.grasp_pivot
        fit = fit_motion_axis(np.asarray(axis.part_path), u, pivot, revolute, cfg.min_travel, cfg.min_angle,
                              cfg.max_rms, cfg.max_turn, cfg.max_ratio, cfg.hinge_points if revolute else 3)
        if fit is not None:
            track.grasp_state = hand_state(ctx, u, pivot, p, revolute)
            track.grasp_p, track.grasp_r, track.grasp_u = p.copy(), r.copy(), fit.direction
            track.pulled, track.held, track.hinge_fit = [p.copy()], [p.copy()], None
            axis.motion, axis.motion_type = fit, est.joint_type
    if axis.motion is None:
        return u
    direction = axis.motion.direction
    return direction if float(direction @ u) >= 0.0 else -direction


def with_motion_axis(ctx: OpenerContext, est: JointAxisEstimate) -> JointAxisEstimate:
    """``est`` with the axis fitted to the part's motion (signed like ``est``'s direction; a revolute
    pivot moved to the point of the fitted line closest to the grasp point)."""
    assert ctx.axis.motion is not None
    direction = ctx.axis.motion.direction
    if float(direction @ est.direction) < 0.0:
        direction = -direction
    pivot = est.pivot
    if est.joint_type == "revolute":
        grasp = np.asarray(est.grasp_point, dtype=np.float64)
        pivot = canonical_pivot(direction, ctx.axis.motion.pivot, grasp)
    return replace(est, direction=direction, pivot=pivot)
