"""Sliding panel: a sash that slides across the front of its frame, over a fixed pane behind it (a
sash window, a sliding cabinet door).

The body is a window frame (four bars, on a plinth or not) or an open-front cabinet carcass; its
opening is split in two along the slide axis. The fixed pane fills one half in the back track; the
sash fills the other half in the front track (each reaching ``overlap`` past the middle) and slides
over the fixed pane: upwards, or sideways to the left or the right. The sash carries a bar or a knob
near its leading or trailing edge or in its middle, standing 3-6 cm off its face.

Zero/sign rule: state 0 = closed (the sash covers its half of the opening); the axis lies in the
front plane, +z for a sash that slides up, +y or -y for one that slides sideways, so a positive
state uncovers the opening; limits [0, 0.75..0.95 x the travel to the frame] m. The handle centre
is the grasp point.
Object frame: front faces -x, resting on z = 0; "left" is +y (the viewer's left facing the front).
"""

from __future__ import annotations

from capt_env.objects.fronts import Front, Panel, build_front
from capt_env.objects.parts import BODY_WHITES, FRAMES, GLASS, WOODS, box_from_bounds, open_carcass
from capt_env.objects.sampling import ParamSampler
from capt_env.objects.spec import Box, JointSpec, LinkSpec, ObjectSpec
from capt_env.objects.style import Style

CATEGORY = "sliding_panel"
GAP = 0.002  # m, between a pane and the frame, and between the two tracks
SLIDE_AXES = {"up": (2, 1.0), "left": (1, 1.0), "right": (1, -1.0)}
"""The sash's slide direction: (object-frame axis index, sign of opening travel)."""
SASH_DENSITY = 300.0  # kg/m^3


def make(instance_id: int, style: Style | None = None) -> ObjectSpec:
    """The sliding-panel instance ``instance_id`` (metres); ``style`` varies the sash's panel and
    handle (see ``capt_env.objects.style``; a window sash keeps its rails and glass)."""
    s = ParamSampler(CATEGORY, instance_id)
    kind = s.choice("kind", ("window", "cabinet"))
    slide = s.choice("slide", tuple(SLIDE_AXES))
    width = s.uniform("width", 0.30, 0.55)
    height = s.uniform("height", 0.28, 0.50)
    depth_draw = s.uniform("depth_draw", 0.0, 1.0)
    frame = s.uniform("frame_width", 0.015, 0.03)
    plinth = s.uniform("plinth_height", 0.0, 0.05)
    sash_t = s.uniform("sash_thickness", 0.012, 0.022)
    rail = s.uniform("rail_width", 0.015, 0.03)
    overlap = s.uniform("overlap", 0.01, 0.025)
    travel = s.uniform("travel_frac", 0.75, 0.95)
    handle_style = s.choice("handle_style", ("bar", "knob"))
    handle_edge = s.choice("handle_edge", ("leading", "trailing", "middle"))
    handle_t = s.uniform("handle_thickness", 0.012, 0.02)
    standoff = s.uniform("handle_standoff", 0.03, 0.06)
    handle_len = s.uniform("handle_length_frac", 0.25, 0.6)
    handle_inset = s.uniform("handle_inset", 0.025, 0.05)
    across_frac = s.uniform("handle_across_frac", 0.35, 0.65)
    frame_color = s.color("frame_color", FRAMES + WOODS + BODY_WHITES)
    sash_color = s.color("sash_color", FRAMES + WOODS + BODY_WHITES)
    glass_color = s.color("glass_color", GLASS)

    window = kind == "window"
    depth = (0.055 + 0.035 * depth_draw) if window else (0.25 + 0.15 * depth_draw)
    base = plinth if window else 0.0
    xf = -depth / 2
    body: list[Box] = _window_frame(width, depth, height, frame, base, frame_color) if window else \
        open_carcass(width, depth, height, frame, frame_color)

    axis_k, sign = SLIDE_AXES[slide]
    across_k = 2 if axis_k == 1 else 1
    lo = {1: -width / 2 + frame + GAP, 2: base + frame + GAP}
    hi = {1: width / 2 - frame - GAP, 2: height - frame - GAP}
    mid = (lo[axis_k] + hi[axis_k]) / 2
    if sign > 0:  # the sash fills the low half and opens towards +axis
        sash_span, pane_span = (lo[axis_k], mid + overlap / 2), (mid - overlap / 2, hi[axis_k])
        max_travel = hi[axis_k] - sash_span[1]
    else:
        sash_span, pane_span = (mid - overlap / 2, hi[axis_k]), (lo[axis_k], mid + overlap / 2)
        max_travel = sash_span[0] - lo[axis_k]
    front_x = (xf + GAP, xf + GAP + sash_t)  # the sash's track
    back_x = (front_x[1] + GAP, front_x[1] + GAP + sash_t)  # the fixed pane's track

    def slab(x: tuple[float, float], span: tuple[float, float]) -> tuple[list[float], list[float]]:
        a, b = [x[0], 0.0, 0.0], [x[1], 0.0, 0.0]
        a[axis_k], b[axis_k] = span
        a[across_k], b[across_k] = lo[across_k], hi[across_k]
        return a, b

    pane_lo, pane_hi = slab(back_x, pane_span)
    body += _glazed(pane_lo, pane_hi, rail, frame_color if window else sash_color, glass_color) if window \
        else [box_from_bounds(pane_lo, pane_hi, sash_color)]

    sash_lo, sash_hi = slab(front_x, sash_span)
    leading = sash_span[1] if sign > 0 else sash_span[0]
    trailing = sash_span[0] if sign > 0 else sash_span[1]
    along_slide = {"leading": leading - sign * handle_inset,
                   "trailing": trailing + sign * handle_inset,
                   "middle": (sash_span[0] + sash_span[1]) / 2}[handle_edge]
    handle_at = [front_x[0], 0.0, 0.0]
    handle_at[axis_k] = along_slide
    handle_at[across_k] = lo[across_k] + across_frac * (hi[across_k] - lo[across_k])
    sash_panel = None
    if window:
        boxes = _glazed(sash_lo, sash_hi, rail, sash_color, glass_color)
        sash_panel = Panel(boxes, [], lambda p: 0.0, rail)
    front = build_front(Front(tuple(sash_lo), tuple(sash_hi), 0, -1.0, sash_color, tuple(handle_at),
                              along=across_k, handle_length=handle_len * (hi[across_k] - lo[across_k]),
                              handle_thickness=handle_t, standoff=standoff, default_handle=handle_style),
                        style, panel=sash_panel)
    # a sash that slides up is balanced (counterweighted), as sash windows are, so it stays where put
    sash = LinkSpec("sash", tuple(front.panel_boxes + front.handle_boxes), density=SASH_DENSITY,
                    shapes=tuple(front.shapes), balanced=axis_k == 2)
    axis = [0.0, 0.0, 0.0]
    axis[axis_k] = sign
    centre = [front_x[0], 0.0, 0.0]
    centre[axis_k] = (sash_span[0] + sash_span[1]) / 2
    centre[across_k] = (lo[across_k] + hi[across_k]) / 2
    joint = JointSpec("sash_slide", "prismatic", "body", "sash", tuple(centre), tuple(axis),
                      (0.0, travel * max_travel), damping=5.0, friction=0.05)
    return ObjectSpec(CATEGORY, instance_id, (LinkSpec("body", tuple(body), density=400.0), sash), (joint,),
                      target_joint=joint.name, grasp_link="sash", grasp_point=front.grasp, params=s.params)


def _window_frame(width: float, depth: float, height: float, bar: float, plinth: float,
                  color: tuple[float, float, float, float]) -> list[Box]:
    """Four bars ``bar`` wide around the opening, standing on a plinth ``plinth`` high (none below
    5 mm) that reaches 1 cm past the frame on every side. Metres."""
    x0, x1, y0, y1 = -depth / 2, depth / 2, -width / 2, width / 2
    boxes = []
    if plinth >= 0.005:
        boxes.append(box_from_bounds((x0 - 0.01, y0 - 0.01, 0.0), (x1 + 0.01, y1 + 0.01, plinth), color))
    else:
        plinth = 0.0
    boxes += [
        box_from_bounds((x0, y0, plinth), (x1, y1, plinth + bar), color),  # bottom
        box_from_bounds((x0, y0, height - bar), (x1, y1, height), color),  # top
        box_from_bounds((x0, y1 - bar, plinth + bar), (x1, y1, height - bar), color),  # left (+y)
        box_from_bounds((x0, y0, plinth + bar), (x1, y0 + bar, height - bar), color),  # right (-y)
    ]
    return boxes


def _glazed(lo: list[float], hi: list[float], rail: float, color: tuple[float, float, float, float],
            glass: tuple[float, float, float, float]) -> list[Box]:
    """A glazed sash filling ``lo``..``hi`` (its thickness along x): four rails ``rail`` wide and a
    4 mm pane of glass set in their middle. Metres."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    r = min(rail, 0.3 * (y1 - y0), 0.3 * (z1 - z0))
    xm = (x0 + x1) / 2
    return [
        box_from_bounds((x0, y0, z0), (x1, y1, z0 + r), color),
        box_from_bounds((x0, y0, z1 - r), (x1, y1, z1), color),
        box_from_bounds((x0, y0, z0 + r), (x1, y0 + r, z1 - r), color),
        box_from_bounds((x0, y1 - r, z0 + r), (x1, y1, z1 - r), color),
        box_from_bounds((xm - 0.002, y0 + r, z0 + r), (xm + 0.002, y1 - r, z1 - r), glass),
    ]

