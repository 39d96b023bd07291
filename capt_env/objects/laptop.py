"""Laptop: a base slab and a lid on a revolute hinge along the base's back edge.

Zero/sign rule: state 0 = lid closed flat on the base; the axis is +y at the back edge, so a
positive state lifts the lid's front edge; limits [0, 2.0..2.3] rad. The lid carries a small lip
(``is_handle``) overhanging the base's front edge: the grasp point is its centre.
Object frame: front faces -x, hinge at x = +depth/2, resting on z = 0.
"""

from __future__ import annotations

from capt_env.objects.fronts import panel_pieces
from capt_env.objects.geometry import opening_axis
from capt_env.objects.parts import GLASS, METALS, box_from_bounds
from capt_env.objects.sampling import ParamSampler
from capt_env.objects.spec import JointSpec, LinkSpec, ObjectSpec
from capt_env.objects.style import Style

CATEGORY = "laptop"
GAP = 0.001  # m, between the closed lid and the base


def make(instance_id: int, style: Style | None = None) -> ObjectSpec:
    """The laptop instance ``instance_id`` (metres, radians); ``style`` rounds or chamfers its base and
    lid, and a recessed-pull style drops the lip (the grasp point is then the lid's front edge)."""
    s = ParamSampler(CATEGORY, instance_id)
    width = s.uniform("width", 0.28, 0.40)
    depth = s.uniform("depth", 0.19, 0.27)
    base_t = s.uniform("base_thickness", 0.015, 0.03)
    lid_t = s.uniform("lid_thickness", 0.006, 0.012)
    upper = s.uniform("max_angle", 2.0, 2.3)
    lip_w = s.uniform("lip_width", 0.04, 0.09)
    lip_out = s.uniform("lip_overhang", 0.015, 0.03)
    lip_y = s.uniform("lip_offset", -0.25, 0.25) * (width - lip_w)
    screen_margin = s.uniform("screen_margin", 0.01, 0.025)
    color = s.color("color", METALS)
    screen_color = s.color("screen_color", GLASS, jitter=0.02)

    x0, x1, y0, y1 = -depth / 2, depth / 2, -width / 2, width / 2
    # rounded corners stay clear of the keyboard's and the screen's corners (0.29 r <= their inset)
    max_radius = min(0.06, 3.0 * screen_margin)
    base_slab = panel_pieces((x0, y0, 0.0), (x1, y1, base_t), 2, 1.0, color, style, max_radius, curved=False)
    base = LinkSpec(
        "base",
        (
            *base_slab.boxes,
            box_from_bounds(
                (x0 + 0.4 * depth, y0 + 0.03, base_t - 0.002),
                (x1 - 0.02, y1 - 0.03, base_t + 0.0005),
                screen_color,
            ),  # keyboard, flush with the top
        ),
        density=600.0,
        shapes=tuple(base_slab.shapes),
    )
    z0 = base_t + GAP
    z1 = z0 + lid_t
    lip_lo = (x0 - lip_out, lip_y - lip_w / 2, z0)
    lip_hi = (x0 + 0.005, lip_y + lip_w / 2, z1)
    lip = box_from_bounds(lip_lo, lip_hi, color, is_handle=True)
    has_lip = style is None or style.handle != "recessed"
    lid_slab = panel_pieces((x0, y0, z0), (x1, y1, z1), 2, 1.0, color, style, max_radius, curved=False)
    lid = LinkSpec(
        "lid",
        (
            *lid_slab.boxes,
            box_from_bounds(
                (x0 + screen_margin, y0 + screen_margin, z0 - 0.0005),
                (x1 - screen_margin, y1 - screen_margin, z0 + 0.001),
                screen_color,
            ),  # screen
            *([lip] if has_lip else []),
        ),
        density=300.0,
        shapes=tuple(lid_slab.shapes),
    )
    pivot = (x1, 0.0, (z0 + z1) / 2)
    axis = opening_axis((-depth, 0.0, 0.0), (0.0, 0.0, 1.0))  # front edge goes up: +y
    hinge = JointSpec(
        "lid_hinge", "revolute", "base", "lid", pivot, axis, (0.0, upper), damping=1.0, friction=0.35
    )
    return ObjectSpec(
        CATEGORY,
        instance_id,
        (base, lid),
        (hinge,),
        target_joint="lid_hinge",
        grasp_link="lid",
        grasp_point=lip.pos if has_lip else (x0, lip_y, (z0 + z1) / 2),
        params=s.params,
    )
