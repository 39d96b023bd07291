"""Bad perception-wrapper settings are rejected with a ConfigError naming them."""

from __future__ import annotations

from pathlib import Path

import pytest

from capt_common.typed_yaml import ConfigError, from_dict, load_yaml
from capt_env.wrappers.config import PerceptionWrapperConfig

CONFIGS = Path(__file__).resolve().parents[2] / "configs" / "wrappers"


@pytest.mark.parametrize(
    ("data", "needle"),
    [
        ({"every_k_steps": 0}, "every_k_steps"),
        ({"num_points": 8}, "num_points"),
        ({"source": "lidar"}, "source"),
        ({"source": "capt"}, "checkpoint"),
        ({"obs_format": "xml"}, "obs_format"),
        ({"noise": {"direction_rad": -0.1}}, "direction_rad"),
        ({"noise": {"pivot_m": "far"}}, "pivot_m"),
        ({"isolation": {"mode": "magic"}}, "mode"),
        ({"isolation": {"workspace_min": [1, 0, 0], "workspace_max": [0, 1, 1]}}, "workspace"),
        ({"isolation": {"outlier_k": 0}}, "outlier_k"),
        ({"every_k": 2}, "every_k"),
        ({"refiner_settings": {"coplanar_panel": {"max_state": -0.1}}}, "max_state"),
        ({"refiner_settings": {"hinge": {}}}, "hinge"),
        ({"refiners": ["handle", "magic"]}, "refiners"),
        ({"refiners": ["handle", "handle"]}, "each name once"),
        ({"fusion": {"handle_jump_m": 0.0}}, "handle_jump_m"),
        ({"source": "capt_raw"}, "checkpoint"),
        ({"hinge_on_part_edge": True}, "hinge_on_part_edge"),
    ],
)
def test_bad_values_raise_config_error(data: dict, needle: str) -> None:
    with pytest.raises(ConfigError, match=needle):
        from_dict(PerceptionWrapperConfig, data)


def test_shipped_yaml_configs_load() -> None:
    files = sorted(CONFIGS.glob("*.yaml"))
    assert files
    for path in files:
        cfg = load_yaml(PerceptionWrapperConfig, path)
        assert cfg.every_k_steps >= 1
