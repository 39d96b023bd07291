"""Where and how the hand grips a part, from the joint-axis estimate alone (world frame, metres).

What kind of part an estimate describes (a door on a vertical hinge, a lid, a door that gravity
opens), the point the TCP grips, and the TCP rotation that approaches it: along the part's outward
normal, pitched down as the Panda's wrist needs near the table, the fingers closing across the
handle. Used by :mod:`agents.scripted.opener`.
"""

from __future__ import annotations

import numpy as np

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.geometry import axis_angle_matrix, grasp_frame, off_axis, perpendicular, rotation_error
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


def approach_normal(est: JointAxisEstimate, cfg: ScriptedOpenerConfig,
                    robot_side: np.ndarray | None = None) -> np.ndarray:
    """World unit direction (3,) out of the face the hand grips, which it approaches against: the
    :func:`outward_normal`, except for a part that :func:`slides_across_face`, whose handle stands off
    its face towards the robot: there, the part of ``robot_side`` across the axis (the hand comes
    at the face square on, whatever direction the part then slides in)."""
    if slides_across_face(est, cfg, robot_side):
        assert robot_side is not None
        face = perpendicular(unit(est.direction), perpendicular(UP, np.asarray(robot_side, dtype=np.float64)))
        if face is not None:
            return face
    return outward_normal(est)


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


def part_kind(est: JointAxisEstimate, cfg: ScriptedOpenerConfig) -> str:
    """The kind of part ``est`` describes, which decides how it is grasped: ``"prismatic"``,
    ``"lid"`` (:func:`is_lid`), ``"vertical_hinge"`` (:func:`is_vertical_hinge`) or ``"hinge"``
    (any other revolute part, e.g. an oven door)."""
    if est.joint_type != "revolute":
        return "prismatic"
    if is_lid(est, cfg):
        return "lid"
    return "vertical_hinge" if is_vertical_hinge(est, cfg) else "hinge"


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


def grasp_target(est: JointAxisEstimate, cfg: ScriptedOpenerConfig) -> np.ndarray:
    """World point (3,) the TCP grips: the grasp point, moved ``lid.edge_offset`` m further from the
    hinge on a lid (the fingers then pinch the front of the lip and clear the lid's edge)."""
    frame = lid_frame(est) if is_lid(est, cfg) else None
    return est.grasp_point if frame is None else est.grasp_point + cfg.lid.edge_offset * frame[0]


def lift_pose(est: JointAxisEstimate, current: np.ndarray, cfg: ScriptedOpenerConfig,
              under: bool) -> tuple[np.ndarray, np.ndarray] | None:
    """TCP goal (position (3,) m, rotation (3, 3)), world frame, for lifting a lid from below: the
    closed fingertips, pointing at the hinge and ``lid.lift.pitch`` rad down, go
    ``lid.lift.below`` m under the grasp point, ``lid.lift.front`` m in front of it (``under`` False:
    where the hand lines up) or ``lid.lift.under`` m behind it (``under`` True: where it slides to).
    For a lip wider than the open fingers."""
    frame = lid_frame(est)
    if frame is None:
        return None
    front, up = frame
    approach = -np.cos(cfg.lid.lift.pitch) * front - np.sin(cfg.lid.lift.pitch) * up
    # front, up and the hinge are orthonormal; the fingers close along the hinge
    rot = nearer_finger_order(grasp_frame(approach, unit(est.direction)), current)
    ahead = -cfg.lid.lift.under if under else cfg.lid.lift.front
    return est.grasp_point + ahead * front - cfg.lid.lift.below * up, rot


def grasp_rotation(est: JointAxisEstimate, current: np.ndarray, cfg: ScriptedOpenerConfig,
                   robot_side: np.ndarray | None = None) -> np.ndarray:
    """TCP rotation (3, 3) for grasping: approach along -n (:func:`approach_normal`; ``robot_side``
    (3,) is the direction from the grasp point to the robot's base), fingers closing across the
    handle.

    Of the two finger orientations (closing c or -c) the one nearer ``current`` is chosen.
    """
    n = approach_normal(est, cfg, robot_side)
    approach = -n
    if is_lid(est, cfg):
        # a part lying flat and opening upwards (a lid): along the radius one finger would come down
        # on the part itself, so the fingers close along the hinge, across the lid's front lip
        closing = perpendicular(approach, unit(est.direction))
    elif est.joint_type == "revolute":
        closing = perpendicular(approach, est.grasp_point - est.pivot)
    elif slides_across_face(est, cfg, robot_side):
        # the fingers close along the slide: one pad pushes the handle the way the part moves,
        # so the pull does not rest on friction, and a bar across the slide lies between them
        closing = perpendicular(approach, unit(est.direction))
    else:
        closing = perpendicular(approach, UP)
    if closing is None:
        closing = perpendicular(approach, np.array([0.0, 1.0, 0.0]))
        assert closing is not None
    frame = grasp_frame(approach, closing)
    elevation = float(np.arcsin(np.clip(approach[2], -1.0, 1.0)))
    horizontal = perpendicular(approach, UP)
    if is_vertical_hinge(est, cfg):
        pitch = cfg.side_door.pitch
    elif est.joint_type == "prismatic" and not slides_across_face(est, cfg, robot_side):
        # a drawer's bar is pulled along the approach: pitched further, the tilted fingers squeeze
        # it out along the pull (see the config); a part sliding across the approach is not
        pitch = cfg.drawer.pitch
    else:
        pitch = cfg.approach.pitch
    if elevation > -pitch and horizontal is not None:
        # point the hand down by turning about the horizontal axis across the approach: the Panda's
        # wrist cannot point level at table height, and a handle bar stays between the fingers
        # (the bar is either along that axis or perpendicular to the closing direction)
        side = np.cross(approach, UP)
        side = side / np.linalg.norm(side)
        rot = axis_angle_matrix(side, -(elevation + pitch))
        if (rot @ approach)[2] > approach[2]:
            rot = rot.T
        frame = rot @ frame
    return nearer_finger_order(frame, current)


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
