"""Shipped default CAPT checkpoints, one per category, each with a model card (``<category>.md``)."""

from __future__ import annotations

from pathlib import Path

CHECKPOINT_DIR = Path(__file__).resolve().parent


def shipped_categories() -> list[str]:
    """Categories that have a shipped default checkpoint."""
    return sorted(p.stem for p in CHECKPOINT_DIR.glob("*.pt"))


def default_checkpoint(category: str) -> Path:
    """Path of the shipped CAPT checkpoint for ``category``; FileNotFoundError names what exists."""
    path = CHECKPOINT_DIR / f"{category}.pt"
    if not path.is_file():
        raise FileNotFoundError(
            f"no shipped checkpoint for {category!r}; shipped: {shipped_categories()}. "
            "Train one with `capt generate` + `capt train` and pass its path instead."
        )
    return path
