"""An append-only log of finished episodes, so that an interrupted ``capt rollout`` resumes.

Each line of the file is one JSON object ``{"run": {...}, "episode": {...}}``: ``run`` identifies the
evaluation the episode belongs to (category, policy, model, perception source and checkpoint, the
perception period, step limit, task and opener overrides), ``episode`` is one
:class:`agents.scripted.rollout.EpisodeResult`. A line is written and flushed to disk as soon as its
episode ends. On a new run with the same file, the episodes already recorded for the same ``run``
are read back instead of being played again; lines of other runs are kept and left alone, and a
last line cut short by a crash is ignored (and overwritten by the next append).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any


def _canonical(value: Any) -> Any:
    """``value`` as JSON would read it back (tuples become lists, numpy scalars plain numbers), so
    that a run identity compares equal to the one read from the file."""
    return json.loads(json.dumps(value, sort_keys=True, default=float))


class EpisodeLog:
    """Finished episodes of one evaluation ``run`` (a JSON-serialisable dict), kept in ``path``."""

    def __init__(self, path: str | os.PathLike, run: dict[str, Any]) -> None:
        self.path = Path(path)
        self.run = _canonical(run)
        self._recorded: dict[int, dict[str, Any]] = {}
        self._intact_bytes = 0  # length of the file's complete lines
        if self.path.exists():
            self._read()

    def _read(self) -> None:
        data = self.path.read_bytes()
        offset = 0
        for raw in data.splitlines(keepends=True):
            if not raw.endswith(b"\n"):
                break  # the last line of a run that was killed while writing it
            try:
                entry = json.loads(raw)
                run, episode = entry["run"], entry["episode"]
                seed = int(episode["seed"])
            except (ValueError, KeyError, TypeError) as err:
                raise ValueError(f"{self.path}: line at byte {offset} is not an episode record "
                                 f"({err}); is this the file of another command?") from err
            if run == self.run:
                self._recorded[seed] = episode
            offset += len(raw)
        self._intact_bytes = offset

    def recorded(self, seed: int) -> dict[str, Any] | None:
        """The episode of ``seed`` already recorded for this run, or None."""
        return self._recorded.get(int(seed))

    def __len__(self) -> int:
        return len(self._recorded)

    def append(self, episode: dict[str, Any]) -> None:
        """Record a finished ``episode`` (with a ``seed`` key) of this run, on disk before returning."""
        episode = _canonical(episode)
        line = json.dumps({"run": self.run, "episode": episode}, sort_keys=True) + "\n"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open(self.path, "ab") as fh:
            if fh.tell() > self._intact_bytes:
                fh.truncate(self._intact_bytes)  # drop a partial last line left by a crash
            fh.write(line.encode())
            fh.flush()
            os.fsync(fh.fileno())
            self._intact_bytes = fh.tell()
        self._recorded[int(episode["seed"])] = episode
