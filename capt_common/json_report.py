"""Reports of a command's numbers: JSON written atomically with the command line, machine and versions
that produced them (``write_json``), and a Markdown table headed by its command line
(``write_markdown``, ``script_command``)."""

from __future__ import annotations

import json
import math
import os
import platform
import shlex
import sys
import tempfile
from pathlib import Path
from typing import Any


def machine_info() -> dict[str, Any]:
    """The machine and software a number was measured on."""
    info: dict[str, Any] = {
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
    }
    for mod in ("torch", "sapien", "mani_skill", "gymnasium", "numpy"):
        try:
            info[mod] = __import__(mod).__version__
        except Exception:  # noqa: BLE001 - a missing module is reported as such
            info[mod] = None
    return info


def _strict(value: Any) -> Any:
    """NaN and infinities (not valid JSON) become null; containers are converted recursively."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _strict(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_strict(v) for v in value]
    return value


def write_json(path: str | os.PathLike | None, payload: dict[str, Any], command: str | None = None) -> None:
    """Write ``payload`` plus ``command`` and ``machine`` to ``path`` as strict JSON (NaN -> null; no-op
    for None). ``command`` defaults to the running ``capt`` command line (scripts pass their own)."""
    if path is None:
        return
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if command is None:
        command = shlex.join(["capt", *sys.argv[1:]])
    data = {"command": command, "machine": machine_info(), **payload}
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(_strict(json.loads(json.dumps(data, default=float))), fh, indent=2, allow_nan=False)
        fh.write("\n")
    os.replace(tmp, path)
    print(f"wrote {path}")


def script_command() -> str:
    """The running repository script's command line, as ``.venv/bin/python scripts/<name>.py ARGS``,
    shell-quoted (an argument with spaces, like a ``--rename`` rule, pastes back as one)."""
    return shlex.join([".venv/bin/python", f"scripts/{Path(sys.argv[0]).name}", *sys.argv[1:]])


def write_markdown(path: str | os.PathLike | None, text: str, command: str) -> None:
    """Write ``text`` to ``path`` headed by ``command`` in backticks (no-op for None)."""
    if path is None:
        return
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"`{command}`\n\n{text}")
