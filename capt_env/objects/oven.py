"""Oven: a box body with a cavity and a door hinged along the bottom front edge.

Zero/sign rule: state 0 = door closed; the hinge axis is -y through the door's bottom back edge,
so a positive state swings the door's top towards the robot and down; limits [0, 1.5..1.6] rad.
A horizontal bar handle near the door's top edge is the grasp point.
Object frame: front faces -x, resting on z = 0.
"""

from __future__ import annotations

from capt_env.objects.fronts import Front, build_front
from capt_env.objects.geometry import opening_axis
from capt_env.objects.interiors import oven_racks
from capt_env.objects.parts import BODY_WHITES, GLASS, METALS, box_from_bounds, open_carcass
from capt_env.objects.sampling import ParamSampler
from capt_env.objects.spec import JointSpec, LinkSpec, ObjectSpec, hinged_door_object
from capt_env.objects.style import Style

CATEGORY = "oven"


def make(instance_id: int, style: Style | None = None) -> ObjectSpec:
    """The oven instance ``instance_id`` (metres, radians); ``style`` varies its door, handle and
    interior (see ``capt_env.objects.style``)."""
    s = ParamSampler(CATEGORY, instance_id)
    width = s.uniform("width", 0.40, 0.56)
    depth = s.uniform("depth", 0.33, 0.48)
    height = s.uniform("height", 0.32, 0.48)
    wall = s.uniform("wall", 0.015, 0.025)
    plinth = s.uniform("plinth_height", 0.045, 0.07)
    panel = s.uniform("control_panel_height", 0.05, 0.10)
    door_t = s.uniform("door_thickness", 0.02, 0.035)
    side_gap = s.uniform("door_side_gap", 0.0, 0.015)
    upper = s.uniform("max_angle", 1.5, 1.6)
    handle_len = s.uniform("handle_length_frac", 0.5, 0.85)
    handle_t = s.uniform("handle_thickness", 0.012, 0.022)
    standoff = s.uniform("handle_standoff", 0.03, 0.045)
    handle_inset = s.uniform("handle_inset", 0.025, 0.05)
    window_frac = s.uniform("window_frac", 0.45, 0.7)
    body_color = s.color("body_color", BODY_WHITES + METALS[:2])
    door_color = s.color("door_color", METALS)
    glass = s.color("window_color", GLASS, jitter=0.02)

    xf = -depth / 2
    body = open_carcass(width, depth, height, wall, body_color)
    body.append(
        box_from_bounds((xf, -width / 2 + wall, wall), (xf + wall, width / 2 - wall, plinth), body_color)
    )
    body.append(
        box_from_bounds(
            (xf, -width / 2 + wall, height - panel), (xf + wall, width / 2 - wall, height - wall), body_color
        )
    )
    for k in (-1, 1):  # two control knobs, not for grasping
        y = k * width * 0.3
        body.append(
            box_from_bounds(
                (xf - 0.015, y - 0.012, height - panel / 2 - 0.012),
                (xf, y + 0.012, height - panel / 2 + 0.012),
                METALS[2] + (1.0,),
            )
        )

    z0, z1 = plinth, height - panel
    y0, y1 = -width / 2 + side_gap, width / 2 - side_gap
    door_h = z1 - z0
    wh, ww = window_frac * door_h, 0.75 * (y1 - y0)
    zc = z0 + 0.45 * door_h
    glass_box = box_from_bounds(
        (xf - door_t - 0.002, -ww / 2, zc - wh / 2), (xf - door_t + 0.001, ww / 2, zc + wh / 2), glass
    )
    front = build_front(Front((xf - door_t, y0, z0), (xf, y1, z1), 0, -1.0, door_color,
                              (xf - door_t, 0.0, z1 - handle_inset - handle_t / 2), along=1,
                              handle_length=handle_len * (y1 - y0), handle_thickness=handle_t,
                              standoff=standoff),
                        style)
    # the window lies on a flat face (none on a curved door or one cut for a recessed pull)
    flat = style is None or (style.panel != "curved" and style.handle != "recessed")
    door_boxes = front.panel_boxes + ([glass_box] if flat else []) + front.handle_boxes
    if style is not None and style.interior:
        body += oven_racks(width, depth, wall, height - wall, wall, METALS[0] + (1.0,), style.rng())
    door = LinkSpec("door", tuple(door_boxes), density=250.0, shapes=tuple(front.shapes))
    grasp = front.grasp
    axis = opening_axis((0.0, 0.0, door_h), (-1.0, 0.0, 0.0))  # top edge towards -x: -y
    hinge = JointSpec(
        "door_hinge",
        "revolute",
        "body",
        "door",
        (xf, 0.0, z0),
        axis,
        (0.0, upper),
        damping=2.0,
        friction=0.2,
    )
    return hinged_door_object(CATEGORY, instance_id, body, door, hinge, grasp, s.params)
