"""``capt generate``: render a labelled single-view cloud dataset of one category or user file (see
dataset.generator); with several files (``--objects``), one dataset per file under ``OUT/LABEL``."""

from __future__ import annotations

import argparse
from pathlib import Path

from capt_common.json_report import write_json
from capt_env.commands.object_targets import add_object_arguments, object_targets


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", default=None,
                        help="GenerateConfig: a shipped name (laptop, oven, ...) or a YAML path (default: "
                             "the GenerateConfig defaults)")
    parser.add_argument("--category", default=None, help="override the config's category")
    parser.add_argument("--out", required=True, help="output directory (resumed if it exists)")
    parser.add_argument("--train", type=int, default=None, help="override the number of train samples")
    parser.add_argument("--val", type=int, default=None, help="override the number of val samples")
    parser.add_argument("--test", type=int, default=None, help="override the number of test samples")
    parser.add_argument("--seed", type=int, default=None, help="override the config's dataset seed")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: every core)")
    add_object_arguments(parser, None, with_categories=False)


def run(args: argparse.Namespace) -> int:
    import dataclasses

    from capt_common.typed_yaml import load_yaml
    from capt_env.dataset.config import GenerateConfig
    from capt_env.dataset.generator import generate
    from capt_env.shipped_configs import resolve_config

    cfg = GenerateConfig()
    if args.config:
        cfg = load_yaml(GenerateConfig, resolve_config("generate", args.config))
    counts = dict(cfg.counts)
    for split in ("train", "val", "test"):
        if getattr(args, split) is not None:
            counts[split] = getattr(args, split)
    changes = {"counts": counts}
    if args.category:
        changes["category"] = args.category
    if args.seed is not None:
        changes["seed"] = args.seed
    jobs = [(dataclasses.replace(cfg, **changes), args.out)]
    if args.object or args.objects:
        if args.category:
            raise SystemExit("give either --category or user files (--object / --objects)")
        args.categories = []
        files = object_targets(args)
        # one dataset per file: OUT itself for one file, OUT/LABEL for several
        jobs = [(dataclasses.replace(cfg, **changes, object=dict(t.task), category=t.label),
                 args.out if len(files) == 1 else str(Path(args.out) / t.label)) for t in files]
    results = []
    for job_cfg, out in jobs:
        job_cfg.validate()
        result = generate(job_cfg, out, workers=args.workers)
        rate = result["samples_per_second"]
        print(f"{job_cfg.category}: {result['counts']} in {out}; rendered {result['rendered_now']} now "
              f"with {result['workers']} workers in {result['seconds']:.1f} s"
              + (f" ({rate:.2f} samples/s)" if rate else "") + f"; {result['skipped_shards']} shards existed")
        results.append(result)
    write_json(args.json, results[0] if len(results) == 1 else {"datasets": results})
    return 0
