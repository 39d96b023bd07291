"""``capt train``: train one CAPT variant on a generated dataset (see perception.training)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from capt_common.json_report import write_json


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", default="capt",
                        help="TrainConfig: a shipped name (capt, capt_plain, pct_regression, ...) or a YAML "
                             "path")
    parser.add_argument("--data", required=True, nargs="+",
                        help="dataset directory made by `capt generate`; several of one category (e.g. "
                             "plain and varied clouds) train that category's model together, several "
                             "categories one cross-category model (--config capt_cross_category)")
    parser.add_argument("--out", required=True, help="run directory: last.pt, best.pt, log.csv")
    parser.add_argument("--epochs", type=int, default=None, help="override the config's epochs")
    parser.add_argument("--device", default=None, help="auto, cpu or cuda[:i] (default: the config's)")
    parser.add_argument("--seed", type=int, default=None,
                        help="override the config's seed (weights, shuffling, augmentation)")
    parser.add_argument("--stop-after", type=int, default=None,
                        help="run at most this many epochs now; run again to resume")
    parser.add_argument("--no-resume", action="store_true", help="start over even if last.pt exists")
    parser.add_argument("--init-checkpoint", default=None,
                        help="CAPT checkpoint whose weights start a new run (fine-tune, e.g. a shipped "
                             "one); ignored when resuming from last.pt")


def dataset_category(data_dir: str | Path) -> str:
    """The category a ``capt generate`` directory holds (from its manifest)."""
    manifest = Path(data_dir) / "manifest.json"
    if not manifest.is_file():
        raise SystemExit(f"{data_dir} has no manifest.json: make it with `capt generate`")
    return json.loads(manifest.read_text())["config"]["category"]


def train_config_for(config_path: str, data_dirs: str | list[str], epochs: int | None, device: str | None,
                     seed: int | None = None):
    """The YAML TrainConfig with the model's output channels set for the dataset's category (a config
    with ``any`` joint slots keeps its own: every dataset's category must fit them), and the command
    line's overrides (``None``: keep the config's). Returns the config and the category label
    (categories joined by ``+`` for a cross-category model)."""

    from capt_common.typed_yaml import from_dict, load_yaml, to_dict
    from capt_env.dataset.category_structure import category_structure
    from capt_env.shipped_configs import resolve_config
    from perception.config import TrainConfig

    dirs = [data_dirs] if isinstance(data_dirs, str) else list(data_dirs)
    categories = [dataset_category(d) for d in dirs]
    cfg = to_dict(load_yaml(TrainConfig, resolve_config("perception", config_path)))
    model = cfg["model"]["model"]
    if "any" not in model["joint_types"]:
        if len(set(categories)) > 1:
            raise SystemExit(f"--data {' '.join(dirs)}: datasets of several categories "
                             f"({', '.join(dict.fromkeys(categories))}) train one cross-category model, "
                             f"whose config has 'any' joint slots (--config capt_cross_category)")
        model.update(category_structure(categories[0]))
    else:
        for category in categories:
            _check_fits_slots(category, category_structure(category), model)
    category = "+".join(dict.fromkeys(categories))
    for key, value in {"epochs": epochs, "device": device, "seed": seed}.items():
        if value is not None:
            cfg[key] = value
    return from_dict(TrainConfig, cfg), category


def _check_fits_slots(category: str, structure: dict, model: dict) -> None:
    """SystemExit unless ``category``'s joints fit the cross-category model's slots: no more parts or
    joints, and joint ``k``'s child part is slot ``k``'s."""
    n = structure["max_joints"]
    if structure["max_parts"] > model["max_parts"] or n > model["max_joints"] or (
            list(structure["joint_child_parts"]) != list(model["joint_child_parts"][:n])):
        raise SystemExit(f"{category}: {structure} does not fit the model's slots (max_parts "
                         f"{model['max_parts']}, joint_child_parts {model['joint_child_parts']})")


def run(args: argparse.Namespace) -> int:
    from perception.training import epoch_seconds, train

    cfg, category = train_config_for(args.config, args.data, args.epochs, args.device, args.seed)
    result = train(cfg, args.data, args.out, resume=not args.no_resume, stop_after=args.stop_after,
                   init_from=args.init_checkpoint)
    print(f"{category} {cfg.model.model.variant}: {result.epochs_run}/{cfg.epochs} epochs, "
          f"best val loss {result.best_val_loss:.4f}, voting window {result.voting_window}, "
          f"best checkpoint {result.best_path}")
    write_json(args.json, {
        "category": category, "variant": cfg.model.model.variant, "epochs_run": result.epochs_run,
        "epochs": cfg.epochs, "seed": cfg.seed, "best_val_loss": result.best_val_loss,
        "voting_window": list(result.voting_window), "best_path": str(result.best_path),
        "log": str(result.log_path), "init_from": args.init_checkpoint,
        "epoch_seconds": epoch_seconds(result.log_path),
    })
    return 0


