"""Shared by the A/B scripts that compare a base git revision with the working tree: the base's code
checked out in a temporary ``git worktree`` (run with it on PYTHONPATH), and runs in ABBA order so
drift of a shared machine's speed hits both sides alike."""

from __future__ import annotations

import subprocess
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TypeVar

ROOT = Path(__file__).resolve().parent.parent
T = TypeVar("T")


@contextmanager
def base_worktree(revision: str) -> Iterator[Path]:
    """A detached worktree of ``revision`` for the block, removed after."""
    tree = Path(tempfile.mkdtemp(prefix="capt_ab_base_"))
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), revision],
                   check=True, capture_output=True)
    try:
        yield tree
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)],
                       check=False, capture_output=True)


def abba(run: Callable[[Path], T], base: Path, rounds: int) -> dict[str, list[T]]:
    """``run(tree)`` for the base and this tree in ``rounds`` ABBA blocks: {"base": [...], "tree": [...]}."""
    runs: dict[str, list[T]] = {"base": [], "tree": []}
    for _ in range(rounds):
        for side in ("base", "tree", "tree", "base"):
            runs[side].append(run(base if side == "base" else ROOT))
    return runs
