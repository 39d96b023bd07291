"""Why a scripted opening failed, named from the opener's own phase log (``ScriptedOpener.phase_log``)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

# the causes failure_cause names, in the order tables list them
CAUSES = ("no grasp found", "grasp missed", "slipped", "stalled", "stopped short", "step limit")


def failure_cause(phase_log: Sequence[dict[str, Any]], success: bool) -> str | None:
    """The cause of a failed episode from its phase log, or None for a success or an empty log (a
    policy that keeps none).

    ``phase_log``: :class:`~agents.scripted.opener.ScriptedOpener`'s entries, one per phase entered,
    ``{"step", "phase", "why"}``, a pull's entry with its ``"grip"`` (``"none"``: the finger gap never
    read ``hold_gap``; ``"held"``: holding when the pull ended; ``"lost"``: held, then closed on nothing).
    The pull that decides is the last one whose fingers ever held the part; ``why`` of the entry after
    it says what ended it (``"target"``, ``"stall"``, ``"limit"``, ``"slip"``).

    - ``no grasp found``: the fingers never closed at a grasp point (no ``close`` phase and no lift
      from below): the approach did not end within the episode.
    - ``grasp missed``: they closed, but no pull ever held the part (fingers closed on nothing).
    - ``slipped``: the deciding pull lost the part (the fingers closed on nothing after holding it,
      or the hand drifted off the grasp point).
    - ``stalled``: the deciding pull still held the part when it stopped for lack of progress
      (``stall``) or at a perceived end stop (``limit``): the part did not move (or no further).
    - ``stopped short``: the deciding pull still held the part when the hand's own measure of the
      part's state reached the opener's target, yet the part was not open enough: the target was
      counted from a wrong state at the grasp, or the hand moved without moving the part as much.
    - ``step limit``: the episode ended while the deciding pull still held the part and was going on.
    """
    if success or not phase_log:
        return None
    phases = [entry["phase"] for entry in phase_log]
    if "close" not in phases and not any(e["phase"] == "pull" and e["why"] == "under" for e in phase_log):
        return "no grasp found"
    held = [i for i, e in enumerate(phase_log) if e["phase"] == "pull" and e.get("grip", "none") != "none"]
    if not held:
        return "grasp missed"
    i = held[-1]
    if phase_log[i]["grip"] == "lost":
        return "slipped"
    if i == len(phase_log) - 1:
        return "step limit"
    ended_by = phase_log[i + 1]["why"]
    if ended_by == "slip":
        return "slipped"
    if ended_by == "target":
        return "stopped short"
    return "stalled"


def count_causes(causes: Sequence[str | None]) -> dict[str, int]:
    """Failed episodes per cause (every cause of :data:`CAUSES` present, zeros included; None, a
    success, is not counted)."""
    counts = {cause: 0 for cause in CAUSES}
    for cause in causes:
        if cause is not None:
            counts[cause] = counts.get(cause, 0) + 1
    return counts
