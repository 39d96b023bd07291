"""Front-loading washing machine: a body with a square porthole and a square or round-ish door on a
vertical hinge at the door's left or right edge (varies per instance).

Zero/sign rule: state 0 = door closed; the axis is vertical (+z for a hinge on the right (-y),
-z for a hinge on the left (+y)) through the door's back hinge edge, oriented so that a positive
state swings the free edge towards the robot (-x); limits [0, 1.5..1.9] rad. The handle (bar or
knob) sits near the free edge and is the grasp point.
Object frame: front faces -x, resting on z = 0; "left" is +y (the viewer's left facing the front).
"""

from __future__ import annotations

import numpy as np

from capt_env.objects.fronts import Front, Panel, build_front
from capt_env.objects.geometry import opening_axis, quat_from_axis_angle
from capt_env.objects.interiors import drum
from capt_env.objects.parts import BODY_WHITES, GLASS, METALS, box_from_bounds, open_carcass
from capt_env.objects.sampling import ParamSampler
from capt_env.objects.spec import Box, JointSpec, LinkSpec, ObjectSpec, hinged_door_object
from capt_env.objects.style import Style

CATEGORY = "washing_machine"


def make(instance_id: int, style: Style | None = None) -> ObjectSpec:
    """The washing machine instance ``instance_id`` (metres, radians); ``style`` varies its door,
    handle and interior (see ``capt_env.objects.style``)."""
    s = ParamSampler(CATEGORY, instance_id)
    width = s.uniform("width", 0.38, 0.52)
    depth = s.uniform("depth", 0.34, 0.48)
    height = s.uniform("height", 0.42, 0.60)
    wall = s.uniform("wall", 0.015, 0.025)
    panel = s.uniform("control_panel_height", 0.06, 0.10)
    hole_frac = s.uniform("opening_frac", 0.5, 0.65)
    overlap = s.uniform("door_overlap", 0.015, 0.035)
    door_t = s.uniform("door_thickness", 0.025, 0.045)
    shape = s.choice("door_shape", ("square", "round"))
    side = s.choice("hinge_side", ("left", "right"))
    upper = s.uniform("max_angle", 1.5, 1.9)
    handle_style = s.choice("handle_style", ("bar", "knob"))
    handle_t = s.uniform("handle_thickness", 0.012, 0.024)
    standoff = s.uniform("handle_standoff", 0.03, 0.045)
    handle_len = s.uniform("handle_length_frac", 0.25, 0.45)
    body_color = s.color("body_color", BODY_WHITES)
    door_color = s.color("door_color", BODY_WHITES + METALS[:2])
    glass = s.color("glass_color", GLASS, jitter=0.02)

    xf = -depth / 2
    y_in0, y_in1 = -width / 2 + wall, width / 2 - wall
    hole = hole_frac * min(width, height - panel)
    zc = (height - panel) / 2 + 0.01
    h0, h1 = zc - hole / 2, zc + hole / 2
    body = open_carcass(width, depth, height, wall, body_color)
    front = [  # the front panel around the square opening
        ((xf, y_in0, wall), (xf + wall, y_in1, h0)),
        ((xf, y_in0, h1), (xf + wall, y_in1, height - wall)),
        ((xf, hole / 2, h0), (xf + wall, y_in1, h1)),
        ((xf, y_in0, h0), (xf + wall, -hole / 2, h1)),
    ]
    body += [box_from_bounds(lo, hi, body_color) for lo, hi in front]

    size = hole + 2 * overlap
    half = size / 2
    x0, x1 = xf - door_t, xf
    own_panel = None
    if shape == "round" and (style is None or not style.cylinders):  # a plus of two slabs and a diamond
        own_panel = Panel([
            box_from_bounds((x0, -half, zc - 0.62 * half), (x1, half, zc + 0.62 * half), door_color),
            box_from_bounds((x0, -0.62 * half, zc - half), (x1, 0.62 * half, zc + half), door_color),
            Box(
                half_size=(door_t / 2, 0.68 * half, 0.68 * half),
                pos=((x0 + x1) / 2, 0.0, zc),
                quat=tuple(float(v) for v in quat_from_axis_angle((1.0, 0.0, 0.0), np.pi / 4)),
                color=door_color,
            ),
        ], [], lambda p: 0.0, 0.005)
    glass_r = 0.55 * half
    glass_box = box_from_bounds((x0 - 0.004, -glass_r, zc - glass_r), (x0 + 0.001, glass_r, zc + glass_r),
                                glass)
    sign = 1.0 if side == "left" else -1.0  # the hinge edge is at y = sign * half
    free_y = -sign * (half - max(0.035, 0.25 * half))
    front = build_front(Front((x0, -half, zc - half), (x1, half, zc + half), 0, -1.0, door_color,
                              (x0, free_y, zc), along=2, handle_length=handle_len * size,
                              handle_thickness=handle_t, standoff=standoff, default_handle=handle_style,
                              knob_size=0.03, round=shape == "round", long_levers=True),
                        style, own_panel)
    # the window lies on a flat face (none on a curved door or one cut for a recessed pull)
    flat = style is None or (style.panel != "curved" and style.handle != "recessed")
    door_boxes = front.panel_boxes + ([glass_box] if flat else []) + front.handle_boxes
    body_shapes = []
    if style is not None and style.interior:
        r_max = min(width / 2 - wall, zc - wall, height - wall - zc) - 0.006
        slats, back = drum(xf + wall + 0.003, depth / 2 - wall - 0.01, zc, min(hole / 2 + 0.01, r_max),
                           METALS[0] + (1.0,), style.rng())
        body += slats
        body_shapes += back
    door = LinkSpec("door", tuple(door_boxes), density=300.0, shapes=tuple(front.shapes))
    grasp = front.grasp
    axis = opening_axis((0.0, -sign * size, 0.0), (-1.0, 0.0, 0.0))
    hinge = JointSpec(
        "door_hinge",
        "revolute",
        "body",
        "door",
        (xf, sign * half, zc),
        axis,
        (0.0, upper),
        damping=1.0,
        friction=0.04,
    )
    return hinged_door_object(CATEGORY, instance_id, body, door, hinge, grasp, s.params, body_shapes)
