"""Typed config of the scripted opener: one nested dataclass per part of the method (world frame;
metres, radians, control steps at 20 Hz).

``ScriptedOpenerConfig`` groups the options by what they govern: ``move`` (every straight move of the
hand), ``approach`` (the pre-grasp and the approach), ``grasp`` (closing the fingers and choosing the
finger order), ``pull``, ``release``, ``recovery`` (grasping again), and one group per part kind whose
rules differ (``side_door``, ``lid``, ``falling_door``, ``drawer``, ``sliding_panel``; each read by its
strategy in :mod:`agents.scripted.part_strategies`). Each option's
docstring says why it has its value. YAML files mirror the tree (``approach: {pitch: 0.55}``); the
flat keys of earlier releases (``approach_pitch: 0.55``) still load, mapped by :data:`LEGACY_KEYS`
with a warning (see :func:`upgrade_legacy_keys`). The traced episodes behind the defaults are in
``docs/scripted_opener.md``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, fields, is_dataclass
from typing import Any

import numpy as np

from capt_common.typed_yaml import require


def _positive(obj: Any, *keys: str, where: str = "") -> None:
    for key in keys:
        value = getattr(obj, key)
        require(value > 0, f"{where}{key} must be > 0, got {value}")


def _at_least_one(obj: Any, *keys: str, where: str = "") -> None:
    for key in keys:
        value = getattr(obj, key)
        require(value >= 1, f"{where}{key} must be >= 1, got {value}")


def _non_negative(obj: Any, *keys: str, where: str = "", note: str = "") -> None:
    for key in keys:
        value = getattr(obj, key)
        require(value >= 0, f"{where}{key} must be >= 0{note}, got {value}")


def _share(obj: Any, *keys: str, where: str = "") -> None:
    for key in keys:
        value = getattr(obj, key)
        require(0.0 <= value <= 1.0, f"{where}{key} must be in [0, 1], got {value}")


def _angle(value: float, name: str, high: float = 1.5) -> None:
    require(0.0 <= value <= high, f"{name} must be in [0, {high}] rad, got {value}")


@dataclass(frozen=True)
class MoveConfig:
    """Every straight move of the hand (pre-grasp, approach, retreat) and every pull step, in
    ``pd_ee_delta_pose`` control steps."""

    max_step_m: float = 0.03
    """Largest TCP translation per control step (m): a noisy estimate that jumps cannot throw the arm."""
    max_step_rad: float = 0.15
    """Largest TCP rotation per control step (rad), for the same reason."""
    pos_tolerance: float = 0.012
    """A move has reached its goal within this distance (m), about a quarter of a handle bar's reach."""
    rot_tolerance: float = 0.12
    """... and within this rotation (rad): the fingers still enclose a bar turned this much."""
    timeout_steps: int = 60
    """A move ends after this many steps whatever its error (the goal may be out of the arm's reach)."""
    blocked_steps: int = 6
    """A move ends when the TCP has not moved for this many steps: it touches something (a handle)."""

    def validate(self) -> None:
        _positive(self, "max_step_m", "max_step_rad", "pos_tolerance", "rot_tolerance", where="move.")
        _at_least_one(self, "timeout_steps", "blocked_steps", where="move.")


@dataclass(frozen=True)
class ApproachConfig:
    """The pre-grasp (outside the grasp point along the part's outward normal) and the approach (in
    along the TCP's approach axis), for any part; per-kind pitches are in the kind's group."""

    pregrasp_offset: float = 0.08
    """Pre-grasp distance (m) outside the grasp point: the open fingers (8 cm long) clear the handle."""
    grasp_depth: float = 0.01
    """How far past the grasp point the approach goes (m), so the pads close round the bar, not its face."""
    pitch: float = 0.55
    """The approach points at least this far below horizontal (rad) for a hinged part other than a side
    door, and for a part sliding across its face: a level Panda hand near the table is beyond its wrist
    limits; a hand pitching with the part as it opens starts nearer level."""
    gap: float = 0.06
    """Finger gap while approaching (m; the Panda opens to 0.08): narrower keeps a pitched fingertip off
    the surface a handle stands on; under 6 cm a finger pitched across a bar clips its edge when the grasp
    point is half a centimetre off."""
    rotate_first_above: float = 0.4
    """The hand first turns in place while it is more than this far (rad) from the grasp orientation:
    turned while travelling, the arm's IK reaches a low, far handle with the wrist at its joint limit and
    cannot hold the pose while pulling."""
    rotate_first_steps: int = 25
    """... for at most this many steps (0: never)."""
    rechoose_grasp_m: float = 0.05
    """The grasp orientation is chosen again, the move starting over, when the perceived grasp point is
    this far (m) from the one it was chosen for (0: never): a first look that finds no handle puts the
    grasp point on the part's far edge, and an orientation chosen there does not suit the handle."""
    rechoose_steps: int = 30
    """... only in a grasp's first this many pre-grasp steps: an open part's grasp point jumps about from
    look to look, and each start over turns the hand first."""
    rechoose_looks: int = 2
    """... and only when each of the last this many looks (new estimates) is that far off and they agree
    with each other within ``rechoose_grasp_m``: a learned grasp point can jump for a single look."""
    rechoose_part_kind: bool = False
    """Also choose again, in those steps and on those looks, when the part's kind (lid, side door, other
    hinge) differs from the one chosen for: a first look can tilt a door's hinge into a lid's."""

    def validate(self) -> None:
        _positive(self, "pregrasp_offset", where="approach.")
        _angle(self.pitch, "approach.pitch")
        require(0.0 < self.gap <= 0.08, f"approach.gap must be in (0, 0.08] m, got {self.gap}")
        require(self.rotate_first_above > 0,
                f"approach.rotate_first_above must be > 0 rad, got {self.rotate_first_above}")
        require(self.rotate_first_steps >= 0,
                f"approach.rotate_first_steps must be >= 0 (0: never), got {self.rotate_first_steps}")
        require(self.rechoose_grasp_m >= 0,
                f"approach.rechoose_grasp_m must be >= 0 m (0: never), got {self.rechoose_grasp_m}")
        require(self.rechoose_steps >= 0, f"approach.rechoose_steps must be >= 0, got {self.rechoose_steps}")
        require(self.rechoose_looks >= 1, f"approach.rechoose_looks must be >= 1, got {self.rechoose_looks}")


@dataclass(frozen=True)
class GraspConfig:
    """Closing the fingers, telling a hold from an empty hand, and choosing the finger order."""

    close_steps: int = 8
    """Steps the gripper takes to close (the Panda's fingers close in about 0.3 s)."""
    hold_gap: float = 0.004
    """Fingers at least this far apart (m) hold something; closed on nothing they touch (about 0)."""
    rehearse_fingers: bool = True
    """Rehearse both finger orders of a grasp (not a lid's) on the Panda's kinematic model
    (:mod:`agents.scripted.grasp_rehearsal`) and take the one farther from the hand's rotation only if
    it reaches the grasp and follows the whole pull while the nearer one does not, or clearly more of
    it: one order can leave a wrist joint at its limit."""
    rehearse_margin: float = 0.2
    """... the nearer order is given up only if the other follows at least this share of the pull path
    (in (0, 1]) more than it: when both fall behind at about the same place, the model cannot tell
    them apart."""
    rehearse_track_m: float = 0.02
    """A rehearsed TCP farther than this (m) from the pull path has fallen behind."""
    rehearse_track_rad: float = 0.25
    """A rehearsed TCP turned more than this (rad) from the pull path's orientation has fallen behind:
    a wrist pinned at its limit lets the hand's roll lag the part while its position keeps up, and
    the handle twists out of the fingers."""

    def validate(self) -> None:
        _positive(self, "hold_gap", "rehearse_track_m", "rehearse_track_rad", where="grasp.")
        _at_least_one(self, "close_steps", where="grasp.")
        require(0.0 < self.rehearse_margin <= 1.0,
                f"grasp.rehearse_margin must be in (0, 1] (a share of the pull path), "
                f"got {self.rehearse_margin}")


@dataclass(frozen=True)
class ArcFitConfig:
    """The hinge measured by the hand that holds its part: once the holding hand's path is long enough,
    the centre of the circle it follows about the estimated axis direction replaces the estimated pivot
    for the rest of the pull. A pivot a few cm off the hinge of a 20 cm door reads the swept angle
    0.4 rad too large, and the hand lets go short of open."""

    enabled: bool = True
    min_chord: float = 0.06
    """The path must span this much (m) before a circle is fitted: shorter arcs fit any centre."""
    min_angle: float = 0.3
    """... and sweep this much (rad) about the estimated hinge."""
    max_rms: float = 0.004
    """The path must lie within this (m, RMS) of the circle: a hand slipping along the handle does not."""
    max_shift: float = 0.15
    """The fitted centre must lie within this (m) of the estimated hinge line: farther is another motion."""

    def validate(self) -> None:
        _positive(self, "min_chord", "min_angle", "max_rms", "max_shift", where="pull.arc_fit.")


@dataclass(frozen=True)
class MotionAxisConfig:
    """The axis measured by how the part moved (:func:`agents.scripted.motion_axis.fit_motion_axis`): the
    estimated grasp points seen while the fingers held the part (every pull of the episode) are fitted
    with a line (prismatic) or a circle in a plane (revolute), and a good fit replaces the estimated axis
    for the rest of the episode. An axis a few degrees off makes the commanded arc or line leave the
    part's own, and the fingers slide off it. Off by default."""

    enabled: bool = False
    min_travel: float = 0.03
    """The points must spread this far (m) before a fit."""
    min_angle: float = 0.4
    """A circle must sweep this much (rad)."""
    max_rms: float = 0.004
    """Points within this (m, RMS) of the fit."""
    max_turn: float = 0.6
    """The fitted axis within this (rad) of the estimated one: farther is a fit to noise."""
    max_ratio: float = 0.1
    """The points' spread off the line or plane at most this share of their spread along it."""
    hinge_points: int = 6
    """Points a circle needs (a plane and a circle through 4 fit anything; a line needs 3)."""

    def validate(self) -> None:
        _positive(self, "min_travel", "min_angle", "max_rms", "max_turn", "max_ratio",
                  where="pull.motion_axis.")
        require(self.hinge_points >= 4,
                f"pull.motion_axis.hinge_points must be >= 4, got {self.hinge_points}")


@dataclass(frozen=True)
class RevolutePullConfig:
    """Pulling a hinged part (lids have their own target, ``lid.target``)."""

    lead: float = 0.12
    """The commanded TCP leads the part by this angle (rad) along its arc: the pull's force."""
    target: float = 1.7
    """The pull ends when the hand's measure of the part's angle reaches this (rad)."""
    stall_progress: float = 0.02
    """A pull that turned less than this (rad) over ``pull.stall_steps`` has stalled (a limit, a lost
    grip)."""
    wrist_follow: float = 0.5
    """The hand turns by this share of the part's angle about a hinge that is not vertical (a side
    door's turns by ``side_door.upright_bar_follow`` or fully): a grasped bar turns between the pads,
    and a hand turned fully with an oven door reaches the Panda's wrist limit."""
    stop_above: float = 1.4
    """A hinged part (not a lid nor a door that falls open) whose pull stalls past this angle (rad), the
    fingers holding and no wrist joint at its limit, is at its end stop and is not grasped again (0:
    off): reaching for its handle again knocks it back towards closed."""
    open_above: float = 1.5
    """Such a part whose pull stalls past this angle (rad) by the hand's measure and as seen is open
    and is not grasped again even with a wrist joint at its limit (0: off): the hand, stopped beside
    a door swung round about a quarter turn, turns round beside it for the other finger order and
    knocks it back, and 1.5 rad is three quarters of a side door's range up to 2.0 rad (115 deg). A
    door of a wider range stalled there is left short of three quarters (a 120 deg microwave door at
    0.72-0.74); the stall's two measures, each a few degrees off, cannot tell the two apart."""

    def validate(self) -> None:
        _positive(self, "lead", "target", "stall_progress", where="pull.revolute.")
        _share(self, "wrist_follow", where="pull.revolute.")
        _non_negative(self, "stop_above", where="pull.revolute.", note=" rad (0: off)")
        _non_negative(self, "open_above", where="pull.revolute.", note=" rad (0: off)")


@dataclass(frozen=True)
class PrismaticPullConfig:
    """Pulling a sliding part (drawers and sliding panels)."""

    lead: float = 0.03
    """The commanded TCP leads the part by this distance (m) along its axis."""
    target: float = 0.4
    """The pull ends when the hand has pulled the part this far out (m)."""
    stall_progress: float = 0.004
    """A pull that moved less than this (m) over ``pull.stall_steps`` has stalled."""
    limit_slowdown: float = 0.8
    """The part is at its end stop when the pulling hand moves less than this share of its cruising speed
    for ``limit_window`` steps: pulled on, the handle slides out of the fingers and a re-grasp chases an
    open part. A handle gripped pitched slides out early, the hand slowing only to 0.6-0.8 of its speed."""
    limit_window: int = 2
    """Steps the hand must stay slowed."""
    limit_min_speed_m: float = 0.005
    """The cruising speed (median step, m) must be at least this for a slowdown to count."""
    stop_above: float = 0.15
    """A slip from a part the hand has pulled past this (m) also ends the pull for good (0: off): the
    handle slid out at the end stop before the slowdown was read, and a re-grasp's approach would push
    the open part back in."""
    track_fit_travel: float = 0.02
    """Once the hand holding a sliding part has travelled this far (m), the line fitted to its path is
    the line it pulls along (0: off): the part's track carries the hand along itself, so the path
    measures the track, while an estimated slide a few degrees off it is pushed back by the track, the
    hand's error off the commanded line grows every step and the pull slows until it reads as the end
    stop or tears the handle out of the fingers."""
    track_fit_max_turn: float = 0.8
    """The fitted line within this (rad) of the estimated one. A single view can read a sash's slide
    30-45 deg off its track and the track still carries the hand along itself; a hand sliding along a
    bar handle across the pull (90 deg) is not the track."""
    track_fit_max_rms: float = 0.004
    """The path within this (m, RMS) of the line: a hand sliding along the handle is not."""
    track_fit_max_gap_change: float = 0.002
    """The hand's path counts until the finger gap changes by more than this (m) in one step: a bar
    sliding out of the fingers narrows the gap by several millimetres a step (1.7 -> 1.2 -> 0.3 cm),
    and the hand's path is then not the part's; a grip settling on its handle closes it by 1-2 mm a
    step."""

    def validate(self) -> None:
        _positive(self, "lead", "target", "stall_progress", "limit_min_speed_m", "track_fit_max_turn",
                  "track_fit_max_rms", "track_fit_max_gap_change", where="pull.prismatic.")
        _non_negative(self, "track_fit_travel", where="pull.prismatic.", note=" m (0: off)")
        _at_least_one(self, "limit_window", where="pull.prismatic.")
        require(0.0 < self.limit_slowdown < 1.0,
                f"pull.prismatic.limit_slowdown must be in (0, 1), got {self.limit_slowdown}")
        _non_negative(self, "stop_above", where="pull.prismatic.", note=" m (0: off)")


@dataclass(frozen=True)
class PullConfig:
    """Moving the held part along its estimated arc or line, measured by the hand's own travel."""

    stall_steps: int = 12
    """Progress is measured over this many steps (0.6 s: longer than a perception period)."""
    slip_distance: float = 0.07
    """The hand has slipped off when it stays farther than this (m) from the perceived grasp point ..."""
    slip_steps: int = 8
    """... for this many steps (longer than a perception period: one bad estimate, e.g. of a handle the
    hand now hides, is not a slip) with its fingers closed on nothing (a gap means they still hold)."""
    frozen_joints: float = 0.002
    """A pull step after which no arm joint moved more than this (rad) froze the arm: the
    ``pd_ee_delta_pose`` controller's IK (100 CLIK iterations from the joints' angles) does not converge
    on a full step towards a goal near the edge of the arm's reach (the elbow near straight, where a
    step of the TCP is a large step of the joints) and then holds the arm where it is, step after step,
    which reads as a stall. 0: off."""
    step_shrink: float = 0.5
    """... the pull's later steps are this share of the commanded ones (again after each frozen step,
    kept for the rest of the pull) ..."""
    min_step_share: float = 0.25
    """... down to this share: half a step converges where the full one does not."""
    revolute: RevolutePullConfig = field(default_factory=RevolutePullConfig)
    prismatic: PrismaticPullConfig = field(default_factory=PrismaticPullConfig)
    arc_fit: ArcFitConfig = field(default_factory=ArcFitConfig)
    motion_axis: MotionAxisConfig = field(default_factory=MotionAxisConfig)

    def validate(self) -> None:
        _positive(self, "slip_distance", where="pull.")
        _non_negative(self, "frozen_joints", where="pull.", note=" rad (0: off)")
        require(0.0 < self.min_step_share <= 1.0 and 0.0 < self.step_shrink <= 1.0,
                f"pull.step_shrink and pull.min_step_share must be in (0, 1], got {self.step_shrink}, "
                f"{self.min_step_share}")
        _at_least_one(self, "stall_steps", "slip_steps", where="pull.")
        for sub in (self.revolute, self.prismatic, self.arc_fit, self.motion_axis):
            sub.validate()


@dataclass(frozen=True)
class ReleaseConfig:
    """Letting go and backing off."""

    steps: int = 6
    """Steps the gripper takes to open."""
    retreat_distance: float = 0.08
    """The open hand backs off this far (m) along its approach axis: the fingers clear the handle."""

    def validate(self) -> None:
        _at_least_one(self, "steps", where="release.")
        _non_negative(self, "retreat_distance", where="release.", note=" m")


@dataclass(frozen=True)
class RecoveryConfig:
    """Grasping again after a miss, a slip or a stall."""

    max_regrasps: int = 2
    """Grasps after the first, at most (a pull that slips or stalls short of its target, fingers that
    close on nothing)."""
    other_fingers: bool = True
    """Fingers that close on nothing (not a lid's) open, back off and grasp again with the fingers the
    other way round: for a low handle one of the two finger orders can leave a wrist joint at its limit
    short of the handle."""
    quarter_turn: bool = True
    """... that is so only when the approach timed out or a wrist joint is at its limit; otherwise the
    hand reached the handle and it does not lie across the fingers (a lever bar at right angles to the
    hinge), so this and later grasps turn the fingers a quarter turn about the approach."""
    wrist_limit_margin: float = 0.05
    """A wrist joint (5, 6, 7) within this (rad) of its limit is at it (0: off). A pull that stalls so
    grasps again with the fingers the other way round: the arm ran out of range with this order."""
    unmoved: float = 0.03
    """A pull whose hand slips off while the part's grasp point as seen has moved less than this (m)
    since the pull began held nothing it could pull (the fingers pinched the end of a lever lying
    along their closing direction, not the bar across it): the next grasp turns the fingers as after
    fingers that closed on nothing (0: never)."""

    def validate(self) -> None:
        require(self.max_regrasps >= 0, "recovery.max_regrasps must be >= 0")
        require(self.unmoved >= 0.0, f"recovery.unmoved must be >= 0 m, got {self.unmoved}")
        require(0.0 <= self.wrist_limit_margin < 0.5,
                f"recovery.wrist_limit_margin must be in [0, 0.5) rad (0: off), "
                f"got {self.wrist_limit_margin}")


@dataclass(frozen=True)
class SideDoorConfig:
    """A door hinged about a near-vertical axis: the hand only yaws while pulling, so it turns with the
    door (fully across a level bar, by ``upright_bar_follow`` across an upright one) and can start
    pitched further down."""

    max_tilt: float = 0.8
    """A hinge within this (rad) of vertical is a side door's."""
    pitch: float = 0.8
    """The approach points at least this far below horizontal (rad)."""
    pull_roll: float = 0.8
    """While pulling, past ``pull_roll_from``, a hand whose fingers close across a level bar (a lever)
    pitches further down by this share of the further angle the door turns (rad per rad), turning
    about the horizontal axis across its approach, which is that bar (the grip turns about what it
    holds), up to ``max_pull_pitch``: a hand square to a door swung far round points away from the
    robot, its wrist out beyond the door and the arm at the edge of its reach; pitched down, the
    wrist stays over the handle. A hand closing level, across an upright bar, keeps its pitch (the
    roll would turn the bar into its palm). 0: off."""
    max_pull_pitch: float = 1.2
    """The roll stops at this pitch below horizontal (rad)."""
    upright_bar_follow: float = 0.8
    """A hand whose fingers close level, across an upright bar (a bar along the hinge), turns by this
    share of the door's angle while pulling; one closed across a level bar (a lever) turns fully. The
    bar spins about its own axis between the pads, and the hand, lagging the door, keeps its wrist
    nearer the robot: the reach the roll gives a hand across a level bar, which this hand cannot take
    (the roll would turn the bar into its palm). On the Panda's kinematics, a handle 37 cm from the
    hinge is followed to 1.5 rad at 0.8 and falls short near 1.45 rad turning fully
    (``tests/agents/test_side_door_reach.py``)."""
    pry_gap: float = 0.004
    """A held upright bar that widens the finger gap by more than this (m) over the pull's first held
    gap is turning between the pads and prying them apart (a flat bar turned on its edge); from then
    on in that pull the hand turns by ``pry_follow`` of the door's angle instead (0: off)."""
    pry_follow: float = 0.6
    """The share of the door's angle a hand across an upright bar that pries its fingers apart turns
    by: held on, the bar levers out of the fingers within a few steps and the hand runs on round the
    arc without the door."""
    pull_roll_from: float = 1.0
    """The roll starts once the door has turned this far (rad): nearer closed the arm has reach to
    spare, and a hand square to the door holds its handle best (each turn of the hand moves the pads on
    a handle gripped a centimetre off the TCP)."""

    def validate(self) -> None:
        _angle(self.max_tilt, "side_door.max_tilt")
        _angle(self.pitch, "side_door.pitch")
        require(self.pull_roll >= 0.0, f"side_door.pull_roll must be >= 0 rad/rad, got {self.pull_roll}")
        _angle(self.max_pull_pitch, "side_door.max_pull_pitch")
        require(0.0 <= self.upright_bar_follow <= 1.0,
                f"side_door.upright_bar_follow must be in [0, 1], got {self.upright_bar_follow}")
        require(self.pull_roll_from >= 0.0,
                f"side_door.pull_roll_from must be >= 0 rad, got {self.pull_roll_from}")
        require(self.pry_gap >= 0.0, f"side_door.pry_gap must be >= 0 m (0: off), got {self.pry_gap}")
        require(0.0 <= self.pry_follow <= 1.0,
                f"side_door.pry_follow must be in [0, 1], got {self.pry_follow}")


@dataclass(frozen=True)
class LidLiftConfig:
    """Lifting a lid from below when the fingers closed on nothing across its lip (wider than the open
    fingers): the closed fingertips, pointing at the hinge and steeply down, slide in under the lip and
    push it open along its arc, carrying its weight."""

    enabled: bool = True
    pitch: float = 1.3
    """The closed fingers point at the hinge this far below horizontal (rad)."""
    below: float = 0.010
    """The fingertips go this far (m) under the grasp point ..."""
    front: float = 0.06
    """... from this far (m) in front of it (where the hand lines up) ..."""
    under: float = 0.0
    """... to this far (m) behind it (where the hand slides to)."""
    wrist_follow: float = 0.0
    """The hand turns by this share of the lid's angle."""
    inward: float = 0.02
    """The hand moves this far (m) towards the hinge per radian the lid has turned: on an estimated hinge
    1-2 cm off, fingertips following its arc slide off the lip; sliding towards the hinge they stay
    under it."""
    press: float = 0.01
    """The hand is sent at least this far (m) towards the hinge from where it is now, and at most twice
    as far inside the ``inward`` arc: a hinge estimated a centimetre off moves that arc away from the
    lid's front face, and fingertips no longer pressed into it ride up over its corner."""
    slip_behind: float = 0.3
    """Lifting, the hand has slipped off the lid only while the lid as perceived also lags the hand's
    own measure of it by more than this (rad; 0: the grasp point alone decides): the closed fingers
    tell no gap, and a look that reads a half-open lid's hinge at its lip, or its far edge mid-lid,
    moves the perceived grasp point far from a hand still under the lid, while the perceived angle
    (the network's state) stays with the lid."""
    lead: float = 0.2
    """The push leads the lid by this angle (rad): pushing from below, the fingertips carry its weight,
    and a larger lead pushes through the stall near 0.4 rad that ``pull.revolute.lead`` meets."""

    def validate(self) -> None:
        _positive(self, "lead", where="lid.lift.")
        require(0.0 < self.pitch <= 1.5, f"lid.lift.pitch must be in (0, 1.5] rad, got {self.pitch}")
        _non_negative(self, "below", "front", "under", "inward", "press", where="lid.lift.", note=" m")
        _non_negative(self, "slip_behind", where="lid.lift.", note=" rad (0: off)")
        _share(self, "wrist_follow", where="lid.lift.")


@dataclass(frozen=True)
class LidConfig:
    """A revolute part whose grasp point opens upwards (a closed laptop): gripped from above, the fingers
    closing along the hinge across its front lip."""

    max_tilt: float = 0.5
    """A part whose grasp point opens within this (rad) of straight up is a lid."""
    gap: float = 0.08
    """Finger gap while approaching (m): fully open, to take the lip's thickness and the estimate's error."""
    edge_offset: float = 0.005
    """The grip is this far (m) beyond the grasp point away from the hinge, so the pads clear the lid's
    edge whether the grasp point is the lip's centre or the outer band of its points."""
    wrist_follow: float = 0.0
    """The hand turns by this share of the lid's angle: the pinch lets the lip turn between the pads, and a
    hand turned with the lid would point back at the robot."""
    target: float = 2.0
    """The pull ends at this angle (rad), past upright, so the lid does not rest on its hinge's friction
    just short of the success angle."""
    slip_off_axis: bool = True
    """A lid's slip distance leaves out its component along the hinge: a lid has no handle, and its grasp
    point (the middle of the far edge's visible points) slides along the edge as the hand hides part of it."""
    along_slack: float = 0.04
    """Along the hinge the reach keeps the hand's own place within this (m) of the grasp point: any
    point of a lid's lip is gripped alike, and the grasp point (the middle of the lip's visible points)
    slides along it from look to look as the hand hides part of it; chased, the hand never settles."""
    lift: LidLiftConfig = field(default_factory=LidLiftConfig)

    def validate(self) -> None:
        _angle(self.max_tilt, "lid.max_tilt")
        _non_negative(self, "along_slack", where="lid.", note=" m")
        require(0.0 < self.gap <= 0.08, f"lid.gap must be in (0, 0.08] m, got {self.gap}")
        _non_negative(self, "edge_offset", where="lid.", note=" m")
        _share(self, "wrist_follow", where="lid.")
        _positive(self, "target", where="lid.")
        self.lift.validate()


@dataclass(frozen=True)
class FallingDoorConfig:
    """A door that gravity opens further once let go (hinged below its grasp point about a non-vertical
    axis, not a lid: an oven door). Reaching for the handle of a door near level pushes it back, so such
    a door is left to fall and watched rather than grasped again."""

    done_above: float = 1.3
    """A pull that ends (stall or slip) past this angle (rad), by both the hand's measure and the perceived
    state, is not followed by a grasp (0: every falling-door rule off)."""
    settle_above: float = 0.8
    """Let go past this angle (rad), the open hand clears the door's sweep and waits while it falls; a
    door let go nearer closed falls too slowly to wait for."""
    clearance: float = 0.1
    """While waiting, and before turning in place for a grasp, the hand moves this far (m) beyond the
    grasp radius about the hinge (out of the door's sweep)."""
    window: int = 10
    """The door is still falling while its perceived state rose by ``progress`` over this many steps."""
    progress: float = 0.06
    """... by this much (rad); a door that creeps is grasped again."""
    max_steps: int = 40
    """Waiting ends after this many steps."""
    watch: bool = True
    """Such a door seen falling open before it is grasped (at least ``settle_above`` open and rising: the
    hand turning in front of it brushed it, or it was let go short of open) is not reached for: the hand
    clears its sweep and waits the same way."""

    def validate(self) -> None:
        _non_negative(self, "done_above", where="falling_door.", note=" rad (0: off)")
        _non_negative(self, "settle_above", where="falling_door.", note=" rad")
        _non_negative(self, "clearance", where="falling_door.", note=" m")
        _positive(self, "progress", where="falling_door.")
        _at_least_one(self, "window", "max_steps", where="falling_door.")


@dataclass(frozen=True)
class DrawerConfig:
    """A sliding part that comes out of the face its handle is on, towards the robot."""

    pitch: float = 0.3
    """The approach points at least this far below horizontal (rad): a drawer's bar is pulled along the
    approach, and fingers pitched further squeeze it out along the pull; a handle near the table
    approached steeper runs wrist joint 5 into its limit."""

    def validate(self) -> None:
        _angle(self.pitch, "drawer.pitch")


@dataclass(frozen=True)
class SlidingPanelConfig:
    """A sliding part that slides across the face its handle is on (a window sliding up, a sliding door):
    approached square on from the robot's side, the fingers closing along the slide, pulled along its
    axis whatever way that points."""

    min_angle: float = 0.785
    """A prismatic axis more than this (rad) from the horizontal direction to the robot's base slides
    across its face (past pi/2: never)."""
    hold_rising_above: float = 0.3
    """A part whose opening direction rises more than this (rad) above horizontal is held where the pull
    ended, not let go: gravity would slide it back closed (0: off)."""

    def validate(self) -> None:
        require(0.0 <= self.min_angle <= np.pi,
                f"sliding_panel.min_angle must be in [0, pi] rad (past pi/2: never), got {self.min_angle}")
        require(0.0 <= self.hold_rising_above <= 1.5,
                f"sliding_panel.hold_rising_above must be in [0, 1.5] rad (0: off), "
                f"got {self.hold_rising_above}")


@dataclass(frozen=True)
class ScriptedOpenerConfig:
    """Options of :class:`agents.scripted.opener.ScriptedOpener`, one group per part of the method or
    part kind (see the module docstring)."""

    move: MoveConfig = field(default_factory=MoveConfig)
    approach: ApproachConfig = field(default_factory=ApproachConfig)
    grasp: GraspConfig = field(default_factory=GraspConfig)
    pull: PullConfig = field(default_factory=PullConfig)
    release: ReleaseConfig = field(default_factory=ReleaseConfig)
    recovery: RecoveryConfig = field(default_factory=RecoveryConfig)
    side_door: SideDoorConfig = field(default_factory=SideDoorConfig)
    lid: LidConfig = field(default_factory=LidConfig)
    falling_door: FallingDoorConfig = field(default_factory=FallingDoorConfig)
    drawer: DrawerConfig = field(default_factory=DrawerConfig)
    sliding_panel: SlidingPanelConfig = field(default_factory=SlidingPanelConfig)

    def validate(self) -> None:
        for f in fields(self):
            getattr(self, f.name).validate()

    @classmethod
    def upgrade_legacy_keys(cls, data: dict[str, Any], where: str = "config") -> dict[str, Any]:
        """Hook of :func:`capt_common.typed_yaml.from_dict`: see :func:`upgrade_legacy_keys`."""
        return upgrade_legacy_keys(data, where)


# The flat option names of earlier releases and where each lives now (deprecated; to be removed in
# the release after next). One table: loading, the warning and ``legacy_value`` all read it.
LEGACY_KEYS: dict[str, str] = {
    "max_step_m": "move.max_step_m",
    "max_step_rad": "move.max_step_rad",
    "pos_tolerance": "move.pos_tolerance",
    "rot_tolerance": "move.rot_tolerance",
    "move_timeout": "move.timeout_steps",
    "blocked_steps": "move.blocked_steps",
    "pregrasp_offset": "approach.pregrasp_offset",
    "grasp_depth": "approach.grasp_depth",
    "approach_pitch": "approach.pitch",
    "approach_gap": "approach.gap",
    "rotate_first_above": "approach.rotate_first_above",
    "rotate_first_steps": "approach.rotate_first_steps",
    "rechoose_grasp_m": "approach.rechoose_grasp_m",
    "rechoose_steps": "approach.rechoose_steps",
    "rechoose_looks": "approach.rechoose_looks",
    "rechoose_part_kind": "approach.rechoose_part_kind",
    "close_steps": "grasp.close_steps",
    "hold_gap": "grasp.hold_gap",
    "rehearse_fingers": "grasp.rehearse_fingers",
    "rehearse_margin": "grasp.rehearse_margin",
    "rehearse_track_m": "grasp.rehearse_track_m",
    "rehearse_track_rad": "grasp.rehearse_track_rad",
    "stall_steps": "pull.stall_steps",
    "slip_distance": "pull.slip_distance",
    "slip_steps": "pull.slip_steps",
    "revolute_lead": "pull.revolute.lead",
    "revolute_target": "pull.revolute.target",
    "stall_progress": "pull.revolute.stall_progress",
    "wrist_follow": "pull.revolute.wrist_follow",
    "revolute_stop_above": "pull.revolute.stop_above",
    "prismatic_lead": "pull.prismatic.lead",
    "prismatic_target": "pull.prismatic.target",
    "stall_progress_m": "pull.prismatic.stall_progress",
    "limit_slowdown": "pull.prismatic.limit_slowdown",
    "limit_window": "pull.prismatic.limit_window",
    "limit_min_speed_m": "pull.prismatic.limit_min_speed_m",
    "prismatic_stop_above": "pull.prismatic.stop_above",
    "arc_fit": "pull.arc_fit.enabled",
    "arc_fit_min_chord": "pull.arc_fit.min_chord",
    "arc_fit_min_angle": "pull.arc_fit.min_angle",
    "arc_fit_max_rms": "pull.arc_fit.max_rms",
    "arc_fit_max_shift": "pull.arc_fit.max_shift",
    "motion_axis": "pull.motion_axis.enabled",
    "motion_axis_min_travel": "pull.motion_axis.min_travel",
    "motion_axis_min_angle": "pull.motion_axis.min_angle",
    "motion_axis_max_rms": "pull.motion_axis.max_rms",
    "motion_axis_max_turn": "pull.motion_axis.max_turn",
    "motion_axis_max_ratio": "pull.motion_axis.max_ratio",
    "motion_axis_hinge_points": "pull.motion_axis.hinge_points",
    "release_steps": "release.steps",
    "retreat_distance": "release.retreat_distance",
    "max_regrasps": "recovery.max_regrasps",
    "regrasp_other_fingers": "recovery.other_fingers",
    "quarter_turn": "recovery.quarter_turn",
    "wrist_limit_margin": "recovery.wrist_limit_margin",
    "vertical_hinge_max_tilt": "side_door.max_tilt",
    "vertical_hinge_pitch": "side_door.pitch",
    "lid_max_tilt": "lid.max_tilt",
    "lid_approach_gap": "lid.gap",
    "lid_edge_offset": "lid.edge_offset",
    "lid_wrist_follow": "lid.wrist_follow",
    "lid_revolute_target": "lid.target",
    "lid_slip_off_axis": "lid.slip_off_axis",
    "lid_lift": "lid.lift.enabled",
    "lid_lift_pitch": "lid.lift.pitch",
    "lid_lift_below": "lid.lift.below",
    "lid_lift_front": "lid.lift.front",
    "lid_lift_under": "lid.lift.under",
    "lid_lift_wrist_follow": "lid.lift.wrist_follow",
    "lid_lift_inward": "lid.lift.inward",
    "lid_lift_lead": "lid.lift.lead",
    "fall_open_done": "falling_door.done_above",
    "settle_above": "falling_door.settle_above",
    "settle_clearance": "falling_door.clearance",
    "settle_window": "falling_door.window",
    "settle_progress": "falling_door.progress",
    "settle_max_steps": "falling_door.max_steps",
    "watch_falling": "falling_door.watch",
    "prismatic_approach_pitch": "drawer.pitch",
    "slide_across_min_angle": "sliding_panel.min_angle",
    "hold_rising_above": "sliding_panel.hold_rising_above",
}


def upgrade_legacy_keys(data: dict[str, Any], where: str = "config") -> dict[str, Any]:
    """``data`` (a mapping for :class:`ScriptedOpenerConfig`) with its flat keys of earlier releases
    moved to their nested places (:data:`LEGACY_KEYS`), warning (``FutureWarning``) once per mapping that
    names them; a key given both ways is an error. Other keys are left for the strict loader to check."""
    legacy = [key for key in data if key in LEGACY_KEYS]
    if not legacy:
        return data
    warnings.warn(f"{where}: flat scripted-opener keys are deprecated, use the nested ones: "
                  + ", ".join(f"{key} -> {LEGACY_KEYS[key]}" for key in legacy), FutureWarning, stacklevel=3)
    out: dict[str, Any] = {k: v for k, v in data.items() if k not in LEGACY_KEYS}
    for key in legacy:
        *groups, leaf = LEGACY_KEYS[key].split(".")
        node = out
        for group in groups:
            child = node.get(group)
            child = {} if child is None else dict(child) if isinstance(child, dict) else child
            require(isinstance(child, dict), f"{where}.{group}: expected a mapping, got {child!r}")
            node[group] = child
            node = child
        require(leaf not in node, f"{where}: {key} and {LEGACY_KEYS[key]} both given")
        node[leaf] = data[key]
    return out


def legacy_value(config: ScriptedOpenerConfig, key: str) -> Any:
    """The value of flat option ``key`` of earlier releases (or of a dotted path) in ``config``."""
    node: Any = config
    for part in LEGACY_KEYS.get(key, key).split("."):
        node = getattr(node, part)
    return node


def with_options(config: ScriptedOpenerConfig, **changes: Any) -> ScriptedOpenerConfig:
    """``config`` with options changed, named by their dotted path with ``__`` for the dots
    (``with_options(cfg, lid__lift__inward=0.0)``) or by their flat name of earlier releases."""
    from dataclasses import replace

    def put(node: Any, path: list[str], value: Any) -> Any:
        if len(path) == 1:
            return replace(node, **{path[0]: value})
        return replace(node, **{path[0]: put(getattr(node, path[0]), path[1:], value)})

    for key, value in changes.items():
        dotted = LEGACY_KEYS.get(key, key.replace("__", "."))
        config = put(config, dotted.split("."), value)
    assert is_dataclass(config)
    config.validate()
    return config
