"""A category-agnostic scripted opener driven only by a joint-axis estimate (type, axis, pivot, state,
grasp point), and a rollout helper that measures its success rate."""

from agents.scripted.config import ScriptedOpenerConfig
from agents.scripted.opener import Phase, ScriptedOpener

__all__ = ["Phase", "ScriptedOpener", "ScriptedOpenerConfig"]
