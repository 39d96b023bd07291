"""Shipped PPO policies, one folder per category: ``final.zip`` (SB3), ``vecnormalize.pkl``, the
run's ``config.yaml`` and a ``MODEL_CARD.md`` (command, steps, wall time, measured success)."""

from __future__ import annotations

from pathlib import Path

POLICY_DIR = Path(__file__).resolve().parent


def shipped_policy(category: str) -> Path:
    """The shipped PPO model (``final.zip``) for ``category``; FileNotFoundError naming the shipped
    categories when there is none."""
    path = POLICY_DIR / category / "final.zip"
    if not path.is_file():
        have = sorted(p.parent.name for p in POLICY_DIR.glob("*/final.zip"))
        raise FileNotFoundError(f"no shipped PPO policy for {category!r} (shipped: {have or 'none'}); "
                                "train one with `capt train-ppo` and pass --model")
    return path
