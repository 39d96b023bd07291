"""Numbers as URDF attribute text."""

from __future__ import annotations

from typing import Any

import numpy as np


def format_floats(values: Any) -> str:
    """Space-separated floats with 9 significant digits (exact for float32 geometry)."""
    return " ".join(f"{float(v):.9g}" for v in np.asarray(values, dtype=np.float64).reshape(-1))
