"""The geometry of a grasp from the joint-axis estimate alone (world frame, metres, radians).

The facts about an estimate that tell the kinds of part apart (:func:`is_lid`,
:func:`is_vertical_hinge`, :func:`falls_open`, :func:`slides_across_face`), the direction a part
opens in (:func:`outward_normal`), a lid's frame (:func:`lid_frame`) and the finger order nearer the
hand (:func:`nearer_finger_order`, :func:`quarter_turn`). What each kind then does with them is in
:mod:`agents.scripted.part_strategies`; :func:`part_kind`, :func:`approach_normal`,
:func:`grasp_target`, :func:`grasp_rotation` and :func:`lift_pose` ask the strategy
(:func:`~agents.scripted.part_strategies.strategy_for`) that ``est`` gets.
"""

from __future__ import annotations

import numpy as np

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.geometry import axis_angle_matrix, off_axis, perpendicular, rotation_error
from capt_env.wrappers.estimate import JointAxisEstimate, unit

UP = np.array([0.0, 0.0, 1.0])
SWAP_FINGERS = np.diag([-1.0, -1.0, 1.0])  # the same approach with the fingers the other way round


def outward_normal(est: JointAxisEstimate) -> np.ndarray:
    """World-frame unit direction in which the grasp point moves when the part opens."""
    u = unit(est.direction)
    if est.joint_type == "prismatic":
        return u
    return unit(np.cross(u, est.grasp_point - est.pivot))


def slides_across_face(est: JointAxisEstimate, cfg: ScriptedOpenerConfig,
                       robot_side: np.ndarray | None) -> bool:
    """Whether ``est`` is a prismatic part that slides across the face its handle is on (a window
    sliding up, a sliding door sliding sideways) rather than out of it towards the hand (a drawer):
    its axis is more than ``sliding_panel.min_angle`` rad from ``robot_side`` (3,), the horizontal
    direction from the grasp point to the robot's base. The robot sees and reaches the object from
    that side, so a handle stands off the face turned to it; a part whose axis points there comes out
    of that face, one whose axis lies across it slides in it. False without ``robot_side``."""
    if est.joint_type != "prismatic" or robot_side is None:
        return False
    side = perpendicular(UP, np.asarray(robot_side, dtype=np.float64))
    if side is None:
        return False
    return float(unit(est.direction) @ side) < float(np.cos(cfg.sliding_panel.min_angle))


def is_vertical_hinge(est: JointAxisEstimate, cfg: ScriptedOpenerConfig) -> bool:
    """Whether ``est`` is a revolute joint whose axis is within ``side_door.max_tilt`` of vertical."""
    if est.joint_type != "revolute":
        return False
    return abs(float(unit(est.direction)[2])) >= float(np.cos(cfg.side_door.max_tilt))


def is_lid(est: JointAxisEstimate, cfg: ScriptedOpenerConfig) -> bool:
    """Whether ``est`` is a revolute part that opens upwards at its grasp point, within
    ``lid.max_tilt`` rad of straight up (a closed lid: the hand comes down from above)."""
    if est.joint_type != "revolute":
        return False
    return float(outward_normal(est)[2]) >= float(np.cos(cfg.lid.max_tilt))


def falls_open(est: JointAxisEstimate, cfg: ScriptedOpenerConfig) -> bool:
    """Whether ``est`` is a part that gravity opens further once it is let go: a revolute part about
    a non-vertical hinge whose grasp point, closed (turned back by the estimated state), is above
    the hinge line, and which is not a lid (an oven door, hinged at its foot)."""
    if est.joint_type != "revolute" or is_vertical_hinge(est, cfg) or is_lid(est, cfg):
        return False
    u = unit(est.direction)
    closed = axis_angle_matrix(u, -float(est.state)) @ (est.grasp_point - est.pivot)
    return float(off_axis(closed, u)[2]) > 0.0


def lid_frame(est: JointAxisEstimate) -> tuple[np.ndarray, np.ndarray] | None:
    """World unit directions (front, up) at a lid's grasp point: ``front`` along the radius from the
    hinge out through the grasp point, ``up`` the direction the grasp point opens in
    (:func:`outward_normal`). None when the grasp point lies on the hinge line."""
    front = perpendicular(unit(est.direction), est.grasp_point - est.pivot)
    return None if front is None else (front, outward_normal(est))


def pitched_down(frame: np.ndarray, pitch: float) -> np.ndarray:
    """TCP rotation ``frame`` (3, 3) whose approach (its z) points less than ``pitch`` rad below level
    turned down to that pitch, about the horizontal axis across the approach: the Panda's wrist cannot
    point level at table height, and a handle bar stays between the fingers (the bar is either along
    that axis or perpendicular to the closing direction). ``frame`` itself for a vertical approach."""
    approach = frame[:, 2]
    elevation = float(np.arcsin(np.clip(approach[2], -1.0, 1.0)))
    if elevation <= -pitch or perpendicular(approach, UP) is None:
        return frame
    side = np.cross(approach, UP)
    side = side / np.linalg.norm(side)
    rot = axis_angle_matrix(side, -(elevation + pitch))
    if (rot @ approach)[2] > approach[2]:
        rot = rot.T
    return rot @ frame


def nearer_finger_order(frame: np.ndarray, current: np.ndarray) -> np.ndarray:
    """Of TCP rotation ``frame`` (3, 3) and the same approach with the fingers swapped, the one
    nearer the current rotation ``current`` (3, 3)."""
    flipped = frame @ SWAP_FINGERS
    if np.linalg.norm(rotation_error(flipped, current)) < np.linalg.norm(rotation_error(frame, current)):
        return flipped
    return frame


def quarter_turn(frame: np.ndarray, current: np.ndarray) -> np.ndarray:
    """TCP rotation ``frame`` (3, 3) turned a quarter turn about its approach axis (the fingers then
    close at right angles to before), of the two ways the one nearer ``current`` (3, 3)."""
    turn = axis_angle_matrix(frame[:, 2], 0.5 * np.pi) @ frame
    return nearer_finger_order(turn, current)


# The answers of the part-kind strategies for the kind ``est`` shows, for callers that have no strategy
# at hand. (The strategies build on this module, so it imports them where they are asked.)


def part_kind(est: JointAxisEstimate, cfg: ScriptedOpenerConfig) -> str:
    """The kind of part ``est`` describes as far as its grasp goes: ``"prismatic"``, ``"lid"``
    (:func:`is_lid`), ``"vertical_hinge"`` (:func:`is_vertical_hinge`) or ``"hinge"`` (any other
    revolute part, e.g. an oven door): the ``grasp_kind`` of its strategy."""
    from agents.scripted.part_strategies import strategy_for

    return strategy_for(est, cfg).grasp_kind


def approach_normal(est: JointAxisEstimate, cfg: ScriptedOpenerConfig,
                    robot_side: np.ndarray | None = None) -> np.ndarray:
    """World unit direction (3,) out of the face the hand grips, which it approaches against
    (:meth:`~agents.scripted.part_strategies.PartStrategy.approach_normal`; ``robot_side`` (3,): the
    direction from the grasp point to the robot's base)."""
    from agents.scripted.part_strategies import strategy_for

    return strategy_for(est, cfg, robot_side).approach_normal(est, robot_side)


def grasp_target(est: JointAxisEstimate, cfg: ScriptedOpenerConfig) -> np.ndarray:
    """World point (3,) the TCP grips (:meth:`~agents.scripted.part_strategies.PartStrategy.grasp_target`):
    the grasp point, a lid's moved ``lid.edge_offset`` m further from the hinge."""
    from agents.scripted.part_strategies import strategy_for

    return strategy_for(est, cfg).grasp_target(est)


def grasp_rotation(est: JointAxisEstimate, current: np.ndarray, cfg: ScriptedOpenerConfig,
                   robot_side: np.ndarray | None = None) -> np.ndarray:
    """TCP rotation (3, 3) for grasping
    (:meth:`~agents.scripted.part_strategies.PartStrategy.grasp_rotation`): approach against
    :func:`approach_normal`, fingers closing across the handle, of the two finger orders the one nearer
    ``current`` (3, 3); ``robot_side`` (3,) is the direction from the grasp point to the robot's base."""
    from agents.scripted.part_strategies import strategy_for

    return strategy_for(est, cfg, robot_side).grasp_rotation(est, current, robot_side)


def lift_pose(est: JointAxisEstimate, current: np.ndarray, cfg: ScriptedOpenerConfig,
              under: bool) -> tuple[np.ndarray, np.ndarray] | None:
    """TCP goal (position (3,) m, rotation (3, 3)) for lifting a lid from below
    (:meth:`~agents.scripted.part_strategies.Lid.lift_pose`), whatever kind ``est`` shows."""
    from agents.scripted.part_strategies import Lid

    return Lid(cfg).lift_pose(est, current, under)
