"""``--noise KEY=VALUE ...``: fields of the ``noisy_oracle`` source's NoiseConfig, shared by
``capt rollout`` and ``capt noise-sweep``; validated here, so a bad key or value exits naming it."""

from __future__ import annotations

import argparse
from typing import Any


def add_noise_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--noise KEY=VALUE ...`` to a command's parser."""
    parser.add_argument("--noise", nargs="+", default=[], metavar="KEY=VALUE",
                        help="noisy_oracle noise (NoiseConfig fields: model=gaussian|fixed_offset, "
                             "direction_rad, pivot_m, state, grasp_m, grasp_outward_m; radians, metres); "
                             "unset fields keep their defaults")


def noise_overrides(items: list[str]) -> dict[str, Any]:
    """The NoiseConfig fields of ``KEY=VALUE`` strings (numbers as floats, ``model`` as text),
    checked by building and validating the config; SystemExit naming a malformed item, an unknown
    key or a bad value."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise SystemExit(f"--noise {item!r}: expected KEY=VALUE")
        if key == "model":
            out[key] = value
            continue
        try:
            out[key] = float(value)
        except ValueError:
            raise SystemExit(f"--noise {item!r}: {key} needs a number, got {value!r}") from None
    check_noise(out)
    return out


def check_noise(overrides: dict[str, Any]) -> None:
    """SystemExit naming the key when NoiseConfig ``overrides`` are unknown or out of range."""
    from capt_common.typed_yaml import ConfigError, from_dict
    from capt_env.wrappers.config import NoiseConfig

    try:
        from_dict(NoiseConfig, overrides, where="noise").validate()
    except ConfigError as err:
        raise SystemExit(f"--noise: {err}") from err


def resolved_noise(overrides: dict[str, Any]) -> dict[str, Any]:
    """Every NoiseConfig field, ``overrides`` applied to the defaults (what a JSON report records)."""
    from capt_common.typed_yaml import from_dict, to_dict
    from capt_env.wrappers.config import NoiseConfig

    return to_dict(from_dict(NoiseConfig, overrides, where="noise"))
