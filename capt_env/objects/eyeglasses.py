"""Eyeglasses: a frame front (two lens rims of four bars each, lenses, bridge, end pieces) and two
temples on vertical revolute hinges at the frame's ends.

Zero/sign rule: state 0 = temple FOLDED flat behind the front (the category's closed pose); a
positive state unfolds it backwards (+x): the left (+y) temple turns about +z, the right (-y)
temple about -z; limits [0, 1.6..1.75] rad (about 90-100 degrees, slightly past perpendicular).
The two folded temples lie at different depths behind the front; the target joint is the outer
one (folded last, so it can be unfolded first), which side that is varies per instance. Its ear
piece (``is_handle``) centre is the grasp point.
Sizes are about 1.6x real glasses (0.2-0.27 m wide) so a Panda can pinch a temple and a camera
sees enough of the thin frame.
Object frame: lenses face -x, the rims' bottom rests on z = 0; "left" is +y.
"""

from __future__ import annotations

from capt_env.objects.geometry import opening_axis
from capt_env.objects.parts import FRAMES, GLASS, box_from_bounds
from capt_env.objects.sampling import ParamSampler
from capt_env.objects.spec import Box, JointSpec, LinkSpec, ObjectSpec
from capt_env.objects.style import Style

CATEGORY = "eyeglasses"
GAP = 0.002  # m, between the front and the folded temples, and between the temples


def make(instance_id: int, style: Style | None = None) -> ObjectSpec:
    """The eyeglasses instance ``instance_id`` (metres, radians); ``style`` changes nothing (thin
    frames have no panel, handle or interior to vary)."""
    s = ParamSampler(CATEGORY, instance_id)
    lens_w = s.uniform("lens_width", 0.075, 0.1)
    lens_h = s.uniform("lens_height", 0.045, 0.07)
    bridge = s.uniform("bridge_width", 0.018, 0.03)
    rim = s.uniform("rim_thickness", 0.005, 0.01)
    front_d = s.uniform("front_depth", 0.006, 0.01)
    end_w = s.uniform("end_piece_width", 0.008, 0.014)
    temple_frac = s.uniform("temple_length_frac", 0.72, 0.88)
    temple_t = s.uniform("temple_thickness", 0.004, 0.007)
    temple_h = s.uniform("temple_height", 0.009, 0.015)
    hinge_frac = s.uniform("hinge_height_frac", 0.6, 0.85)
    upper = s.uniform("max_angle", 1.6, 1.75)
    outer = s.choice("outer_temple", ("left", "right"))
    frame_color = s.color("frame_color", FRAMES)
    lens_color = s.color("lens_color", GLASS, jitter=0.03)

    width = 2 * lens_w + bridge + 2 * end_w
    temple_len = temple_frac * width
    fx0, fx1 = -front_d / 2, front_d / 2
    front: list[Box] = []
    for sign in (-1.0, 1.0):  # rims at y > 0 (left) and y < 0 (right)
        yi, yo = sign * bridge / 2, sign * (bridge / 2 + lens_w)
        ya, yb = min(yi, yo), max(yi, yo)
        front += [
            box_from_bounds((fx0, ya, lens_h - rim), (fx1, yb, lens_h), frame_color),  # top bar
            box_from_bounds((fx0, ya, 0.0), (fx1, yb, rim), frame_color),  # bottom bar
            box_from_bounds((fx0, ya, rim), (fx1, ya + rim, lens_h - rim), frame_color),
            box_from_bounds((fx0, yb - rim, rim), (fx1, yb, lens_h - rim), frame_color),
            box_from_bounds((-0.001, ya + rim, rim), (0.001, yb - rim, lens_h - rim), lens_color),  # lens
        ]
    front.append(
        box_from_bounds((fx0, -bridge / 2, lens_h * 0.55), (fx1, bridge / 2, lens_h * 0.75), frame_color)
    )
    zh = hinge_frac * lens_h
    block = temple_h / 2 + 0.002
    x_back = fx1 + 0.003  # the end pieces reach a little behind the front to carry the hinges
    for sign in (-1.0, 1.0):
        ya, yb = sorted((sign * (width / 2 - end_w), sign * width / 2))
        front.append(box_from_bounds((fx0, ya, zh - block), (x_back, yb, zh + block), frame_color))

    links = [LinkSpec("frame", tuple(front), density=900.0)]
    joints: list[JointSpec] = []
    grasp = (0.0, 0.0, 0.0)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        layer = 1 if side == outer else 0
        xc = x_back + GAP + temple_t / 2 + layer * (temple_t + GAP)  # temple centre line when folded
        y_pivot = sign * (width / 2 - temple_t / 2)
        y_tip = y_pivot - sign * temple_len
        ear_len = 0.3 * temple_len
        ya, yb = sorted((y_pivot, y_tip))
        arm = box_from_bounds(
            (xc - temple_t / 2, ya, zh - temple_h / 2),
            (xc + temple_t / 2, yb, zh + temple_h / 2),
            frame_color,
        )
        ea, eb = sorted((y_tip, y_tip + sign * ear_len))
        ear = box_from_bounds(
            (xc - 0.6 * temple_t, ea, zh - 0.6 * temple_h),
            (xc + 0.6 * temple_t, eb, zh + 0.6 * temple_h),
            frame_color,
            is_handle=True,
        )
        name = f"temple_{side}"
        links.append(LinkSpec(name, (arm, ear), density=900.0))
        axis = opening_axis((0.0, -sign, 0.0), (1.0, 0.0, 0.0))
        joints.append(
            JointSpec(
                f"{name}_hinge",
                "revolute",
                "frame",
                name,
                (xc, y_pivot, zh),
                axis,
                (0.0, upper),
                damping=0.05,
                friction=0.05,
            )
        )
        if side == outer:
            grasp = ear.pos
    target = f"temple_{outer}"
    return ObjectSpec(
        CATEGORY,
        instance_id,
        tuple(links),
        tuple(joints),
        target_joint=f"{target}_hinge",
        grasp_link=target,
        grasp_point=grasp,
        params=s.params,
    )
