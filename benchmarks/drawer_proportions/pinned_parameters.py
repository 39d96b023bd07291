"""``capt generate`` with some of an instance's shape parameters pinned to a range (a diagnosis tool,
not a library option): every ``ParamSampler`` draw named in the JSON draws from the given range.

    python benchmarks/drawer_proportions/pinned_parameters.py '{"width": [0.22, 0.22]}' \
        generate --config drawer_cabinet --out /tmp/dg/narrow --train 0 --val 0 --test 100 \
        --workers 1 --seed 7

``--workers 1`` keeps the generation in this process, where the pins apply.
"""

from __future__ import annotations

import json
import sys
from typing import Any

from capt_env.objects import sampling

PINS: dict[str, tuple[float, float]] = {}
_uniform = sampling.ParamSampler.uniform
_integer = sampling.ParamSampler.integer


def _pinned_uniform(self: sampling.ParamSampler, name: str, low: float, high: float) -> float:
    low, high = PINS.get(name, (low, high))
    return _uniform(self, name, low, high)


def _pinned_integer(self: sampling.ParamSampler, name: str, low: int, high: int) -> int:
    low, high = PINS.get(name, (low, high))
    return _integer(self, name, int(low), int(high))


def main(argv: list[str]) -> Any:
    PINS.update({k: (v[0], v[1]) for k, v in json.loads(argv[0]).items()})
    sampling.ParamSampler.uniform = _pinned_uniform  # type: ignore[method-assign]
    sampling.ParamSampler.integer = _pinned_integer  # type: ignore[method-assign]
    from capt_env.cli import main as capt_main

    return capt_main(argv[1:])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
