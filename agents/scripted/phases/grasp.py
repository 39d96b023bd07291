"""Closing the fingers on the handle, and what the finger gap then says: held (pull), or closed on
nothing (what then is the grasp's part-kind strategy's: a lid's lip is lifted from below, other parts
are grasped again with the fingers turned)."""

from __future__ import annotations

import numpy as np

from agents.scripted.phases import pull, release
from agents.scripted.phases.base import GRIPPER_CLOSE, OpenerPhase, Phase, hold, wrist_at_limit
from agents.scripted.phases.context import OpenerContext


class Close(OpenerPhase):
    """Close the gripper for ``grasp.close_steps``; then pull, or recover from an empty grasp."""

    phase = Phase.CLOSE

    def step(self, ctx: OpenerContext) -> tuple[np.ndarray, OpenerPhase]:
        cfg, look = ctx.cfg, ctx.now
        assert look is not None
        action = hold(GRIPPER_CLOSE)
        if ctx.phase_steps < cfg.grasp.close_steps:
            return action, self
        gap = look.finger_gap
        empty = gap is not None and gap < cfg.grasp.hold_gap
        grip = ctx.grip(look.est)
        if grip.lifts_from_below(ctx.lift) and empty:
            # the fingers closed on nothing across the lid's lip (wider than the open fingers): back
            # off, then lift the lid from below
            ctx.lift = ctx.grasp_again = True
            return action, release.Release("empty")
        if (grip.turns_fingers_on_miss and cfg.recovery.other_fingers and empty
                and ctx.regrasps < cfg.recovery.max_regrasps):
            assert gap is not None
            # the fingers closed on nothing: back off and grasp again, the fingers turned
            ctx.regrasps += 1
            ctx.grasp_again = True
            turn_fingers(ctx, look.arm_qpos)
            return action, release.Release("empty", gap=round(gap, 4))
        started = pull.start_pull(ctx, look.p, look.r, look.est, "empty" if empty else "closed")
        if gap is not None:
            started.log_extra["gap"] = round(gap, 4)
        return action, started


def turn_fingers(ctx: OpenerContext, arm_qpos: np.ndarray | None) -> None:
    """Turn the next grasp's fingers after one that held nothing it could pull (``arm_qpos`` (7,) rad
    or None: the arm now). If the approach timed out or a wrist joint is at its limit, the arm stopped
    short of the handle (a low handle can put one there in one of the two finger orders): the fingers
    the other way round. Otherwise the hand was at the handle (there, or stopped by touching it), which
    does not lie across the fingers (a lever or bar at right angles to the one expected): a quarter
    turn on (``recovery.quarter_turn``)."""
    cfg, choice = ctx.cfg, ctx.grasp
    short = ctx.move.reach_why == "timeout" or wrist_at_limit(arm_qpos, cfg.recovery.wrist_limit_margin)
    if not cfg.recovery.quarter_turn or short:
        choice.other_fingers = True
    else:
        choice.quarter = not choice.quarter
