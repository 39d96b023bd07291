"""The part-kind strategies of the scripted opener, on constructed joint-axis estimates: which kind
each estimate gets, what each kind answers, that each reads its own config group, and that the
phases ask the strategy chosen with the grasp."""

from __future__ import annotations

import numpy as np
import pytest

from agents.scripted import ScriptedOpener, ScriptedOpenerConfig
from agents.scripted.config import with_options
from agents.scripted.geometry import axis_angle_matrix
from agents.scripted.grasp_pose import grasp_rotation, grasp_target, part_kind, quarter_turn
from agents.scripted.opener import ACTION_SCALE_M, Phase
from agents.scripted.part_strategies import (
    PALM_CLEAR_PITCH,
    STRATEGIES,
    Drawer,
    FallingDoor,
    Hinged,
    Lid,
    SideDoor,
    SlidingPanel,
    closes_across_level_bar,
    strategy_for,
)
from agents.scripted.phases.base import Look
from agents.scripted.phases.grasp import Close
from agents.scripted.phases.pull import start_pull
from capt_env.wrappers.estimate import JointAxisEstimate

CFG = ScriptedOpenerConfig()
Y = np.array([0.0, 1.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])
# the robot's base is towards -x from every part below
ROBOT_SIDE = np.array([-0.9, 0.0, -0.2])


def _lid(state: float = 0.0) -> JointAxisEstimate:
    # a laptop lid hinged along +y at its back edge (x = 0.15, z = 0.03), its lip on the front edge
    pivot = np.array([0.15, 0.0, 0.03])
    lip = pivot + axis_angle_matrix(Y, state) @ np.array([-0.25, 0.05, 0.0])
    return JointAxisEstimate("revolute", Y, pivot, state, lip)


def _side_door() -> JointAxisEstimate:
    # hinge along +z at y = -0.2, handle at y = +0.2 on the front face x = -0.1
    return JointAxisEstimate("revolute", Z, np.array([-0.1, -0.2, 0.3]), 0.0, np.array([-0.1, 0.2, 0.3]))


def _oven(state: float = 0.0) -> JointAxisEstimate:
    # a door hinged along -y at its foot (x = 0.1, z = 0.1), its handle 0.25 m above the hinge
    u, pivot = -Y, np.array([0.1, 0.0, 0.1])
    handle = pivot + axis_angle_matrix(u, state) @ np.array([-0.02, 0.0, 0.25])
    return JointAxisEstimate("revolute", u, pivot, state, handle)


def _flap() -> JointAxisEstimate:
    # a flap hinged along +y at its top edge (z = 0.5), its handle 0.25 m below the hinge
    return JointAxisEstimate("revolute", Y, np.array([-0.1, 0.0, 0.5]), 0.0, np.array([-0.12, 0.0, 0.25]))


def _drawer() -> JointAxisEstimate:
    # slides out along -x, towards the robot
    return JointAxisEstimate("prismatic", np.array([-1.0, 0.0, 0.0]), np.zeros(3), 0.0,
                             np.array([-0.1, 0.0, 0.1]))


def _panel(direction: np.ndarray) -> JointAxisEstimate:
    # slides along ``direction`` in its front face x = -0.1 (a sliding door, a window)
    return JointAxisEstimate("prismatic", np.asarray(direction, dtype=np.float64), np.zeros(3), 0.0,
                             np.array([-0.1, 0.0, 0.3]))


def test_each_kind_of_part_gets_its_strategy() -> None:
    assert isinstance(strategy_for(_lid(), CFG), Lid)
    assert isinstance(strategy_for(_side_door(), CFG), SideDoor)
    assert isinstance(strategy_for(_oven(), CFG), FallingDoor)
    assert isinstance(strategy_for(_oven(1.2), CFG), FallingDoor)  # judged closed: still one
    assert type(strategy_for(_flap(), CFG)) is Hinged  # gravity closes a flap hinged at its top
    assert isinstance(strategy_for(_drawer(), CFG, ROBOT_SIDE), Drawer)
    for direction in (Y, -Y, Z, -Z):
        assert isinstance(strategy_for(_panel(direction), CFG, ROBOT_SIDE), SlidingPanel)
        # without the robot's side nothing tells its face: a drawer's grasp
        assert isinstance(strategy_for(_panel(direction), CFG), Drawer)
    # the kinds grasped alike share a grasp kind, which part_kind names
    for est, kind in ((_lid(), "lid"), (_side_door(), "vertical_hinge"), (_oven(), "hinge"),
                      (_flap(), "hinge"), (_drawer(), "prismatic"), (_panel(Y), "prismatic")):
        assert strategy_for(est, CFG, ROBOT_SIDE).grasp_kind == part_kind(est, CFG) == kind
    assert {s.name for s in STRATEGIES} == {"lid", "side_door", "falling_door", "hinge", "drawer",
                                           "sliding_panel"}


def test_a_lid_is_pinched_from_above_at_its_lip_and_pulled_past_upright() -> None:
    lid = strategy_for(_lid(), CFG)
    est = _lid()
    rot = lid.grasp_rotation(est, np.eye(3))
    np.testing.assert_allclose(rot[:, 2], -Z, atol=1e-9)  # straight down
    assert abs(float(rot[:, 1] @ Y)) == pytest.approx(1.0)  # the fingers close along the hinge
    # the grip is lid.edge_offset beyond the lip, away from the hinge (-x)
    np.testing.assert_allclose(lid.grasp_target(est), est.grasp_point + [-CFG.lid.edge_offset, 0.0, 0.0],
                               atol=1e-12)
    assert lid.gap == CFG.lid.gap and not lid.rehearses
    assert lid.pull_target(revolute=True) == CFG.lid.target
    assert not lid.stall_can_be_end_stop and not lid.turns_fingers_on_miss and not lid.falls_open
    # a look that no longer shows a lid is gripped at its grasp point
    np.testing.assert_allclose(lid.grasp_target(_side_door()), _side_door().grasp_point)


def test_a_lid_whose_lip_the_fingers_missed_is_lifted_from_below() -> None:
    lid = Lid(CFG)
    assert lid.lifts_from_below(lifting=False) and not lid.lifts_from_below(lifting=True)
    assert not Lid(with_options(CFG, lid__lift__enabled=False)).lifts_from_below(lifting=False)
    for other in (SideDoor(CFG), FallingDoor(CFG), Hinged(CFG), Drawer(CFG), SlidingPanel(CFG)):
        assert not other.lifts_from_below(lifting=False) and other.turns_fingers_on_miss
    # lifting, the lid's lift options drive the pull; gripped, the shared lead and the lid's follow
    lift = CFG.lid.lift
    assert (lid.pull_lead(True), lid.inward(True), lid.wrist_follow(True)) == (
        lift.lead, lift.inward, lift.wrist_follow)
    assert (lid.pull_lead(False), lid.inward(False), lid.wrist_follow(False)) == (
        CFG.pull.revolute.lead, 0.0, CFG.lid.wrist_follow)
    pre, rot = lid.lift_pose(_lid(), np.eye(3), under=False)
    np.testing.assert_allclose(pre, _lid().grasp_point + [-lift.front, 0.0, -lift.below], atol=1e-9)
    np.testing.assert_allclose(rot[:, 2], [np.cos(lift.pitch), 0.0, -np.sin(lift.pitch)], atol=1e-9)


def test_a_lid_s_slip_leaves_out_travel_along_its_hinge() -> None:
    away = np.array([0.01, 0.2, 0.0])
    np.testing.assert_allclose(Lid(CFG).slip_offset(away, Y), [0.01, 0.0, 0.0])
    np.testing.assert_allclose(Lid(with_options(CFG, lid__slip_off_axis=False)).slip_offset(away, Y), away)
    np.testing.assert_allclose(SideDoor(CFG).slip_offset(away, Y), away)


def test_a_side_door_is_pitched_further_and_the_hand_turns_with_it() -> None:
    door = strategy_for(_side_door(), CFG)
    assert door.pitch == CFG.side_door.pitch
    rot = door.grasp_rotation(_side_door(), np.eye(3))
    # towards the door (+x), side_door.pitch below horizontal; the fingers close along the radius
    # from the hinge (y), across a bar that runs along the hinge
    pitch = CFG.side_door.pitch
    np.testing.assert_allclose(rot[:, 2], [np.cos(pitch), 0.0, -np.sin(pitch)], atol=1e-9)
    assert abs(float(rot[:, 1] @ Y)) == pytest.approx(1.0)
    # a hand across a level bar (a lever) turns fully with the door, one across an upright bar lags it
    lever = quarter_turn(rot, rot)
    assert door.hand_turn(_side_door(), lifting=False, grasp_r=lever) == 1.0
    assert door.hand_turn(_side_door(), lifting=False, grasp_r=rot) == CFG.side_door.upright_bar_follow < 1.0
    # and lags it further once the upright bar has pried the fingers apart; a lever's hand does not
    assert (door.hand_turn(_side_door(), lifting=False, grasp_r=rot, prying=True)
            == CFG.side_door.pry_follow < CFG.side_door.upright_bar_follow)
    assert door.hand_turn(_side_door(), lifting=False, grasp_r=lever, prying=True) == 1.0
    # the hinge the look shows decides: a door grasped as a side door, seen tilted, turns by the share
    assert door.hand_turn(_oven(), lifting=False, grasp_r=rot) == CFG.pull.revolute.wrist_follow
    assert door.pull_target(revolute=True) == CFG.pull.revolute.target and door.stall_can_be_end_stop


def _elevation(v: np.ndarray) -> float:
    return float(np.arcsin(np.clip(v[2], -1.0, 1.0)))


def test_a_side_door_s_pull_pitches_the_hand_down_about_a_level_bar_it_holds() -> None:
    door, own = SideDoor(CFG), CFG.side_door
    grasp = quarter_turn(door.grasp_rotation(_side_door(), np.eye(3)), np.eye(3))
    assert closes_across_level_bar(grasp)
    np.testing.assert_allclose(door.pull_rotation(grasp, 0.0), grasp)
    # nearer closed than pull_roll_from the hand stays square to the door
    np.testing.assert_allclose(door.pull_rotation(grasp, 0.9 * own.pull_roll_from), grasp)
    for turned in (0.6, 1.5, 4.0):
        held = axis_angle_matrix(Z, turned) @ grasp
        rolled = door.pull_rotation(held, turned)
        want = min(own.pitch + own.pull_roll * max(turned - own.pull_roll_from, 0.0), own.max_pull_pitch)
        assert _elevation(rolled[:, 2]) == pytest.approx(-want)
        # fingers closing across a level bar (a lever) turn about the bar
        np.testing.assert_allclose(rolled[:, 0], held[:, 0], atol=1e-9)
    # off, and no other kind of part rolls its hand
    off = SideDoor(with_options(CFG, side_door__pull_roll=0.0))
    np.testing.assert_allclose(off.pull_rotation(grasp, 1.5), grasp)
    for other in (Hinged, Lid, FallingDoor, Drawer):
        np.testing.assert_allclose(other(CFG).pull_rotation(grasp, 1.5), grasp)


def test_a_hand_holding_an_upright_bar_keeps_its_pitch_so_the_bar_stays_off_its_palm() -> None:
    door = SideDoor(CFG)
    grasp = door.grasp_rotation(_side_door(), np.eye(3))  # fingers close level, across a bar along the hinge
    assert not closes_across_level_bar(grasp)
    for turned in (1.2, 1.5, 2.0):
        held = axis_angle_matrix(Z, turned) @ grasp
        np.testing.assert_allclose(door.pull_rotation(held, turned), held)
    # the pitch it keeps passes an upright bar outside the palm
    assert CFG.side_door.pitch < PALM_CLEAR_PITCH


def test_the_palm_clear_pitch_is_the_panda_hand_s_own_geometry() -> None:
    trimesh = pytest.importorskip("trimesh")
    from pathlib import Path

    from mani_skill.agents.robots.panda.panda import Panda

    mesh = trimesh.load(Path(Panda.urdf_path).parent / "franka_description/meshes/collision/hand.stl")
    tcp_depth = 0.1034  # panda_hand_tcp_joint: the TCP lies this far along the hand's z
    behind = tcp_depth - float(mesh.vertices[:, 2].max())  # the palm's end nearest the TCP
    half_thickness = float(np.abs(mesh.vertices[:, 0]).max())  # across the fingers' plane
    assert PALM_CLEAR_PITCH == pytest.approx(np.arctan2(behind, half_thickness), abs=0.01)


def test_a_door_that_falls_open_is_grasped_as_any_hinge_and_said_to_fall() -> None:
    oven, flap = strategy_for(_oven(), CFG), strategy_for(_flap(), CFG)
    assert oven.falls_open and not flap.falls_open
    np.testing.assert_allclose(oven.grasp_rotation(_oven(), np.eye(3)),
                               Hinged(CFG).grasp_rotation(_oven(), np.eye(3)), atol=1e-12)
    assert oven.pitch == flap.pitch == CFG.approach.pitch
    assert oven.hand_turn(_oven(), lifting=False, grasp_r=np.eye(3)) == CFG.pull.revolute.wrist_follow
    assert oven.own is CFG.falling_door


def test_a_hand_to_turn_in_a_falling_door_s_sweep_moves_out_of_it_first() -> None:
    # the hand pointing down 14 cm from an oven door's hinge (its handle 25 cm out): turning in place
    # there, it knocks a door that then falls onto the arm
    down_at = np.array([0.0, 0.0, 0.2, 0.0, 1.0, 0.0, 0.0])
    radial = down_at[:3] - np.array([0.1, 0.0, 0.1])  # from the hinge line (along y) to the hand
    opener = ScriptedOpener()
    step = opener.act_on(_oven(), down_at)[:3]
    assert opener.phase == Phase.PREGRASP and isinstance(opener.ctx.grasp.strategy, FallingDoor)
    assert float(step @ radial) > 0.9 * np.linalg.norm(step) * np.linalg.norm(radial) > 0.0
    action = opener.act_on(_oven(), down_at)
    assert np.allclose(action[3:6], 0.0)  # unturned until clear: turning there is what knocks the door
    # clear of the sweep (or a door that does not fall, or the rule off), it turns where it is
    outside = np.array([-0.3, 0.0, 0.4, 0.0, 1.0, 0.0, 0.0])
    for est, pose, cfg in ((_oven(), outside, CFG), (_side_door(), down_at, CFG),
                           (_oven(), down_at, with_options(CFG, falling_door__done_above=0.0))):
        action = ScriptedOpener(cfg).act_on(est, pose)
        assert np.allclose(action[:3], 0.0) and not np.allclose(action[3:6], 0.0)


def test_a_drawer_is_approached_along_its_axis_pitched_drawer_pitch() -> None:
    drawer = strategy_for(_drawer(), CFG, ROBOT_SIDE)
    rot = drawer.grasp_rotation(_drawer(), np.eye(3), ROBOT_SIDE)
    pitch = CFG.drawer.pitch
    np.testing.assert_allclose(rot[:, 2], [np.cos(pitch), 0.0, -np.sin(pitch)], atol=1e-9)
    # the fingers close in the vertical plane of the approach, across a horizontal bar
    np.testing.assert_allclose(rot[:, 1] @ Y, 0.0, atol=1e-9)
    assert drawer.pull_target(revolute=False) == CFG.pull.prismatic.target and drawer.rehearses
    assert drawer.gap == CFG.approach.gap


@pytest.mark.parametrize("direction", [Y, -Y, Z, -Z])
def test_a_sliding_panel_is_gripped_square_on_and_pulled_along_its_axis_either_way(direction) -> None:
    est = _panel(direction)
    panel = strategy_for(est, CFG, ROBOT_SIDE)
    np.testing.assert_allclose(panel.approach_normal(est, ROBOT_SIDE), [-1.0, 0.0, 0.0], atol=1e-9)
    rot = panel.grasp_rotation(est, np.eye(3), ROBOT_SIDE)
    # towards the face (+x), pitched down; the fingers close along the slide (pitched with the hand)
    along = 1.0 if direction[2] == 0.0 else np.cos(CFG.approach.pitch)
    assert rot[0, 2] > 0.0 and abs(float(rot[:, 1] @ direction)) == pytest.approx(along)
    # the pull leads the handle along the axis, whichever way it points
    opener = ScriptedOpener(with_options(CFG, move__max_step_m=1.0))
    opener.ctx.grasp.strategy = panel
    opener.enter(start_pull(opener.ctx, est.grasp_point, rot, est, "closed"))
    opener.ctx.now = Look(est, est.grasp_point, rot, 0.02, None)
    action, _ = opener.current.step(opener.ctx)
    np.testing.assert_allclose(action[:3] * ACTION_SCALE_M, CFG.pull.prismatic.lead * direction, atol=1e-9)


def _pull_along_track(cfg: ScriptedOpenerConfig, est: JointAxisEstimate, track: np.ndarray,
                      travel: float, finger_gap: float = 0.02, gap_change: float = 0.0) -> np.ndarray:
    """The commanded TCP step (m) after the hand, holding, was carried ``travel`` m along unit ``track``
    in 8 steps, the finger gap going from ``finger_gap`` by ``gap_change`` (m) on the way."""
    opener = ScriptedOpener(with_options(cfg, move__max_step_m=1.0))
    opener.ctx.grasp.strategy = strategy_for(est, cfg, ROBOT_SIDE)
    start = np.asarray(est.grasp_point, dtype=np.float64)
    opener.enter(start_pull(opener.ctx, start, np.eye(3), est, "closed"))
    action = np.zeros(7)
    for d, gap in zip(np.linspace(0.0, travel, 8), np.linspace(finger_gap, finger_gap + gap_change, 8),
                      strict=True):
        opener.ctx.now = Look(est, start + d * track, np.eye(3), float(gap), None)
        action, _ = opener.current.step(opener.ctx)
    return action[:3] * ACTION_SCALE_M


def test_a_held_sliding_part_is_pulled_along_the_track_its_hand_follows_not_the_estimate() -> None:
    # a sash on a level track (-y), estimated 14 deg up: the track carries the hand level
    track = -Y
    tilted = np.cos(np.radians(14.0)) * track + np.sin(np.radians(14.0)) * Z
    est = _panel(tilted)
    step = _pull_along_track(CFG, est, track, travel=0.06)
    np.testing.assert_allclose(step / np.linalg.norm(step), track, atol=1e-6)
    # before the hand has travelled track_fit_travel, or with the fit off, the estimate's line holds
    # (the commanded step climbs back towards it: the error off it is what slows a pull into its end stop)
    short = _pull_along_track(CFG, est, track, travel=0.015)
    off = _pull_along_track(with_options(CFG, pull__prismatic__track_fit_travel=0.0), est, track, travel=0.06)
    for step in (short, off):
        assert step @ Z > 0.2 * np.linalg.norm(step)
    # fingers that closed on nothing measure no track, nor do fingers a bar is sliding out of (the
    # gap narrowing 2.3 mm a step); a grip settling on its handle (1 mm a step) still does
    empty = _pull_along_track(CFG, est, track, travel=0.06, finger_gap=0.0)
    slipping = _pull_along_track(CFG, est, track, travel=0.06, finger_gap=0.02, gap_change=-0.016)
    for step in (empty, slipping):
        assert step @ Z > 0.2 * np.linalg.norm(step)
    settling = _pull_along_track(CFG, est, track, travel=0.06, finger_gap=0.036, gap_change=-0.007)
    np.testing.assert_allclose(settling / np.linalg.norm(settling), track, atol=1e-6)


@pytest.mark.parametrize(("option", "value", "kind", "answer"), [
    ("lid__target", 2.4, Lid, lambda s: s.pull_target(True)),
    ("lid__gap", 0.05, Lid, lambda s: s.gap),
    ("side_door__pitch", 0.6, SideDoor, lambda s: s.pitch),
    ("drawer__pitch", 0.4, Drawer, lambda s: s.pitch),
])
def test_each_strategy_reads_its_own_config_group(option, value, kind, answer) -> None:
    changed = with_options(CFG, **{option: value})
    for strategy in STRATEGIES:
        before, after = answer(strategy(CFG)), answer(strategy(changed))
        if strategy is kind:
            assert after == value != before
        else:
            assert after == before


def test_the_grasp_pose_functions_answer_as_the_strategy_each_estimate_gets() -> None:
    for est in (_lid(), _side_door(), _oven(), _flap(), _drawer(), _panel(Z)):
        strategy = strategy_for(est, CFG, ROBOT_SIDE)
        np.testing.assert_array_equal(grasp_rotation(est, np.eye(3), CFG, ROBOT_SIDE),
                                      strategy.grasp_rotation(est, np.eye(3), ROBOT_SIDE))
        np.testing.assert_array_equal(grasp_target(est, CFG), strategy_for(est, CFG).grasp_target(est))


def test_the_context_keeps_the_strategy_chosen_with_the_grasp() -> None:
    pose = np.array([-0.3, 0.0, 0.4, 0.0, 1.0, 0.0, 0.0])
    for est, kind in ((_lid(), Lid), (_side_door(), SideDoor), (_oven(), FallingDoor), (_drawer(), Drawer)):
        opener = ScriptedOpener()
        assert opener.ctx.grasp.strategy is None
        opener.act_on(est, pose)
        assert isinstance(opener.ctx.grasp.strategy, kind) and opener.ctx.grasp.lid is (kind is Lid)
        assert opener.ctx.grip(_drawer()) is opener.ctx.grasp.strategy  # later looks do not change it
    # before any grasp is chosen a phase entered directly pulls a part that is not a lid
    opener = ScriptedOpener()
    assert type(opener.ctx.grip(_lid())) is Hinged and type(opener.ctx.grip(_drawer())) is Drawer
    opener.ctx.grasp.lid = True
    assert isinstance(opener.ctx.grasp.strategy, Lid)


def test_fingers_closed_on_nothing_do_what_the_grasp_s_strategy_says() -> None:
    above = np.array([-0.1, 0.05, 0.05, 0.0, 1.0, 0.0, 0.0])
    for strategy, lifts in ((Lid(CFG), True), (Hinged(CFG), False)):
        opener = ScriptedOpener()
        opener.ctx.grasp.strategy = strategy
        opener.enter(Close("reached"))
        for _ in range(CFG.grasp.close_steps):
            opener.act_on(_lid(), above, finger_gap=0.0)
        assert opener.phase == Phase.RELEASE
        assert opener.ctx.lift is lifts and opener.regrasps == int(not lifts)
