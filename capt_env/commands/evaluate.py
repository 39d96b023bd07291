"""``capt evaluate``: the paper's Table I (and Table II timing) for one or more checkpoints, side by side.

Every number is the network's own estimate, the ``capt_raw`` perception source (double voting as the
variant has it, no geometric refiners: those need the scene around a look, which a dataset cloud
does not have); the table says so, and ``capt estimate-errors`` scores the refined ``capt`` source.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from capt_common.json_report import write_json

if TYPE_CHECKING:
    from perception.corruption import Corruption
    from perception.outlier_filter import OutlierFilter

PERCEPTION_SOURCE = "capt_raw"
"""What a dataset cloud is scored with: the network alone (see the module docstring)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("checkpoints", nargs="+", help="checkpoints (e.g. CAPT, CAPT-plain, PCT) to compare")
    parser.add_argument("--data", required=True, help="dataset directory made by `capt generate`")
    parser.add_argument("--split", default="test", choices=["train", "val", "test"],
                        help="dataset split to score")
    parser.add_argument("--device", default="cpu", help="torch device (cpu, cuda, cuda:1)")
    parser.add_argument("--timing-clouds", type=int, default=100,
                        help="time at least this many calls per checkpoint (the scored clouds are timed, "
                             "then more calls cycle over the split)")
    parser.add_argument("--max-samples", type=int, default=None,
                        help="score at most this many clouds (default: all)")
    parser.add_argument("--markdown", default=None, help="also write the table as Markdown here")
    parser.add_argument("--figures", default=None, help="save a cloud+axes PNG per checkpoint here")
    parser.add_argument("--without-double-voting", action="store_true",
                        help="also score each CAPT checkpoint with the coarse vote only, as method "
                             "capt_without_dv (the paper's 'CAPT w/o DV')")
    parser.add_argument("--test-pose", default="world", choices=["world", "yaw", "so3"],
                        help="score the stored world-frame clouds (world), or each in a seeded rigid pose: "
                             "rotation about +z (yaw) or about x, y and z (so3, as the paper's augmented "
                             "test clouds), translation in [-1, 1] m; the same poses for every checkpoint")
    parser.add_argument("--test-jitter", type=float, default=0.0, metavar="METRES",
                        help="add seeded Gaussian noise with this standard deviation (metres) to every test "
                             "point, the same noise for every checkpoint")
    parser.add_argument("--test-outliers", type=float, default=0.0, metavar="FRACTION",
                        help="append this fraction (of the cloud's points) of seeded stray points, uniform "
                             "in the cloud's bounding box; segmentation is scored on the cloud's own points")
    parser.add_argument("--filter-outliers", action="store_true",
                        help="make every checkpoint drop stray points (statistical outlier removal) before "
                             "its network, as ArticulationEstimator(outlier_filter=...) does")
    parser.add_argument("--filter-neighbours", type=int, default=None, metavar="K",
                        help="with --filter-outliers: nearest points that score each point (default 8)")
    parser.add_argument("--filter-std-ratio", type=float, default=None, metavar="R",
                        help="with --filter-outliers: robust standard deviations above the median score a "
                             "kept point may lie (default 3)")


def run(args: argparse.Namespace) -> int:
    import dataclasses

    from perception.checkpoint import CheckpointError
    from perception.corruption import Corruption
    from perception.evaluation import evaluate
    from perception.metrics import summarise

    try:
        corruption = Corruption(jitter_m=args.test_jitter, outlier_fraction=args.test_outliers)
        outlier_filter = _outlier_filter(args)
        result = evaluate(args.checkpoints, args.data, split=args.split, device=args.device,
                          timing_clouds=args.timing_clouds, max_samples=args.max_samples,
                          without_double_voting=args.without_double_voting, test_pose=args.test_pose,
                          corruption=corruption, outlier_filter=outlier_filter)
    except (ValueError, CheckpointError, FileNotFoundError) as err:
        raise SystemExit(f"capt evaluate: {err}") from err
    timing = "\n".join(f"| {m} | {ms:.1f} |" for m, ms in result.median_ms.items())
    pose = "" if args.test_pose == "world" else f"Test clouds in {args.test_pose} poses (`--test-pose`).\n\n"
    noise = "" if corruption.is_clean else f"Test clouds corrupted: {corruption.describe()}.\n\n"
    if outlier_filter is not None:
        noise += (f"Stray points filtered before the network: {outlier_filter.neighbours} neighbours, "
                  f"std ratio {outlier_filter.std_ratio:g}.\n\n")
    source = f"Perception source: `{PERCEPTION_SOURCE}` (the network alone, no refiners).\n\n"
    for method, count in result.target_only.items():
        noise += (f"{count} clouds have more joints than {method}'s model has slots: each is scored on its "
                  f"target joint only, in the slot the estimate pipeline reads it from, its other moving "
                  f"parts counted as fixed.\n\n")
    medians = (f"Median errors (a few flipped axes can carry a mean; position: distance between the axis "
               f"lines):\n\n{result.medians}")
    text = (f"{source}{pose}{noise}{result.table}\n\n{medians}\n\nTime per input (median over >= "
            f"{args.timing_clouds} clouds, device {args.device}):\n\n| method | ms |\n| --- | --- |\n"
            f"{timing}\n")
    print(text)
    if args.markdown:
        Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
        Path(args.markdown).write_text(text)
    if args.figures:
        _figures(args.checkpoints, args.data, args.split, Path(args.figures), args.test_pose, corruption,
                 outlier_filter)
    methods = sorted({r.method for r in result.results})
    categories = sorted({r.category for r in result.results})
    summary = {m: {c: summarise([r for r in result.results if r.method == m and r.category == c])
                   for c in categories} for m in methods}
    write_json(args.json, {
        "perception": PERCEPTION_SOURCE, "split": args.split, "test_pose": args.test_pose,
        "test_corruption": dataclasses.asdict(corruption),
        "outlier_filter": None if outlier_filter is None else dataclasses.asdict(outlier_filter),
        "data": args.data, "checkpoints": args.checkpoints,
        "median_ms_per_input": result.median_ms, "summary": summary, "table_markdown": result.table,
        "median_table_markdown": result.medians, "target_joint_only": result.target_only,
        "samples": [dataclasses.asdict(r) for r in result.results],
    })
    return 0


def _outlier_filter(args: argparse.Namespace) -> OutlierFilter | None:
    """The command line's outlier filter, or None without ``--filter-outliers`` (whose options alone are
    an error rather than ignored)."""
    from perception.outlier_filter import OutlierFilter

    options = {"neighbours": args.filter_neighbours, "std_ratio": args.filter_std_ratio}
    given = {k: v for k, v in options.items() if v is not None}
    if not args.filter_outliers:
        if given:
            raise ValueError(f"--filter-neighbours and --filter-std-ratio need --filter-outliers; "
                             f"got {given}")
        return None
    return OutlierFilter(**given)


def _figures(checkpoints: list[str], data: str, split: str, out_dir: Path, test_pose: str = "world",
             corruption: Corruption | None = None, outlier_filter: OutlierFilter | None = None) -> None:
    """One picture per checkpoint: the first test cloud (in its ``test_pose``, with its ``corruption``,
    stray points included) coloured by predicted part,
    axes red/green. Named ``<category>_<variant>.png``, with the checkpoint's position appended (``_2``)
    when an earlier checkpoint of the same variant already took that name."""

    from perception.corruption import corrupt_cloud
    from perception.data import CaptShardDataset
    from perception.figures import plot_cloud_with_axes
    from perception.inference import ArticulationEstimator

    taken: set[str] = set()
    for i, path in enumerate(checkpoints, start=1):
        est = ArticulationEstimator.from_checkpoint(path, outlier_filter=outlier_filter)
        sample = CaptShardDataset(data, split, est.config.model, augment=False, max_samples=1,
                                  pose=test_pose).posed(0)
        cloud = sample.object_points()
        if corruption is not None:
            cloud = corrupt_cloud(cloud, 0, corruption)
        pred = est.predict(cloud)
        true = [(sample.joint_dirs[k], sample.joint_pivots[k]) for k in range(len(sample.joint_mask))
                if sample.joint_mask[k]]
        name = f"{sample.category}_{est.config.model.variant}.png"
        name = name if name not in taken else name.replace(".png", f"_{i}.png")
        taken.add(name)
        plot_cloud_with_axes(out_dir / name, cloud, pred.part_labels,
                             [(j.direction, j.pivot) for j in pred.joints], true,
                             title=f"{sample.category}, {est.config.model.variant}")
        print(f"wrote {out_dir / name}")
