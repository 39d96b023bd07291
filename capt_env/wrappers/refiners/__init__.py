"""Geometric refiners of the network's estimate, in the order the ``capt`` source runs them.

Each refiner is a small class with a ``name``, its own config dataclass and a ``refine(draft)`` that
changes a :class:`~capt_env.wrappers.refiners.draft.Draft` in place where its geometric rule holds
(each module's docstring gives the rule and when it must not fire). The ``capt_raw`` source runs
none; ``capt`` runs those the wrapper config names (``refiners``, default all), always in this order:

1. ``dense_handle_search``: look for handles among all isolated points, not only the network's input.
2. ``stacked_parts``: in a drawer stack, the target is the k-th handle from the bottom.
3. ``coplanar_panel``: a closed part's edges and handle are looked for on its whole flat panel.
4. ``edge_direction``: a hinge's direction is turned onto the nearer edge of its rectangular part.
5. ``slide_over_pane``: a sash slides along its track over the pane behind it.
6. ``handle``: the grasp point is the handle standing off the part's face.
7. ``front_normal``: a drawer slides along its front's normal.
8. ``hinge_on_edge``: a hinge's line is put on the part's edge away from the handle.
9. ``opening_sign``: the axis is signed so that opening moves the part out of its body.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Literal, get_args

from capt_common.typed_yaml import require
from capt_env.wrappers.refiners.coplanar_panel import CoplanarPanel, CoplanarPanelConfig
from capt_env.wrappers.refiners.dense_handle_search import DenseHandleSearch, DenseHandleSearchConfig
from capt_env.wrappers.refiners.draft import Draft, Refiner
from capt_env.wrappers.refiners.edge_direction import EdgeDirection, EdgeDirectionConfig
from capt_env.wrappers.refiners.front_normal import FrontNormal, FrontNormalConfig
from capt_env.wrappers.refiners.handle import Handle, HandleConfig
from capt_env.wrappers.refiners.hinge_on_edge import HingeOnEdge, HingeOnEdgeConfig
from capt_env.wrappers.refiners.opening_sign import OpeningSign, OpeningSignConfig
from capt_env.wrappers.refiners.slide_over_pane import SlideOverPane, SlideOverPaneConfig
from capt_env.wrappers.refiners.stacked_parts import StackedParts, StackedPartsConfig

RefinerName = Literal["dense_handle_search", "stacked_parts", "coplanar_panel", "edge_direction",
                      "slide_over_pane", "handle", "front_normal", "hinge_on_edge", "opening_sign"]
REFINER_NAMES: tuple[RefinerName, ...] = get_args(RefinerName)
"""Every refiner's name, in the order they run."""


@dataclass(frozen=True)
class RefinerSettings:
    """Each refiner's config, by the refiner's name (YAML: ``refiner_settings: {coplanar_panel:
    {max_state: 0.35}}``). The defaults here are the only ones."""

    dense_handle_search: DenseHandleSearchConfig = field(default_factory=DenseHandleSearchConfig)
    stacked_parts: StackedPartsConfig = field(default_factory=StackedPartsConfig)
    coplanar_panel: CoplanarPanelConfig = field(default_factory=CoplanarPanelConfig)
    edge_direction: EdgeDirectionConfig = field(default_factory=EdgeDirectionConfig)
    slide_over_pane: SlideOverPaneConfig = field(default_factory=SlideOverPaneConfig)
    handle: HandleConfig = field(default_factory=HandleConfig)
    front_normal: FrontNormalConfig = field(default_factory=FrontNormalConfig)
    hinge_on_edge: HingeOnEdgeConfig = field(default_factory=HingeOnEdgeConfig)
    opening_sign: OpeningSignConfig = field(default_factory=OpeningSignConfig)

    def validate(self) -> None:
        for name in REFINER_NAMES:
            getattr(self, name).validate()


_CLASSES = {cls.name: cls for cls in (DenseHandleSearch, StackedParts, CoplanarPanel, EdgeDirection,
                                      SlideOverPane, Handle, FrontNormal, HingeOnEdge, OpeningSign)}
assert tuple(_CLASSES) == REFINER_NAMES


def check_refiner_names(names: Iterable[str]) -> None:
    """Raise ConfigError for an unknown or repeated refiner name."""
    names = list(names)
    unknown = sorted(set(names) - set(REFINER_NAMES))
    require(not unknown, f"refiners: unknown {unknown}; known: {list(REFINER_NAMES)}")
    require(len(set(names)) == len(names), f"refiners: each name once, got {names}")


def build_refiners(names: Iterable[str] = REFINER_NAMES,
                   settings: RefinerSettings | None = None) -> tuple[Refiner, ...]:
    """The refiners named ``names`` (any order; they run in ``REFINER_NAMES``' order), each with its
    config from ``settings`` (default: every config's defaults)."""
    names = list(names)
    check_refiner_names(names)
    settings = settings or RefinerSettings()
    return tuple(_CLASSES[n](getattr(settings, n)) for n in REFINER_NAMES if n in names)


def without(*names: str) -> tuple[str, ...]:
    """Every refiner's name but ``names`` (for an ablation), in order."""
    check_refiner_names(names)
    return tuple(n for n in REFINER_NAMES if n not in names)


__all__ = ["REFINER_NAMES", "Draft", "Refiner", "RefinerName", "RefinerSettings", "build_refiners",
           "check_refiner_names", "without"]
