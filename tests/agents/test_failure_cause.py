"""A failed episode's cause is named from the scripted opener's phase log."""

from __future__ import annotations

from typing import Any

import numpy as np

from agents.scripted import ScriptedOpener, ScriptedOpenerConfig
from agents.scripted.failure_cause import CAUSES, count_causes, failure_cause
from agents.scripted.opener import Phase
from agents.scripted.phases.grasp import Close
from capt_env.wrappers.estimate import JointAxisEstimate


def _log(*entries: str) -> list[dict[str, Any]]:
    """A phase log from ``"phase:why"`` or ``"pull:why:grip"`` entries, one step apart."""
    log = []
    for step, text in enumerate(entries):
        phase, why, *grip = text.split(":")
        log.append({"step": step, "phase": phase, "why": why, **({"grip": grip[0]} if grip else {})})
    return log


GRASP = ("pregrasp:start", "approach:reached", "close:reached")


def test_a_success_has_no_cause() -> None:
    assert failure_cause(_log(*GRASP, "pull:closed:held", "release:target"), success=True) is None
    assert failure_cause([], success=False) is None  # a policy that keeps no log


def test_an_approach_that_never_ended_found_no_grasp() -> None:
    assert failure_cause(_log("pregrasp:start", "approach:timeout"), False) == "no grasp found"


def test_fingers_that_only_ever_closed_on_nothing_missed_the_grasp() -> None:
    log = _log(*GRASP, "release:empty", "retreat:released", "pregrasp:regrasp", "approach:blocked",
               "close:blocked", "pull:empty:none", "release:limit", "retreat:released")
    assert failure_cause(log, False) == "grasp missed"


def test_a_pull_that_lost_the_part_slipped_even_if_a_later_grasp_missed() -> None:
    log = _log(*GRASP, "pull:closed:lost", "pregrasp:slip", "approach:reached", "close:reached",
               "pull:empty:none", "release:stall")
    assert failure_cause(log, False) == "slipped"
    # a lid lifted from below (closed fingers) that slid off it
    assert failure_cause(_log("pregrasp:start", "approach:reached", "pull:under:lost", "pregrasp:slip"),
                         False) == "slipped"


def test_a_part_that_did_not_move_under_a_holding_hand_stalled() -> None:
    assert failure_cause(_log(*GRASP, "pull:closed:held", "release:stall", "retreat:released",
                              "done:retreated"), False) == "stalled"
    assert failure_cause(_log(*GRASP, "pull:closed:held", "release:limit"), False) == "stalled"


def test_a_pull_that_reached_its_target_by_the_hands_measure_stopped_short() -> None:
    assert failure_cause(_log(*GRASP, "pull:closed:held", "release:target", "retreat:released",
                              "done:retreated"), False) == "stopped short"


def test_a_pull_still_holding_and_going_at_the_end_ran_out_of_steps() -> None:
    assert failure_cause(_log(*GRASP, "pull:closed:held"), False) == "step limit"


def test_causes_are_counted_with_every_cause_listed() -> None:
    counts = count_causes(["slipped", None, "slipped", "stalled"])
    assert list(counts) == list(CAUSES)
    assert counts["slipped"] == 2 and counts["stalled"] == 1 and sum(counts.values()) == 3


def test_the_opener_logs_each_phase_and_whether_its_pull_holds() -> None:
    # a drawer sliding along -x, the hand at its handle
    est = JointAxisEstimate("prismatic", np.array([-1.0, 0.0, 0.0]), np.zeros(3), 0.0,
                            np.array([-0.2, 0.0, 0.3]))
    cfg = ScriptedOpenerConfig()
    opener = ScriptedOpener(cfg)
    pose = np.array([-0.2, 0.0, 0.3, 0.0, 1.0, 0.0, 0.0])
    opener.act_on(est, pose)
    opener.enter(Close("reached"))
    for _ in range(cfg.grasp.close_steps):
        opener.act_on(est, pose, finger_gap=0.02)
    assert opener.phase == Phase.PULL and opener.phase_log[-1]["grip"] == "none"
    opener.act_on(est, pose, finger_gap=0.02)
    assert opener.phase_log[-1]["grip"] == "held"
    opener.act_on(est, pose, finger_gap=0.0)  # the fingers closed on nothing: the handle slid out
    assert opener.phase_log[-1]["grip"] == "lost"
    assert [e["phase"] for e in opener.phase_log] == ["pregrasp", "close", "pull"]
    assert opener.phase_log[-1]["step"] == 1 + cfg.grasp.close_steps
