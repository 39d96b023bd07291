"""After a pull: open the fingers, back off, and then grasp again, be done, or (a door that gravity
opens) clear the door's sweep and wait while it falls; and the done hand, which holds still (or holds
a part that would fall back closed)."""

from __future__ import annotations

import numpy as np

from agents.scripted.geometry import out_of_sweep
from agents.scripted.phases import reach
from agents.scripted.phases.base import GRIPPER_CLOSE, GRIPPER_OPEN, OpenerPhase, Phase, goto, hold, reached
from agents.scripted.phases.context import OpenerContext
from capt_env.wrappers.estimate import unit


class Release(OpenerPhase):
    """Open the gripper for ``release.steps``; then retreat."""

    phase = Phase.RELEASE

    def step(self, ctx: OpenerContext) -> tuple[np.ndarray, OpenerPhase]:
        assert ctx.now is not None
        action = hold(GRIPPER_OPEN)
        if ctx.phase_steps >= ctx.cfg.release.steps:
            ctx.retreat_from = ctx.now.p.copy()
            return action, Retreat("released")
        return action, self


class Retreat(OpenerPhase):
    """Back off ``release.retreat_distance`` along the approach axis (until there, blocked or timed out);
    then wait for a falling door, grasp again (a re-grasp: a fresh pre-grasp from the part's new pose),
    or be done."""

    phase = Phase.RETREAT

    def step(self, ctx: OpenerContext) -> tuple[np.ndarray, OpenerPhase]:
        look = ctx.now
        assert look is not None and ctx.retreat_from is not None
        p, r = look.p, look.r
        goal = ctx.retreat_from - r[:, 2] * ctx.cfg.release.retreat_distance
        action, perr, _ = goto(ctx, p, r, goal, r, GRIPPER_OPEN)
        if not reached(ctx, p, perr, 0.0):  # there, timed out, or blocked (the arm's range)
            return action, self
        # (a pull's end sets the state it let go at; fingers that closed on nothing do not)
        let_go, ctx.let_go_state = ctx.let_go_state, 0.0
        if lets_fall(ctx) and let_go >= ctx.cfg.falling_door.settle_above:
            ctx.settle = []  # clear the door's sweep, wait while it falls, then decide
            return action, WaitForFall(None)
        if ctx.grasp_again:
            return action, regrasp(ctx)
        return action, Done("retreated")


def regrasp(ctx: OpenerContext) -> OpenerPhase:
    """Grasp again: a new grasp (its orientation chosen afresh) from the pre-grasp."""
    ctx.grasp_again = False
    ctx.grasp.target_r = None
    return reach.pregrasp(ctx, "regrasp")


class WaitForFall(OpenerPhase):
    """After letting go of a door that falls open, at least ``falling_door.settle_above`` open (or one
    seen falling before its grasp): move the open hand out of its sweep, to ``falling_door.clearance``
    beyond the grasp radius about the estimated hinge, and wait while the perceived state still rises
    (by ``falling_door.progress`` over ``falling_door.window`` steps; at most ``max_steps``). Then grasp
    again if the pull ended short of its target and the state is still short of ``done_above``, else
    done. Reported as the retreat it continues."""

    phase = Phase.RETREAT

    def step(self, ctx: OpenerContext) -> tuple[np.ndarray, OpenerPhase]:
        cfg, look = ctx.cfg.falling_door, ctx.now
        assert look is not None and ctx.settle is not None and ctx.pull.grasp_p is not None
        est, p, r = look.est, look.p, look.r
        goal = out_of_sweep(p, unit(est.direction), est.pivot, ctx.pull.grasp_p, cfg.clearance)
        action, _, _ = goto(ctx, p, r, p if goal is None else goal, r, GRIPPER_OPEN)
        ctx.settle.append(float(est.state))
        states = ctx.settle
        rising = len(states) <= cfg.window or risen(ctx, states)
        if rising and len(states) < cfg.max_steps:
            return action, self
        ctx.settle = None
        again, ctx.grasp_again = ctx.grasp_again and est.state < cfg.done_above, False
        if again:
            ctx.grasp.target_r = None
            return action, reach.pregrasp(ctx, "regrasp")
        return action, Done("settled")


class Done(OpenerPhase):
    """Hold still with the gripper open, or hold the part at ``ctx.hold_at`` with the fingers closed
    (let go, it would fall back closed)."""

    phase = Phase.DONE

    def step(self, ctx: OpenerContext) -> tuple[np.ndarray, OpenerPhase]:
        assert ctx.now is not None
        if ctx.hold_at is not None:  # keep the hand, and the part it holds, where the pull ended
            return goto(ctx, ctx.now.p, ctx.now.r, *ctx.hold_at, GRIPPER_CLOSE)[0], self
        return hold(GRIPPER_OPEN), self


def risen(ctx: OpenerContext, states: list[float]) -> bool:
    """Whether the last of ``states`` (rad, one per step) is ``falling_door.progress`` above the one
    ``falling_door.window`` steps before (False with fewer states than that)."""
    cfg = ctx.cfg.falling_door
    return len(states) > cfg.window and states[-1] - states[-1 - cfg.window] >= cfg.progress


def lets_fall(ctx: OpenerContext) -> bool:
    """Whether to let the part being pulled fall open when the hand loses it: it
    :func:`~agents.scripted.grasp_pose.falls_open` by the estimate the pull began with (one of a door
    near level, its handle hidden by the hand, can be far off) and ``falling_door.done_above`` > 0."""
    return ctx.cfg.falling_door.done_above > 0.0 and ctx.pull.falls
