"""Cabinet with one door: an open-front carcass (optionally a shelf) and an overlay door on a
vertical hinge at its left or right edge (varies per instance).

Zero/sign rule: state 0 = door closed; the axis is vertical (+z for a hinge on the right (-y),
-z for a hinge on the left (+y)) through the door's back hinge edge, so a positive state swings the
free edge towards the robot (-x); limits [0, 1.6..2.0] rad. A vertical bar or a knob near the free
edge is the grasp point.
Object frame: front faces -x, resting on z = 0; "left" is +y (the viewer's left facing the front).
"""

from __future__ import annotations

from capt_env.objects.fronts import Front, build_front
from capt_env.objects.geometry import opening_axis
from capt_env.objects.interiors import cabinet_interior
from capt_env.objects.parts import BODY_WHITES, WOODS, box_from_bounds, open_carcass
from capt_env.objects.sampling import ParamSampler
from capt_env.objects.spec import JointSpec, LinkSpec, ObjectSpec, hinged_door_object
from capt_env.objects.style import Style, proportioned

CATEGORY = "cabinet_door"
GAP = 0.002  # m, around the door
WIDTH = (0.28, 0.48)
"""Metres: the carcass's width range; under ``proportions`` (``capt_env.objects.style``) it is
:data:`WIDE_WIDTH`, and likewise for the depth and the height."""
DEPTH = (0.25, 0.40)
HEIGHT = (0.32, 0.60)
WIDE_WIDTH = (0.20, 0.75)
WIDE_DEPTH = (0.15, 0.55)
WIDE_HEIGHT = (0.22, 0.85)


def make(instance_id: int, style: Style | None = None) -> ObjectSpec:
    """The cabinet instance ``instance_id`` (metres, radians); ``style`` varies its door, handle and
    interior (see ``capt_env.objects.style``)."""
    s = ParamSampler(CATEGORY, instance_id)
    width = s.uniform("width", *WIDTH)
    depth = s.uniform("depth", *DEPTH)
    height = s.uniform("height", *HEIGHT)
    wall = s.uniform("wall", 0.012, 0.022)
    door_t = s.uniform("door_thickness", 0.012, 0.024)
    shelves = s.integer("shelves", 0, 1)
    side = s.choice("hinge_side", ("left", "right"))
    upper = s.uniform("max_angle", 1.6, 2.0)
    handle_style = s.choice("handle_style", ("bar", "knob"))
    handle_t = s.uniform("handle_thickness", 0.012, 0.022)
    standoff = s.uniform("handle_standoff", 0.03, 0.045)
    handle_len = s.uniform("handle_length_frac", 0.2, 0.45)
    handle_inset = s.uniform("handle_inset", 0.03, 0.06)
    handle_z = s.uniform("handle_height_frac", 0.4, 0.65)
    body_color = s.color("body_color", WOODS + BODY_WHITES)
    door_color = s.color("door_color", WOODS + BODY_WHITES)

    width, depth, height = proportioned(  # after every draw, which it leaves as they were
        style, (width, depth, height), (WIDE_WIDTH, WIDE_DEPTH, WIDE_HEIGHT))
    s.params.update(width=width, depth=depth, height=height)
    xf = -depth / 2
    body = open_carcass(width, depth, height, wall, body_color)
    if shelves:
        zs = height * 0.5
        body.append(
            box_from_bounds(
                (xf + 0.02, -width / 2 + wall, zs - wall / 2),
                (depth / 2 - wall, width / 2 - wall, zs + wall / 2),
                body_color,
            )
        )
    y0, y1, z0, z1 = -width / 2 + GAP, width / 2 - GAP, GAP, height - GAP
    door_w = y1 - y0
    sign = 1.0 if side == "left" else -1.0
    hinge_y = sign * y1
    free_y = -sign * (y1 - handle_inset)
    zh = z0 + handle_z * (z1 - z0)
    front = build_front(Front((xf - door_t, y0, z0), (xf, y1, z1), 0, -1.0, door_color,
                              (xf - door_t, free_y, zh), along=2, handle_length=handle_len * (z1 - z0),
                              handle_thickness=handle_t, standoff=standoff, default_handle=handle_style,
                              long_levers=True),
                        style)
    if style is not None and style.interior:
        body += cabinet_interior(width, depth, height, wall, [height * 0.5] if shelves else [], body_color,
                                 style.rng())
    door = LinkSpec("door", tuple(front.panel_boxes + front.handle_boxes), density=350.0,
                    shapes=tuple(front.shapes))
    grasp = front.grasp
    axis = opening_axis((0.0, -sign * door_w, 0.0), (-1.0, 0.0, 0.0))
    hinge = JointSpec(
        "door_hinge",
        "revolute",
        "body",
        "door",
        (xf, hinge_y, (z0 + z1) / 2),
        axis,
        (0.0, upper),
        damping=1.0,
        friction=0.04,
    )
    return hinged_door_object(CATEGORY, instance_id, body, door, hinge, grasp, s.params)
