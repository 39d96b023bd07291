"""The per-episode state the opener's phases share (:class:`OpenerContext`), world frame, metres,
radians, control steps, among it the part-kind strategy chosen with the grasp under way
(:class:`GraspChoice`, :meth:`OpenerContext.grip`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.grasp_rehearsal import Rehearsal
from agents.scripted.motion_axis import MotionAxis
from agents.scripted.part_strategies import Drawer, Hinged, Lid, PartStrategy
from agents.scripted.phases.base import Look, MoveTracker, OpenerPhase, Phase
from capt_env.wrappers.estimate import JointAxisEstimate


@dataclass
class GraspChoice:
    """The grasp being made: its TCP rotation and what it was chosen for."""

    cfg: ScriptedOpenerConfig = field(repr=False)
    """The opener's options (for :attr:`lid`'s setter)."""
    target_r: np.ndarray | None = None
    """TCP rotation (3, 3) to grasp with; None: choose it on the next pre-grasp step (a new grasp)."""
    target_for: np.ndarray | None = None
    """The grasp point (3,) m ``target_r`` was chosen for."""
    looks: list[np.ndarray] = field(default_factory=list)
    """The grasp points (3,) of the last ``approach.rechoose_looks`` looks (distinct estimates)."""
    strategy: PartStrategy | None = None
    """The part-kind strategy (:func:`~agents.scripted.part_strategies.strategy_for`) ``target_r`` was
    chosen with; None before a grasp is chosen."""
    kinds: list[str] = field(default_factory=list)
    """The part kinds (``grasp_kind``) of the last ``approach.rechoose_looks`` looks since then."""
    kind_key: np.ndarray | None = None
    """The last look's grasp point and axis direction (6,), to tell a new look."""
    swap_this_grasp: bool = False
    """This grasp turns the fingers the other way round (see ``other_fingers``)."""
    other_fingers: bool = False
    """The next grasp turns the fingers the other way round (a wrist joint ran to its limit)."""
    quarter: bool = False
    """Grasps turn the fingers a quarter turn about the approach (``recovery.quarter_turn``)."""
    pregrasp_steps: int = 0
    """Steps this grasp has spent in the pre-grasp, moves started over included."""

    @property
    def lid(self) -> bool:
        """The part is a lid (gripped from above across its lip), as the grasp was chosen: its strategy
        is a :class:`~agents.scripted.part_strategies.Lid`. Set True, the grasp takes the lid's
        strategy; set False, it forgets its strategy."""
        return isinstance(self.strategy, Lid)

    @lid.setter
    def lid(self, value: bool) -> None:
        self.strategy = Lid(self.cfg) if value else None


@dataclass
class PullTrack:
    """The pull under way, measured by the hand that holds the part."""

    grasp_p: np.ndarray | None = None
    """TCP position (3,) m where the pull began (or where a fitted motion axis restarted it)."""
    grasp_r: np.ndarray | None = None
    """TCP rotation (3, 3) there."""
    grasp_state: float = 0.0
    """The part's state (rad or m) there: the estimate's at the grasp, then the hand's own measure."""
    grasp_pivot: np.ndarray | None = None
    """The estimated pivot (3,) m when the pull began: the arc's centre until the part's own motion
    measures one (``pull.arc_fit``, ``pull.motion_axis``)."""
    grasp_seen: np.ndarray | None = None
    """The perceived grasp point (3,) m when the pull began."""
    grasp_u: np.ndarray | None = None
    """Unit axis (3,) the part opened along when the pull began (a re-estimate that flips it is turned
    back)."""
    history: list[float] = field(default_factory=list)
    """The hand's measure of the part's state (rad or m), every pull step."""
    pulled: list[np.ndarray] = field(default_factory=list)
    """TCP positions (3,) m of this pull, every step."""
    held: list[np.ndarray] = field(default_factory=list)
    """Those while the fingers held the part (for the arc fit of a hinge, the line fit of a slide)."""
    hinge_fit: np.ndarray | None = None
    """The hinge pivot (3,) m fitted to the held path (``pull.arc_fit``), kept for the pull."""
    line_fit: np.ndarray | None = None
    """The unit direction (3,) of the line fitted to the held path of a sliding part
    (``pull.prismatic.track_fit_travel``), the latest accepted this pull."""
    line_gap: float | None = None
    """The finger gap (m) at the last step the hand held the sliding part this pull."""
    line_slipped: bool = False
    """The gap jumped (``pull.prismatic.track_fit_max_gap_change``): the hand's path no longer counts."""
    slip_count: int = 0
    """Steps running the hand has been off the grasp point with its fingers closed on nothing."""
    first_gap: float | None = None
    """The finger gap (m) at the first step of this pull the fingers held the part."""
    prying: bool = False
    """A held bar has widened the finger gap by more than ``side_door.pry_gap`` this pull."""
    step_share: float = 1.0
    """The share of the commanded steps the pull moves by (``pull.step_shrink``)."""
    last_q: np.ndarray | None = None
    """The arm's joint angles (7,) rad at the last pull step."""
    falls: bool = False
    """The part falls open when let go: the estimate the pull began with shows a
    :class:`~agents.scripted.part_strategies.FallingDoor` (a door near level, its handle hidden by the
    hand, can be far off later)."""


@dataclass
class MotionTrack:
    """The axis measured by the part's own motion (``pull.motion_axis``), over the whole episode."""

    part_path: list[np.ndarray] = field(default_factory=list)
    """Estimated grasp points (3,) m seen while the fingers held the part, every pull."""
    motion: MotionAxis | None = None
    """The axis fitted to them, once accepted (kept for the episode)."""
    motion_type: str = ""
    """The joint type it was fitted for."""


@dataclass
class OpenerContext:
    """Everything the phases share over one episode. The phase now running is the policy's."""

    cfg: ScriptedOpenerConfig
    now: Look | None = None
    """This control step's inputs."""
    steps: int = 0
    """Control steps this episode."""
    phase_steps: int = 0
    """Control steps in the current phase (1 on its first step)."""
    phase_log: list[dict[str, Any]] = field(default_factory=list)
    """One entry per phase entered: ``{"step", "phase", "why"}``, a pull's with its ``"grip"``
    (``"none"``, ``"held"``, ``"lost"``; see :func:`agents.scripted.phases.pull.record_grip`)."""
    move: MoveTracker = field(default_factory=MoveTracker)
    grasp: GraspChoice = field(init=False)
    """The grasp being made and the strategy it was chosen with."""
    pull: PullTrack = field(default_factory=PullTrack)
    axis: MotionTrack = field(default_factory=MotionTrack)
    regrasps: int = 0
    """Grasps after the first so far (at most ``recovery.max_regrasps``)."""
    lift: bool = False
    """The lid is lifted from below from now on (its lip is wider than the open fingers)."""
    grasp_again: bool = False
    """After the release and retreat under way, grasp again (else done)."""
    let_go_state: float = 0.0
    """The part's state (rad or m) when a pull last let go of it."""
    retreat_from: np.ndarray | None = None
    """TCP position (3,) m the retreat backs off from."""
    settle: list[float] | None = None
    """Perceived states (rad) while waiting for a door that falls open; None when not waiting."""
    watch: list[float] = field(default_factory=list)
    """Perceived states (rad) of a door that falls open, watched before its grasp."""
    hold_at: tuple[np.ndarray, np.ndarray] | None = None
    """TCP pose (position, rotation) at which the done hand holds a part that would fall back closed."""
    base: np.ndarray | None = None
    """The robot base's position (3,) m, once joint angles are seen."""
    rehearsals: tuple[Rehearsal, Rehearsal] | None = None
    """The last finger-order rehearsal (nearer order, other order)."""

    def __post_init__(self) -> None:
        self.grasp = GraspChoice(self.cfg)

    def grip(self, est: JointAxisEstimate) -> PartStrategy:
        """The strategy of the grasp under way (``grasp.strategy``). Before any grasp was chosen (a
        phase entered directly), a part that is not a lid (only a grasp chosen for one makes it a
        lid's): :class:`~agents.scripted.part_strategies.Hinged` or
        :class:`~agents.scripted.part_strategies.Drawer` by ``est``'s joint type, whose pull rules are
        those every kind but the lid shares."""
        if self.grasp.strategy is not None:
            return self.grasp.strategy
        return Hinged(self.cfg) if est.joint_type == "revolute" else Drawer(self.cfg)

    def enter(self, phase: OpenerPhase) -> None:
        """Enter ``phase``: log it (unless its ``why`` is None: it continues the phase before) and
        start its step count and move afresh."""
        if phase.why is None:
            return
        if phase.phase != Phase.APPROACH:
            self.watch = []
        self.phase_log.append({"step": self.steps, "phase": phase.phase.value, "why": phase.why,
                               **phase.log_extra})
        self.phase_steps = 0
        self.move.still = 0
        self.move.last_p = None
