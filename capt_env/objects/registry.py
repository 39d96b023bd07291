"""The procedural categories and ``make_object(category, instance_id)``, the one entry point."""

from __future__ import annotations

import importlib
from collections.abc import Callable

from capt_env.objects.sampling import NUM_INSTANCES, check_instance_id
from capt_env.objects.spec import ObjectSpec
from capt_env.objects.style import GeometryVariation, draw_style

CATEGORIES: tuple[str, ...] = (
    "laptop",
    "oven",
    "washing_machine",
    "eyeglasses",
    "drawer_cabinet",
    "cabinet_door",
    "sliding_panel",
)
"""Known categories: the paper's four (laptop, oven, washing_machine, eyeglasses) and three more."""

PAPER_CATEGORIES: tuple[str, ...] = CATEGORIES[:4]


def _maker(category: str) -> Callable[..., ObjectSpec]:
    module = importlib.import_module(f"capt_env.objects.{category}")
    return module.make


def make_object(category: str, instance_id: int, variation: GeometryVariation | None = None) -> ObjectSpec:
    """The ObjectSpec of one instance; a pure function of its arguments. ``variation`` varies its
    geometry (see ``capt_env.objects.style``; eyeglasses have none); None or all off gives the
    category's own instance.

    :raises ValueError: for an unknown category (the message lists the known ones) or an id
        outside 0 <= instance_id < NUM_INSTANCES.
    """
    if category not in CATEGORIES:
        raise ValueError(f"unknown category {category!r}; known categories: {list(CATEGORIES)}")
    check_instance_id(category, instance_id)
    style = draw_style(category, int(instance_id), variation) if variation is not None else None
    spec = _maker(category)(int(instance_id), style)
    if spec.category != category or spec.instance_id != int(instance_id):
        raise AssertionError(f"{category} maker returned a spec for {spec.category} #{spec.instance_id}")
    return spec


__all__ = ["CATEGORIES", "PAPER_CATEGORIES", "NUM_INSTANCES", "make_object"]
