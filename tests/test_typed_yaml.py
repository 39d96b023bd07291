"""The strict YAML -> dataclass loader: unknown keys and bad values are errors that name them."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import pytest

from capt_common.typed_yaml import ConfigError, from_dict, load_yaml, require, to_dict


@dataclass(frozen=True)
class Inner:
    size: int = 3
    ratio: tuple[float, float] = (0.1, 0.2)


@dataclass(frozen=True)
class Outer:
    name: str = "x"
    mode: Literal["a", "b"] = "a"
    inner: Inner = field(default_factory=Inner)
    items: tuple[Inner, ...] = ()
    maybe: float | None = None

    def validate(self) -> None:
        require(self.inner.size > 0, "inner.size must be > 0")


def test_defaults_and_nested_values() -> None:
    cfg = from_dict(Outer, {"mode": "b", "inner": {"ratio": [1, 2]}, "items": [{"size": 5}], "maybe": 2})
    assert cfg.mode == "b" and cfg.inner == Inner(3, (1.0, 2.0)) and cfg.items == (Inner(5),)
    assert cfg.maybe == 2.0 and isinstance(cfg.maybe, float)
    assert from_dict(Outer, to_dict(cfg)) == cfg


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"colour": 1}, r"unknown key\(s\) \['colour'\]"),
        ({"inner": {"sise": 1}}, r"config.inner: unknown key"),
        ({"mode": "c"}, r"config.mode: 'c' is not one of"),
        ({"inner": {"size": "3"}}, r"config.inner.size: expected an integer"),
        ({"inner": {"size": True}}, r"config.inner.size: expected an integer"),
        ({"inner": {"ratio": [1]}}, r"config.inner.ratio: expected 2 items"),
        ({"inner": {"size": 0}}, r"inner.size must be > 0"),
        ([1, 2], r"expected a mapping"),
    ],
)
def test_errors_name_the_key(data: object, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        from_dict(Outer, data)


def test_load_yaml_file(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text("name: y\ninner:\n  size: 7\n")
    assert load_yaml(Outer, path).inner.size == 7
    with pytest.raises(ConfigError, match="not found"):
        load_yaml(Outer, tmp_path / "missing.yaml")


def test_shipped_configs_load() -> None:
    import yaml

    from capt_env.commands.task_overrides import task_overrides
    from capt_env.dataset.config import GenerateConfig
    from capt_env.tasks.config import TaskConfig

    root = Path(__file__).resolve().parents[1] / "configs"
    for path in sorted((root / "generate").glob("*.yaml")):
        config = load_yaml(GenerateConfig, path)
        if path.stem == "varied":  # every variation option on, for any --category
            assert config.variation.enabled
            continue
        assert path.stem == config.category or path.stem.startswith(f"{config.category}_")
    for path in sorted((root / "tasks").glob("*.yaml")):
        raw = yaml.safe_load(path.read_text())
        if "category" in raw or "object" in raw:
            load_yaml(TaskConfig, path)
        else:  # an override file for `capt rollout --task`: valid on top of any category
            overrides = task_overrides(str(path))
            config = from_dict(TaskConfig, {"category": "oven", **overrides}, where=str(path))
            assert set(overrides) <= set(to_dict(config))


def test_larger_generate_configs_share_their_base_val_and_test_shards() -> None:
    """``<category>_<n>.yaml`` only adds training clouds: every setting but the train count is its base
    config's, so its val and test shards (a pure function of seed, split and index) are the same."""
    import dataclasses

    from capt_env.dataset.config import GenerateConfig
    from capt_env.dataset.generator import plan_shards

    root = Path(__file__).resolve().parents[1] / "configs" / "generate"
    larger = [p for p in sorted(root.glob("*.yaml"))
              if p.stem != "varied" and p.stem != load_yaml(GenerateConfig, p).category]
    assert larger, "expected at least one larger dataset config"
    for path in larger:
        big = load_yaml(GenerateConfig, path)
        base = load_yaml(GenerateConfig, root / f"{big.category}.yaml")
        assert big.counts["train"] > base.counts["train"]
        assert dataclasses.replace(big, counts=base.counts) == base
        held_out = [j for j in plan_shards(big) if j.split != "train"]
        assert held_out == [j for j in plan_shards(base) if j.split != "train"]
