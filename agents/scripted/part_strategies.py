"""Part-kind strategies of the scripted opener: what the opener does differently for a lid, a side
door, a door that falls open, any other hinged part, a drawer and a sliding panel (world frame;
metres, radians).

:func:`strategy_for` tells the kind from the joint-axis estimate (and, for a sliding part, the
direction to the robot's base) with the predicates of :mod:`agents.scripted.grasp_pose`; the reach
phases choose it with each grasp and the context keeps it (``ctx.grasp.strategy``). The phases then
ask it, instead of branching on the kind: where the TCP grips and how the hand is turned
(:meth:`PartStrategy.grasp_rotation`, :meth:`PartStrategy.grasp_target`), the approach gap, whether
the finger orders are rehearsed, what fingers that closed on nothing do, and the pull's target,
lead, wrist follow, slip measure and whether a stall far open is an end stop. Each strategy owns its
config group (``Lid`` reads ``lid``, ``SideDoor`` ``side_door``, ...) and reads the shared groups
(``approach``, ``pull``) for what it does like any other part.

Rules that a phase reads from the look at hand rather than from the kind of the grasp stay with the
phase: the joint type the current estimate shows (arc or line), a hinge the current estimate shows
vertical (:meth:`PartStrategy.hand_turn`), a door that falls open by the estimate a pull began with
(``ctx.pull.falls``), and a sliding part that rises (``sliding_panel.hold_rising_above``, any
prismatic pull).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from agents.scripted.config import (
    DrawerConfig,
    FallingDoorConfig,
    LidConfig,
    ScriptedOpenerConfig,
    SideDoorConfig,
    SlidingPanelConfig,
)
from agents.scripted.geometry import axis_angle_matrix, grasp_frame, off_axis, perpendicular
from agents.scripted.grasp_pose import (
    UP,
    falls_open,
    is_lid,
    is_vertical_hinge,
    lid_frame,
    nearer_finger_order,
    outward_normal,
    pitched_down,
    slides_across_face,
)
from capt_env.wrappers.estimate import JointAxisEstimate, unit

FULL_TURN = 1.0  # share of a side door's angle a hand across a level bar turns by


class PartStrategy(ABC):
    """How one kind of part is grasped and pulled. Built from the whole config (``Lid(cfg)``); each
    kind reads its own group (``own``) and the shared ``approach`` and ``pull`` groups.

    ``name``: the kind. ``grasp_kind``: what :func:`~agents.scripted.grasp_pose.part_kind` calls it
    (``"lid"``, ``"vertical_hinge"``, ``"hinge"``, ``"prismatic"``: kinds grasped alike share one;
    ``approach.rechoose_part_kind`` compares these).
    """

    name: ClassVar[str]
    grasp_kind: ClassVar[str]
    falls_open: ClassVar[bool] = False
    """Gravity opens the part further once let go (:class:`FallingDoor`)."""
    rehearses: ClassVar[bool] = True
    """Both finger orders are rehearsed on the arm's model (``grasp.rehearse_fingers``)."""
    turns_fingers_on_miss: ClassVar[bool] = True
    """Fingers that closed on nothing grasp again with the fingers turned (``recovery.other_fingers``,
    ``recovery.quarter_turn``)."""
    stall_can_be_end_stop: ClassVar[bool] = True
    """A held pull that stalls past ``pull.revolute.stop_above`` is at the part's end stop."""

    def __init__(self, cfg: ScriptedOpenerConfig) -> None:
        self.cfg = cfg

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    # -- the grasp --

    def approach_normal(self, est: JointAxisEstimate, robot_side: np.ndarray | None) -> np.ndarray:
        """World unit direction (3,) out of the face the hand grips, which it approaches against: the
        :func:`~agents.scripted.grasp_pose.outward_normal` (the way the grasp point moves as the part
        opens), where the handle stands off the face."""
        return outward_normal(est)

    @abstractmethod
    def closing(self, est: JointAxisEstimate, approach: np.ndarray,
                robot_side: np.ndarray | None) -> np.ndarray | None:
        """Unit direction (3,) the fingers close along, across the handle, for unit ``approach`` (3,);
        None when the kind's choice is parallel to the approach."""

    @property
    def pitch(self) -> float:
        """The approach points at least this far below horizontal (rad): ``approach.pitch``."""
        return self.cfg.approach.pitch

    @property
    def gap(self) -> float:
        """Finger gap while approaching (m): ``approach.gap``."""
        return self.cfg.approach.gap

    def along_slack(self, est: JointAxisEstimate) -> float:
        """How far (m) along the joint axis the reach may keep the hand's own place instead of the grasp
        point's: 0, a handle is gripped where it is."""
        return 0.0

    def grasp_target(self, est: JointAxisEstimate) -> np.ndarray:
        """World point (3,) the TCP grips: the grasp point (a handle's)."""
        return est.grasp_point

    def grasp_rotation(self, est: JointAxisEstimate, current: np.ndarray,
                       robot_side: np.ndarray | None = None) -> np.ndarray:
        """TCP rotation (3, 3) for grasping: approach along minus :meth:`approach_normal`
        (``robot_side`` (3,): the direction from the grasp point to the robot's base), the fingers
        closing along :meth:`closing`, pitched down to at least :attr:`pitch`; of the two finger
        orders the one nearer ``current`` (3, 3)."""
        approach = -self.approach_normal(est, robot_side)
        closing = self.closing(est, approach, robot_side)
        if closing is None:
            closing = perpendicular(approach, np.array([0.0, 1.0, 0.0]))
            assert closing is not None
        return nearer_finger_order(pitched_down(grasp_frame(approach, closing), self.pitch), current)

    # -- fingers that closed on nothing --

    def lifts_from_below(self, lifting: bool) -> bool:
        """Whether fingers that closed on nothing back off and lift the part from below (``lifting``:
        already doing so). Only a lid's lip is lifted."""
        return False

    # -- the pull --

    def pull_target(self, revolute: bool) -> float:
        """The state (rad or m) at which the pull ends, for a part the current look shows ``revolute``
        or sliding: ``pull.revolute.target`` or ``pull.prismatic.target``."""
        return self.cfg.pull.revolute.target if revolute else self.cfg.pull.prismatic.target

    def pull_lead(self, lifting: bool) -> float:
        """The angle (rad) by which the commanded TCP leads a hinged part along its arc (the pull's
        force): ``pull.revolute.lead``."""
        return self.cfg.pull.revolute.lead

    def wrist_follow(self, lifting: bool) -> float:
        """The share of the part's angle the hand turns by about a hinge that is not vertical:
        ``pull.revolute.wrist_follow`` (a bar turns between the pads; a hand turned fully with an oven
        door reaches the Panda's wrist limit)."""
        return self.cfg.pull.revolute.wrist_follow

    def hand_turn(self, est: JointAxisEstimate, lifting: bool, grasp_r: np.ndarray,
                  prying: bool = False) -> float:
        """The share of the part's angle the hand turns by while pulling about ``est``'s hinge, for a
        grasp with TCP rotation ``grasp_r`` (3, 3). About a hinge ``est`` shows vertical (a side
        door's: the wrist has room): fully for a hand closed across a level bar (a lever stays square
        in the fingers), ``side_door.upright_bar_follow`` for one closing level, across an upright bar
        (:func:`closes_across_level_bar`), or ``side_door.pry_follow`` once that bar has pried the
        fingers apart (``prying``); else :meth:`wrist_follow`. Read from the look at hand, not from
        the kind of the grasp: the hinge seen while pulling is the one the hand follows."""
        if not is_vertical_hinge(est, self.cfg):
            return self.wrist_follow(lifting)
        if closes_across_level_bar(grasp_r):
            return FULL_TURN
        return self.cfg.side_door.pry_follow if prying else self.cfg.side_door.upright_bar_follow

    def pulling_rotation(self, est: JointAxisEstimate, lifting: bool, grasp_r: np.ndarray, u: np.ndarray,
                         delta: float, turned: float, prying: bool = False) -> np.ndarray:
        """The pulling hand's rotation (3, 3) about a hinge along unit ``u`` (3,): the grasp rotation
        ``grasp_r`` (3, 3) turned by :meth:`hand_turn`'s share of ``delta`` (rad along the arc the hand
        is sent to; ``prying``: see there), then :meth:`pull_rotation` for the part turned ``turned``
        rad since the grasp. The pull and the finger-order rehearsal both ask this."""
        follow = self.hand_turn(est, lifting, grasp_r, prying)
        return self.pull_rotation(axis_angle_matrix(u, follow * delta) @ grasp_r, turned)

    def inward(self, lifting: bool) -> float:
        """How far (m per radian turned) the pulling hand moves towards the hinge off the arc: 0."""
        return 0.0

    def press(self, lifting: bool) -> float:
        """How far (m) the pulling hand is sent towards the hinge from where it is: 0."""
        return 0.0

    def slip_behind(self, lifting: bool) -> float:
        """How far (rad) the perceived part must lag the hand's measure for a slip as well: 0 (the
        grasp point alone decides)."""
        return 0.0

    def pull_rotation(self, r: np.ndarray, turned: float) -> np.ndarray:
        """The pulling hand's rotation (3, 3) for ``r`` (3, 3), the grasp rotation turned with the part,
        when the part has turned ``turned`` rad since the grasp: ``r``."""
        return r

    def slip_offset(self, away: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The part of the hand's offset ``away`` (3,) m from the perceived grasp point that counts
        towards a slip (``pull.slip_distance``), for the part's unit axis ``u`` (3,): all of it."""
        return away


class Hinged(PartStrategy):
    """A hinged part that is none of the kinds below (a flap hinged at its top, which gravity
    closes): approached along its outward normal, pitched ``approach.pitch`` down, the fingers
    closing along the radius from the hinge, across a handle bar that runs along the hinge; pulled
    with the ``pull.revolute`` options."""

    name = "hinge"
    grasp_kind = "hinge"

    def closing(self, est: JointAxisEstimate, approach: np.ndarray,
                robot_side: np.ndarray | None) -> np.ndarray | None:
        return perpendicular(approach, est.grasp_point - est.pivot)


LEVEL_CLOSING_SINE = 0.5
"""Fingers whose closing direction rises less than 30 deg (this sine) from level close level, across
an upright bar; a side door's grasp closes either level (across a bar along the hinge) or, turned a
quarter turn across a level bar (a lever), at the approach's pitch from vertical (44 deg at 0.8 rad)."""

PALM_CLEAR_PITCH = float(np.arctan2(0.0374, 0.0316))
"""rad (0.87): below this pitch below level, an upright bar held at the TCP between level-closing
fingers passes outside the palm: the Panda hand's collision mesh ends 3.74 cm behind the TCP and
spans 3.16 cm either side of the fingers' plane, and at pitch p the bar runs 3.74 / tan(p) cm across
that plane there. ``side_door.pitch`` (0.8) lies below it."""


def closes_across_level_bar(r: np.ndarray) -> bool:
    """Whether a TCP rotation ``r`` (3, 3; its y the closing direction) has fingers that close across
    a level bar: the closing direction rises at least 30 deg from level (:data:`LEVEL_CLOSING_SINE`)."""
    return abs(float(r[2, 1])) >= LEVEL_CLOSING_SINE


class SideDoor(Hinged):
    """A door on a hinge within ``side_door.max_tilt`` of vertical (:func:`~agents.scripted.grasp_pose.
    is_vertical_hinge`): grasped as any hinged part, pitched ``side_door.pitch`` down (the hand has
    room to turn with the door, so it can start pitched further); the hand turns with it
    (:meth:`PartStrategy.hand_turn`)."""

    name = "side_door"
    grasp_kind = "vertical_hinge"

    def __init__(self, cfg: ScriptedOpenerConfig) -> None:
        super().__init__(cfg)
        self.own: SideDoorConfig = cfg.side_door

    @property
    def pitch(self) -> float:
        return self.own.pitch

    def pull_rotation(self, r: np.ndarray, turned: float) -> np.ndarray:
        """``r`` pitched down to ``side_door.pitch`` plus ``side_door.pull_roll`` times the angle
        ``turned`` (rad) beyond ``side_door.pull_roll_from``, at most ``side_door.max_pull_pitch``,
        about the horizontal axis across its approach (:func:`~agents.scripted.grasp_pose.
        pitched_down`), when the fingers close across a level bar (:func:`closes_across_level_bar`):
        a hand square to a door swung far round has its wrist out beyond the door, where the arm runs
        out of reach. That axis is then the bar itself, and the grip turns about what it holds. A
        hand whose fingers close level holds an upright bar (a side door's bar runs along its hinge),
        and that axis is the line between its fingertips: pitching turns the bar in the grip, and
        past :data:`PALM_CLEAR_PITCH` the bar's upper end meets the palm, which pushes the door and
        prises the bar out of the fingers (Franka Kitchen's microwave, whose bar runs the door's
        height). Such a hand keeps ``r``."""
        beyond = turned - self.own.pull_roll_from
        if self.own.pull_roll <= 0.0 or beyond <= 0.0 or not closes_across_level_bar(r):
            return r
        return pitched_down(r, min(self.own.pitch + self.own.pull_roll * beyond, self.own.max_pull_pitch))


class FallingDoor(Hinged):
    """A door that gravity opens further once let go (:func:`~agents.scripted.grasp_pose.falls_open`:
    hinged below its grasp point about a non-vertical axis, not a lid; an oven door). Grasped and
    pulled as any hinged part; its ``falling_door`` options say when it is let fall and waited for
    rather than grasped again (reaching for the handle of a door near level pushes it back): the
    pull, the release and the reach read them for a part whose pull began on such a door
    (``ctx.pull.falls``) or that is seen falling before its grasp."""

    name = "falling_door"
    grasp_kind = "hinge"
    falls_open = True

    def __init__(self, cfg: ScriptedOpenerConfig) -> None:
        super().__init__(cfg)
        self.own: FallingDoorConfig = cfg.falling_door


class Lid(Hinged):
    """A hinged part whose grasp point opens within ``lid.max_tilt`` of straight up (a closed laptop's
    lid; :func:`~agents.scripted.grasp_pose.is_lid`): no handle, so the hand comes down from above
    and pinches the front lip, the fingers closing along the hinge; a lip wider than the open fingers
    is lifted from below instead (``lid.lift``)."""

    name = "lid"
    grasp_kind = "lid"
    rehearses = False  # the pinch from above has one approach; the rehearsal compares handle grasps
    turns_fingers_on_miss = False  # an empty pinch is a lip wider than the fingers: lifted instead
    stall_can_be_end_stop = False  # the pull runs to lid.target, past upright; a stall is not the stop

    def __init__(self, cfg: ScriptedOpenerConfig) -> None:
        super().__init__(cfg)
        self.own: LidConfig = cfg.lid

    def closing(self, est: JointAxisEstimate, approach: np.ndarray,
                robot_side: np.ndarray | None) -> np.ndarray | None:
        # a part lying flat and opening upwards: along the radius one finger would come down on the
        # part itself, so the fingers close along the hinge, across the lid's front lip
        return perpendicular(approach, unit(est.direction))

    @property
    def gap(self) -> float:
        """``lid.gap``: fully open, to take the lip's thickness and the estimate's error."""
        return self.own.gap

    def grasp_target(self, est: JointAxisEstimate) -> np.ndarray:
        """The grasp point moved ``lid.edge_offset`` further from the hinge (the pads then clear the
        lid's edge), while ``est`` still shows a lid; a look that does not is gripped at its grasp
        point."""
        frame = lid_frame(est) if is_lid(est, self.cfg) else None
        return est.grasp_point if frame is None else est.grasp_point + self.own.edge_offset * frame[0]

    def along_slack(self, est: JointAxisEstimate) -> float:
        """``lid.along_slack`` while ``est`` shows a lid (its grip is a lip along the hinge)."""
        return self.own.along_slack if is_lid(est, self.cfg) else 0.0

    def lift_pose(self, est: JointAxisEstimate, current: np.ndarray,
                  under: bool) -> tuple[np.ndarray, np.ndarray] | None:
        """TCP goal (position (3,) m, rotation (3, 3)), world frame, for lifting the lid from below: the
        closed fingertips, pointing at the hinge and ``lid.lift.pitch`` rad down, go ``lid.lift.below``
        m under the grasp point, ``lid.lift.front`` m in front of it (``under`` False: where the hand
        lines up) or ``lid.lift.under`` m behind it (``under`` True: where it slides to). None when the
        grasp point lies on the hinge line."""
        frame = lid_frame(est)
        if frame is None:
            return None
        front, up = frame
        lift = self.own.lift
        approach = -np.cos(lift.pitch) * front - np.sin(lift.pitch) * up
        # front, up and the hinge are orthonormal; the fingers close along the hinge
        rot = nearer_finger_order(grasp_frame(approach, unit(est.direction)), current)
        ahead = -lift.under if under else lift.front
        return est.grasp_point + ahead * front - lift.below * up, rot

    def lifts_from_below(self, lifting: bool) -> bool:
        """With ``lid.lift.enabled``, unless already lifting: the fingers closed on nothing across the
        lip, which is wider than the open fingers."""
        return self.own.lift.enabled and not lifting

    def pull_target(self, revolute: bool) -> float:
        """``lid.target`` (past upright, so the lid does not rest on its hinge's friction just short of
        the success angle) while the look shows it hinged."""
        return self.own.target if revolute else self.cfg.pull.prismatic.target

    def pull_lead(self, lifting: bool) -> float:
        """``lid.lift.lead`` while lifting from below (the fingertips carry the lid's weight and push
        through the stall near 0.4 rad), else ``pull.revolute.lead``."""
        return self.own.lift.lead if lifting else self.cfg.pull.revolute.lead

    def wrist_follow(self, lifting: bool) -> float:
        """``lid.lift.wrist_follow`` while lifting, else ``lid.wrist_follow``: the pinch lets the lip
        turn between the pads, and a hand turned with the lid would point back at the robot."""
        return self.own.lift.wrist_follow if lifting else self.own.wrist_follow

    def inward(self, lifting: bool) -> float:
        """``lid.lift.inward`` while lifting: on an estimated hinge 1-2 cm off, fingertips following
        its arc slide off the lip; sliding towards the hinge they stay under it."""
        return self.own.lift.inward if lifting else 0.0

    def press(self, lifting: bool) -> float:
        """``lid.lift.press`` while lifting: the fingertips stay pressed into the lid's front face
        whatever the estimated hinge's error."""
        return self.own.lift.press if lifting else 0.0

    def slip_behind(self, lifting: bool) -> float:
        """``lid.lift.slip_behind`` while lifting: the perceived angle, not the grasp point, tells a
        hand that ran on from a lid it no longer carries."""
        return self.own.lift.slip_behind if lifting else 0.0

    def slip_offset(self, away: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Without the part along the hinge (``lid.slip_off_axis``): a lid has no handle, and its grasp
        point (the middle of the far edge's visible points) slides along the edge as the hand hides
        part of it."""
        return off_axis(away, u) if self.own.slip_off_axis else away


class Sliding(PartStrategy):
    """A sliding part, pulled along its axis with the ``pull.prismatic`` options."""

    grasp_kind = "prismatic"


class Drawer(Sliding):
    """A sliding part that comes out of the face its handle is on, towards the robot: approached along
    its axis, pitched ``drawer.pitch`` down, the fingers closing in the vertical plane of the
    approach, across a horizontal bar on its front."""

    name = "drawer"

    def __init__(self, cfg: ScriptedOpenerConfig) -> None:
        super().__init__(cfg)
        self.own: DrawerConfig = cfg.drawer

    def closing(self, est: JointAxisEstimate, approach: np.ndarray,
                robot_side: np.ndarray | None) -> np.ndarray | None:
        return perpendicular(approach, UP)

    @property
    def pitch(self) -> float:
        """``drawer.pitch``: a drawer's bar is pulled along the approach, and fingers pitched further
        squeeze it out along the pull; a handle near the table approached steeper runs wrist joint 5
        into its limit."""
        return self.own.pitch


class SlidingPanel(Sliding):
    """A sliding part that slides across the face its handle is on (a window sliding up, a sliding
    door; :func:`~agents.scripted.grasp_pose.slides_across_face`): its handle stands off that face
    towards the robot, so the hand comes at the face square on from the robot's side, pitched
    ``approach.pitch`` down, the fingers closing along the slide; pulled along its axis whatever way
    that points."""

    name = "sliding_panel"

    def __init__(self, cfg: ScriptedOpenerConfig) -> None:
        super().__init__(cfg)
        self.own: SlidingPanelConfig = cfg.sliding_panel

    def approach_normal(self, est: JointAxisEstimate, robot_side: np.ndarray | None) -> np.ndarray:
        """The part of ``robot_side`` across the axis (the face turned to the robot), whatever direction
        the part then slides in."""
        assert robot_side is not None
        face = perpendicular(unit(est.direction), perpendicular(UP, np.asarray(robot_side, dtype=np.float64)))
        return outward_normal(est) if face is None else face

    def closing(self, est: JointAxisEstimate, approach: np.ndarray,
                robot_side: np.ndarray | None) -> np.ndarray | None:
        # the fingers close along the slide: one pad pushes the handle the way the part moves, so the
        # pull does not rest on friction, and a bar across the slide lies between them
        return perpendicular(approach, unit(est.direction))


STRATEGIES: tuple[type[PartStrategy], ...] = (Lid, SideDoor, FallingDoor, Hinged, SlidingPanel, Drawer)
"""Every kind, in the order :func:`strategy_for` tells them apart."""


def strategy_for(est: JointAxisEstimate, cfg: ScriptedOpenerConfig,
                 robot_side: np.ndarray | None = None) -> PartStrategy:
    """The strategy for the part ``est`` describes. A hinged part is a :class:`Lid`
    (:func:`~agents.scripted.grasp_pose.is_lid`), else a :class:`SideDoor`
    (:func:`~agents.scripted.grasp_pose.is_vertical_hinge`), else a :class:`FallingDoor`
    (:func:`~agents.scripted.grasp_pose.falls_open`), else :class:`Hinged`. A sliding part is a
    :class:`SlidingPanel` when it slides across the face turned to ``robot_side`` (3,), the direction
    from the grasp point to the robot's base (:func:`~agents.scripted.grasp_pose.slides_across_face`),
    else (or without ``robot_side``) a :class:`Drawer`."""
    if est.joint_type == "revolute":
        if is_lid(est, cfg):
            return Lid(cfg)
        if is_vertical_hinge(est, cfg):
            return SideDoor(cfg)
        return FallingDoor(cfg) if falls_open(est, cfg) else Hinged(cfg)
    return SlidingPanel(cfg) if slides_across_face(est, cfg, robot_side) else Drawer(cfg)
