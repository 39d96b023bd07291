"""Drawer cabinet: an open-front carcass with 1..3 stacked drawers on prismatic joints.

Zero/sign rule: state 0 = drawer closed (front flush with the carcass); each axis is -x (the
front normal, towards the robot), so a positive state pulls the drawer out; limits
[0, 0.7..0.85 x drawer depth] m. Each drawer front carries a horizontal bar or a knob; the target
drawer is drawn per instance and its handle centre is the grasp point. Drawers are named
``drawer_0`` (bottom) upwards, joints ``drawer_0_slide`` and so on.
Object frame: front faces -x, resting on z = 0.
"""

from __future__ import annotations

from capt_env.objects.fronts import Front, build_front
from capt_env.objects.interiors import drawer_divider, drawer_frames
from capt_env.objects.parts import BODY_WHITES, METALS, WOODS, box_from_bounds, open_carcass
from capt_env.objects.sampling import ParamSampler
from capt_env.objects.spec import JointSpec, LinkSpec, ObjectSpec
from capt_env.objects.style import Style, proportioned

CATEGORY = "drawer_cabinet"
GAP = 0.002  # m, between drawer fronts and around them
WIDTH = (0.30, 0.50)
"""Metres: the carcass's width range; under ``proportions`` (``capt_env.objects.style``) it reaches
down to :data:`NARROW`."""
DEPTH = (0.28, 0.45)
"""Metres: the carcass's depth range; under ``proportions`` it reaches down to :data:`SHALLOW`."""
BOX_HEIGHT = (0.6, 0.8)
"""A drawer box's height as a share of its front's; under ``proportions`` it reaches up to 1."""
NARROW = 0.18
SHALLOW = 0.16


def make(instance_id: int, style: Style | None = None) -> ObjectSpec:
    """The drawer-cabinet instance ``instance_id`` (metres); ``style`` varies its fronts, handles and
    interior and its proportions (see ``capt_env.objects.style``)."""
    s = ParamSampler(CATEGORY, instance_id)
    count = s.integer("num_drawers", 1, 3)
    width = s.uniform("width", *WIDTH)
    depth = s.uniform("depth", *DEPTH)
    slot = s.uniform("drawer_height", 0.10, 0.17)
    wall = s.uniform("wall", 0.012, 0.022)
    front_t = s.uniform("front_thickness", 0.012, 0.022)
    side_t = s.uniform("drawer_wall", 0.006, 0.012)
    box_frac = s.uniform("drawer_box_height_frac", *BOX_HEIGHT)
    depth_frac = s.uniform("drawer_depth_frac", 0.85, 0.95)
    travel = s.uniform("travel_frac", 0.7, 0.85)
    handle_style = s.choice("handle_style", ("bar", "knob"))
    handle_t = s.uniform("handle_thickness", 0.012, 0.02)
    standoff = s.uniform("handle_standoff", 0.03, 0.045)
    handle_len = s.uniform("handle_length_frac", 0.3, 0.6)
    target = s.integer("target_drawer", 0, count - 1)
    body_color = s.color("body_color", WOODS + BODY_WHITES)
    front_color = s.color("front_color", WOODS + BODY_WHITES)
    inner_color = s.color("inner_color", WOODS)
    handle_color = s.color("handle_color", METALS)

    width, depth, box_frac = proportioned(  # after every draw, which it leaves as they were
        style, (width, depth, box_frac), ((NARROW, WIDTH[1]), (SHALLOW, DEPTH[1]), (BOX_HEIGHT[0], 1.0)))
    s.params.update(width=width, depth=depth, drawer_box_height_frac=box_frac)
    height = count * slot + 2 * wall
    xf = -depth / 2
    body_boxes = open_carcass(width, depth, height, wall, body_color)
    rng = style.rng() if style is not None and style.interior else None
    if rng is not None:
        body_boxes += drawer_frames(count, slot, wall, width, xf + front_t + 0.003, depth / 2 - wall,
                                    body_color)
    body = LinkSpec("body", tuple(body_boxes), density=400.0)
    links, joints, grasp = [body], [], (0.0, 0.0, 0.0)
    y0, y1 = -width / 2 + wall + GAP, width / 2 - wall - GAP
    inner_depth = depth_frac * (depth - wall - front_t)
    fill = 1.0 if style is None else style.front_fill
    for i in range(count):
        z0 = wall + i * slot + GAP
        z1 = wall + (i + 1) * slot - GAP
        zc = (z0 + z1) / 2  # the joint's line: through the opening's middle whatever the front
        zf, zh = z1, zc  # the front's top and its handle's height
        if fill < 1.0:  # ``openings``: a lower front, the carcass's inside showing above it
            zf = z0 + fill * (z1 - z0)
            zh = (z0 + zf) / 2
        xb = xf + front_t + inner_depth  # back of the drawer box
        zt = z0 + box_frac * (zf - z0)
        front = build_front(Front((xf, y0, z0), (xf + front_t, y1, zf), 0, -1.0, front_color, (xf, 0.0, zh),
                                  along=1, handle_length=handle_len * (y1 - y0), handle_thickness=handle_t,
                                  standoff=standoff, handle_color=handle_color, default_handle=handle_style),
                            style)
        boxes = front.panel_boxes + [
            box_from_bounds((xf + front_t, y0 + GAP, z0), (xb, y1 - GAP, z0 + side_t), inner_color),  # bottom
            box_from_bounds((xf + front_t, y0 + GAP, z0 + side_t), (xb, y0 + GAP + side_t, zt), inner_color),
            box_from_bounds((xf + front_t, y1 - GAP - side_t, z0 + side_t), (xb, y1 - GAP, zt), inner_color),
            box_from_bounds(
                (xb - side_t, y0 + GAP + side_t, z0 + side_t), (xb, y1 - GAP - side_t, zt), inner_color
            ),
        ] + front.handle_boxes
        if rng is not None:
            boxes += drawer_divider(xf + front_t, xb - side_t, y0 + GAP + side_t, y1 - GAP - side_t,
                                    z0 + side_t, zt, inner_color, rng)
        centre = front.grasp
        name = f"drawer_{i}"
        links.append(LinkSpec(name, tuple(boxes), density=300.0, shapes=tuple(front.shapes)))
        joints.append(
            JointSpec(
                f"{name}_slide",
                "prismatic",
                "body",
                name,
                (xf, 0.0, zc),
                (-1.0, 0.0, 0.0),
                (0.0, travel * inner_depth),
                damping=5.0,
                friction=0.05,
            )
        )
        if i == target:
            grasp = centre
    return ObjectSpec(
        CATEGORY,
        instance_id,
        tuple(links),
        tuple(joints),
        target_joint=f"drawer_{target}_slide",
        grasp_link=f"drawer_{target}",
        grasp_point=grasp,
        params=s.params,
    )
