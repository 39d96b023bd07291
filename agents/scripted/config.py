"""Typed config of the scripted opener (metres, radians, control steps at 20 Hz)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from capt_common.typed_yaml import require


@dataclass(frozen=True)
class ScriptedOpenerConfig:
    """Gains, offsets and targets of :class:`agents.scripted.opener.ScriptedOpener`.

    Approach: pre-grasp ``pregrasp_offset`` m outside the grasp point along the part's outward normal,
    then ``grasp_depth`` m past it. The approach direction points at least ``vertical_hinge_pitch`` rad
    below horizontal for parts hinged about a near-vertical axis (the axis within
    ``vertical_hinge_max_tilt`` rad of vertical: doors; the hand only yaws while pulling) and
    ``approach_pitch`` rad for other hinges (oven doors, lids: the hand pitches while pulling, so
    it starts nearer level) and ``prismatic_approach_pitch`` for drawers; a level Panda hand near the
    table is beyond its wrist limits. A drawer's handle 8 cm above the table, approached 0.55 rad
    down, ran wrist joint 5 into its limit short of the grasp orientation, and the tilted fingers
    squeezed the bar out (drawer seeds 38, 41, 94, 133, 157, 162; 0.3 rad opened them). A prismatic
    part whose axis lies more than ``slide_across_min_angle`` rad from the horizontal direction to the
    robot's base slides across its face (a window sliding up, a sliding door): the hand approaches
    that face square on from the robot's side, ``approach_pitch`` rad down, the fingers closing along
    the slide, and pulls along the axis whatever way it points
    (:func:`~agents.scripted.grasp_pose.slides_across_face`); a part whose axis points nearer the
    robot comes out of its face like a drawer. A prismatic part whose opening direction rises more
    than ``hold_rising_above`` rad above horizontal (a window sliding up) is held where the pull
    ended, not let go: gravity slides it back closed (0: off). The hand first
    turns in place to the grasp orientation while it is more than ``rotate_first_above`` rad from it, for
    at most ``rotate_first_steps`` steps (turned while travelling, the arm's IK reaches a low, far handle
    with the wrist at its joint limit and cannot hold the pose while pulling; 0 steps: never). The grasp
    orientation is chosen as the pre-grasp move starts and chosen again, the move starting over, when
    in the first ``rechoose_steps`` steps of the grasp's pre-grasp the perceived grasp point is more
    than ``rechoose_grasp_m`` m from the one it was chosen for (0: never): a first look that finds no
    handle puts the grasp point on the part's far edge, and an orientation chosen for that point does
    not suit the handle seen a few steps later (not later on: an open part's grasp point jumps about
    from look to look, and each start over turns the hand first). With ``rechoose_looks`` n > 1,
    only when each of the last n looks (new estimates) is that far from it and they agree with each
    other within ``rechoose_grasp_m`` (CAPT's grasp point on a washing machine's door can jump between
    looks: on seeds 2 and 4 the orientation was chosen again on three looks running and the fingers
    then closed on nothing; 2, the default since session 20, opened 5 more of 200 washing machines with
    CAPT than 1, 2 more ovens, as many laptops and one cabinet door fewer). With
    ``rechoose_part_kind`` the orientation is also chosen again, in those steps and on those looks,
    when the part's kind (:func:`~agents.scripted.grasp_pose.part_kind`: lid, side door, other hinge)
    differs from the one it was chosen for: a first look that tilts a door's hinge into a lid's sent
    the hand to the door's top edge (cabinet door seed 3 with CAPT). The fingers
    approach ``approach_gap`` m apart (the Panda opens to 0.08 m; a narrower gap keeps a pitched fingertip
    off the surface a handle stands on, but under 6 cm a finger pitched across a drawer's bar clips its
    edge when the grasp point is half a centimetre off). Moves are capped at ``max_step_m`` /
    ``max_step_rad`` per control step; ``pos_tolerance`` / ``rot_tolerance`` end a move, as do
    ``move_timeout`` steps or ``blocked_steps`` steps without TCP motion (contact). A lid (a revolute part
    whose grasp point opens within ``lid_max_tilt`` rad of straight up, like a closed laptop) is gripped
    from above with the fingers ``lid_approach_gap`` m apart and closing along the hinge, across its front
    lip, ``lid_edge_offset`` m beyond the grasp point away from the hinge (so the pads clear the lid's
    edge whether the grasp point is the lip's centre, as with ground truth, or the outer band of its
    points, as from CAPT); the hand turns by ``lid_wrist_follow`` of the lid's angle (the pinch lets the
    lip turn between the pads; a hand turned with the lid would point back at the robot), and pulls to
    ``lid_revolute_target`` rad (past upright, so the lid does not rest on its hinge's friction just short
    of the success angle). If the fingers close on nothing across a lid's lip (it is wider than the open
    fingers), the hand backs off and lifts the lid from below (``lid_lift``): fingers closed, pointing at
    the hinge ``lid_lift_pitch`` rad below horizontal, the fingertips go ``lid_lift_below`` m under the
    grasp point, from ``lid_lift_front`` m in front of it to ``lid_lift_under`` m behind it, and push the
    lid open along the same arc as a pull, ``lid_lift_lead`` rad ahead of it (pushing from below, the
    fingertips carry the lid's weight; the larger lead pushes harder, through the stall near 0.4 rad
    that a lead of ``revolute_lead`` met with an estimated hinge), the hand turning by
    ``lid_lift_wrist_follow`` of the lid's angle and moving ``lid_lift_inward`` m towards the hinge per
    radian the lid has turned (on an estimated hinge 1-2 cm off, the fingertips following its arc slid off
    the lip at about 1.2 rad; sliding towards the hinge they stay under the lid). ``close_steps`` steps
    close the gripper. Pulling leads the part by ``revolute_lead`` rad or ``prismatic_lead`` m. The hand
    turns with a door about a vertical hinge, and by ``wrist_follow`` of the part's angle about any other
    hinge (a grasped bar turns between the pads; a hand turned fully with an oven door reaches the Panda's
    wrist limit). Pulling stops at ``revolute_target`` rad / ``prismatic_target`` m, or when the state
    grew by less than ``stall_progress`` rad / ``stall_progress_m`` m over ``stall_steps`` steps (a limit,
    or a lost grip).
    The gripper re-grasps (at most ``max_regrasps`` times) if it stays more than ``slip_distance`` m from
    the part's perceived grasp point for ``slip_steps`` steps (longer than the perception period, so one
    bad estimate, e.g. of a handle the hand now hides, is not a slip) and its fingers are less than
    ``hold_gap`` m apart (closed on nothing; a gap means they hold the handle, whatever the perceived
    grasp point says). With ``lid_slip_off_axis``, a lid's slip distance leaves out its component
    along the estimated hinge: a lid has no handle, and its grasp point (the mean of the far edge's
    visible points) slides along the edge as the hand hides part of it (laptop seeds 6 and 38 with a
    fine-tuned model: 11-13 cm along the hinge mid-pull read as a slip, and the re-grasps ran out
    the episode at 58% and 5% open). Pulling a prismatic part ends for good, without a re-grasp,
    when the hand, having pulled at a cruising speed of at least ``limit_min_speed_m`` m per step,
    moves less than
    ``limit_slowdown`` of that speed for ``limit_window`` steps: the part has hit its end stop (pulled on,
    the handle would slide out of the fingers and a re-grasp would chase an open drawer; gripped at
    ``prismatic_approach_pitch`` 0.3 rad the handle slides out sooner, the hand slowing only to 0.6-0.8
    of its speed: with 0.6, 63 of 200 drawer episodes ran 30 or more steps longer, the stop missed and
    the open drawer grasped twice more, seeds 4, 5, 8). When that brake is missed all the same (the
    handle slid out of the fingers at the end stop before the hand's slowing was read), a slip from a
    prismatic part whose state, by the hand's own measure, is past ``prismatic_stop_above`` m (0: off)
    also ends the pull for good: the re-grasp's approach pushed the open drawer back in (CAPT seeds
    34, 54, 119: pulled 100% open, slipped, then 21-42% open at the end). After release it
    backs off ``retreat_distance`` m. With ``regrasp_other_fingers``, fingers that close on nothing (gap
    below ``hold_gap``; not a lid's) open, back off and grasp again with the fingers the other way round
    (a re-grasp): for a low handle one of the two finger orders can leave a wrist joint at its limit short
    of the handle. With ``quarter_turn``, that is so only when the approach timed out (``move_timeout``)
    or a wrist joint is within ``wrist_limit_margin`` of its limit as the fingers close; otherwise the
    hand reached the handle (its goal, or blocked by touching it) and the handle does not lie across
    the fingers (a lever bar at right angles to a door's hinge, where the fingers close along the
    radius for a bar parallel to it), so this and later grasps turn the fingers a quarter turn about
    the approach (each such miss turns them back). A pull that stalls with one of the Panda's wrist
    joints (5, 6, 7) within ``wrist_limit_margin`` rad of its limit (0: off) grasps again that way
    too: the arm ran out of range
    with this finger order (oven doors), and grasping again the same way returns it to the same limit.
    A door that gravity opens further once let go (hinged below its grasp point about a non-vertical
    axis and not a lid: an oven door) is not grasped again once the pull ends (stall or slip) past
    ``fall_open_done`` rad by both the hand's measure and the perceived state (reaching for the handle
    of a door near level pushes it back). Let go past
    ``settle_above`` rad (a door let go nearer closed falls too slowly to wait for), the open hand
    backs off, moves ``settle_clearance`` m beyond the grasp radius about the estimated hinge (out of
    the door's sweep) and waits while the perceived state still rises by ``settle_progress`` rad over
    ``settle_window`` steps (a door falling open; one that creeps is grasped again; at most
    ``settle_max_steps``); then it is done if the door fell past ``fall_open_done`` and grasps again
    otherwise (``fall_open_done`` 0: all of this off). With ``watch_falling``, such a door seen falling
    open before it is grasped (at least ``settle_above`` rad open and risen by ``settle_progress`` rad
    over the last ``settle_window`` steps: the hand turning in front of it brushed it, or it was let go
    short of open) is not reached for (reaching for the handle pushed it back, oven seeds 57 and 129):
    the hand clears its sweep and waits the same way, then grasps it anew if it stopped short.
    A pull of any other revolute part (not a lid, nor a door that falls open) that stalls past
    ``revolute_stop_above`` rad (the hand's own measure), the fingers still holding and no wrist joint
    at its limit, has met the part's end stop and is not grasped again (0: off): a side-hinged door
    whose limit (1.5-2.0 rad) lies short of ``revolute_target`` stalls there, and grasping it again
    knocked it back towards closed.
    With ``arc_fit``, a hinge is also measured by the hand that holds its part: once the TCP, with the
    fingers apart (holding), has moved ``arc_fit_min_chord`` m and ``arc_fit_min_angle`` rad (about the
    estimated hinge) from where the pull began, a circle is fitted to its path about the estimated axis
    direction; if the path lies within ``arc_fit_max_rms`` m of that circle and its centre is within
    ``arc_fit_max_shift`` m of the estimated line, the centre replaces the estimated pivot for the rest of
    this pull (the swept angle and the arc the hand follows; the first accepted fit is kept, as a hand
    slipping off the handle later leaves the arc). A pivot a few cm off the hinge of a 20 cm door reads
    the swept angle 0.4 rad too large, and the hand lets go short of open.
    With ``motion_axis`` (off by default), the axis is also measured by how the part moved: the
    estimated grasp points seen while the fingers held the part (every pull of the episode) are fitted
    with a line (prismatic) or a circle in a plane (revolute: the plane's normal is the axis, the
    circle's centre its pivot; :func:`agents.scripted.motion_axis.fit_motion_axis`) once they spread
    ``motion_axis_min_travel`` m and, revolute, sweep ``motion_axis_min_angle`` rad and number
    ``motion_axis_hinge_points`` (a line needs 3; a plane and circle through 4 fit anything); a fit within
    ``motion_axis_max_rms`` m of the points, whose points spread off the line or plane at most
    ``motion_axis_max_ratio`` of their spread along it, and within ``motion_axis_max_turn`` rad of
    the estimated direction replaces the estimated axis for the rest of the episode (the pull starts
    over from where the hand is). An axis a few degrees off makes the commanded arc or line leave
    the part's own, and the fingers slide off it (``capt noise-sweep``).
    With ``rehearse_fingers`` (and the arm's joint angles in the observation), the two finger orders of
    a grasp (not a lid's) are first rehearsed on the Panda's kinematic model
    (:mod:`agents.scripted.grasp_rehearsal`): turn, pre-grasp, approach and the pull to its target,
    each step capped as above and every joint stopped at its limit. The other order than the one
    nearer the hand's rotation is taken only if it reaches the grasp pose (within twice the
    tolerances) and follows the whole pull path (tracked within ``rehearse_track_m`` m), and the
    nearer one does not reach the grasp pose or falls behind before ``1 - rehearse_margin`` of the
    path (when both fall behind part-way, which does better on the robot was a coin toss: oven
    seeds 35 and 140).
    """

    pregrasp_offset: float = 0.08
    grasp_depth: float = 0.01
    approach_pitch: float = 0.55
    prismatic_approach_pitch: float = 0.3
    slide_across_min_angle: float = 0.785
    hold_rising_above: float = 0.3
    vertical_hinge_pitch: float = 0.8
    vertical_hinge_max_tilt: float = 0.8
    rotate_first_above: float = 0.4
    rotate_first_steps: int = 25
    rechoose_grasp_m: float = 0.05
    rechoose_steps: int = 30
    rechoose_looks: int = 2
    rechoose_part_kind: bool = False
    max_step_m: float = 0.03
    max_step_rad: float = 0.15
    pos_tolerance: float = 0.012
    rot_tolerance: float = 0.12
    move_timeout: int = 60
    blocked_steps: int = 6
    approach_gap: float = 0.06
    lid_max_tilt: float = 0.5
    lid_approach_gap: float = 0.08
    lid_edge_offset: float = 0.005
    lid_wrist_follow: float = 0.0
    lid_revolute_target: float = 2.0
    lid_lift: bool = True
    lid_lift_pitch: float = 1.3
    lid_lift_below: float = 0.010
    lid_lift_front: float = 0.06
    lid_lift_under: float = 0.0
    lid_lift_wrist_follow: float = 0.0
    lid_lift_inward: float = 0.02
    lid_lift_lead: float = 0.2
    close_steps: int = 8
    revolute_lead: float = 0.12
    prismatic_lead: float = 0.03
    wrist_follow: float = 0.5
    revolute_target: float = 1.7
    prismatic_target: float = 0.4
    stall_progress: float = 0.02
    stall_progress_m: float = 0.004
    stall_steps: int = 12
    slip_distance: float = 0.07
    slip_steps: int = 8
    lid_slip_off_axis: bool = True
    hold_gap: float = 0.004
    limit_slowdown: float = 0.8
    limit_window: int = 2
    limit_min_speed_m: float = 0.005
    max_regrasps: int = 2
    regrasp_other_fingers: bool = True
    quarter_turn: bool = True
    wrist_limit_margin: float = 0.05
    retreat_distance: float = 0.08
    fall_open_done: float = 1.3
    revolute_stop_above: float = 1.4
    prismatic_stop_above: float = 0.15
    settle_above: float = 0.8
    settle_clearance: float = 0.1
    settle_window: int = 10
    settle_progress: float = 0.06
    settle_max_steps: int = 40
    watch_falling: bool = True
    release_steps: int = 6
    arc_fit: bool = True
    arc_fit_min_chord: float = 0.06
    arc_fit_min_angle: float = 0.3
    arc_fit_max_rms: float = 0.004
    arc_fit_max_shift: float = 0.15
    motion_axis: bool = False
    motion_axis_min_travel: float = 0.03
    motion_axis_min_angle: float = 0.4
    motion_axis_max_rms: float = 0.004
    motion_axis_max_turn: float = 0.6
    motion_axis_max_ratio: float = 0.1
    motion_axis_hinge_points: int = 6
    rehearse_fingers: bool = True
    rehearse_margin: float = 0.2
    rehearse_track_m: float = 0.02

    def validate(self) -> None:
        for key in ("pregrasp_offset", "max_step_m", "max_step_rad", "pos_tolerance", "rot_tolerance",
                    "revolute_lead", "lid_lift_lead", "prismatic_lead", "stall_progress", "stall_progress_m",
                    "revolute_target", "prismatic_target", "lid_revolute_target",
                    "slip_distance", "hold_gap", "limit_min_speed_m", "arc_fit_min_chord",
                    "arc_fit_min_angle", "arc_fit_max_rms", "arc_fit_max_shift", "settle_progress",
                    "motion_axis_min_travel", "motion_axis_min_angle", "motion_axis_max_rms",
                    "motion_axis_max_turn", "motion_axis_max_ratio"):
            require(getattr(self, key) > 0, f"{key} must be > 0, got {getattr(self, key)}")
        require(0.0 < self.rehearse_margin <= 1.0,
                f"rehearse_margin must be in (0, 1] (a share of the pull path), got {self.rehearse_margin}")
        require(self.rehearse_track_m > 0, f"rehearse_track_m must be > 0 m, got {self.rehearse_track_m}")
        require(self.rotate_first_above > 0,
                f"rotate_first_above must be > 0 rad, got {self.rotate_first_above}")
        require(self.rechoose_grasp_m >= 0,
                f"rechoose_grasp_m must be >= 0 m (0: never), got {self.rechoose_grasp_m}")
        require(self.rechoose_steps >= 0, f"rechoose_steps must be >= 0, got {self.rechoose_steps}")
        require(self.rechoose_looks >= 1, f"rechoose_looks must be >= 1, got {self.rechoose_looks}")
        require(self.motion_axis_hinge_points >= 4,
                f"motion_axis_hinge_points must be >= 4, got {self.motion_axis_hinge_points}")
        require(self.rotate_first_steps >= 0,
                f"rotate_first_steps must be >= 0 (0: never), got {self.rotate_first_steps}")
        for key in ("move_timeout", "blocked_steps", "close_steps", "stall_steps", "release_steps",
                    "slip_steps", "limit_window", "settle_window", "settle_max_steps"):
            require(getattr(self, key) >= 1, f"{key} must be >= 1, got {getattr(self, key)}")
        require(0.0 < self.approach_gap <= 0.08,
                f"approach_gap must be in (0, 0.08] m, got {self.approach_gap}")
        for key in ("wrist_follow", "lid_wrist_follow", "lid_lift_wrist_follow"):
            value = getattr(self, key)
            require(0.0 <= value <= 1.0, f"{key} must be in [0, 1], got {value}")
        require(0.0 < self.lid_approach_gap <= 0.08,
                f"lid_approach_gap must be in (0, 0.08] m, got {self.lid_approach_gap}")
        require(self.lid_edge_offset >= 0, f"lid_edge_offset must be >= 0 m, got {self.lid_edge_offset}")
        require(0.0 < self.lid_lift_pitch <= 1.5,
                f"lid_lift_pitch must be in (0, 1.5] rad, got {self.lid_lift_pitch}")
        for key in ("lid_lift_below", "lid_lift_front", "lid_lift_under", "lid_lift_inward"):
            require(getattr(self, key) >= 0, f"{key} must be >= 0 m, got {getattr(self, key)}")
        require(0.0 < self.limit_slowdown < 1.0,
                f"limit_slowdown must be in (0, 1), got {self.limit_slowdown}")
        require(self.max_regrasps >= 0, "max_regrasps must be >= 0")
        require(self.fall_open_done >= 0,
                f"fall_open_done must be >= 0 rad (0: off), got {self.fall_open_done}")
        require(self.revolute_stop_above >= 0,
                f"revolute_stop_above must be >= 0 rad (0: off), got {self.revolute_stop_above}")
        require(0.0 <= self.slide_across_min_angle <= np.pi,
                f"slide_across_min_angle must be in [0, pi] rad (past pi/2: never), "
                f"got {self.slide_across_min_angle}")
        require(0.0 <= self.hold_rising_above <= 1.5,
                f"hold_rising_above must be in [0, 1.5] rad (0: off), got {self.hold_rising_above}")
        require(self.prismatic_stop_above >= 0,
                f"prismatic_stop_above must be >= 0 m (0: off), got {self.prismatic_stop_above}")
        require(self.settle_above >= 0, f"settle_above must be >= 0 rad, got {self.settle_above}")
        require(self.settle_clearance >= 0,
                f"settle_clearance must be >= 0 m, got {self.settle_clearance}")
        require(0.0 <= self.wrist_limit_margin < 0.5,
                f"wrist_limit_margin must be in [0, 0.5) rad (0: off), got {self.wrist_limit_margin}")
        for key in ("approach_pitch", "prismatic_approach_pitch", "vertical_hinge_pitch",
                    "vertical_hinge_max_tilt", "lid_max_tilt"):
            value = getattr(self, key)
            require(0 <= value <= 1.5, f"{key} must be in [0, 1.5] rad, got {value}")
