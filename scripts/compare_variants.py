"""CAPT vs CAPT-plain vs direct-regression PCT across categories, from `capt evaluate --json` files.

Each input file is one `capt evaluate` run that scored the three variants side by side on one
category's test split. Files that score the same method on the same category again are further
training runs (e.g. another `capt train --seed`) of it, evaluated on the same data: its values are
the mean over its runs, its method cell says how many, and the paired gaps use per-cloud errors
averaged over runs (a file given twice is an error). Prints, per category and as the mean over
categories, the mean direction error (degrees), position error (normalised object frame), and state
error, in degrees over revolute joints and in metres over prismatic ones (never averaged together),
each first averaged over the category's joints. A joint without a position error is prismatic
(``capt evaluate`` reports none for them). A mean over no value (e.g. position when every category
is prismatic) is "-". The means table also gives the share of axes pointing the wrong way (direction
error over 90 degrees, ``capt evaluate``'s ``dir_flipped``), as a few sign flips can carry a
mean direction error.

Then, for every method beside the reference (``--reference``, default ``capt``), the paired gap
reference minus method on each category and on the mean, with a 95% bootstrap interval over the test
clouds (``perception/paired_comparison.py``; ``--draws``, ``--seed``): negative means the reference
has the lower error, and an interval that excludes 0 means the gap is more than the luck of which
clouds are in the test split (it does not measure training noise). ``--resample instances`` draws
the test instances instead, with all their views (needs the samples' ``instance_id``): the luck of
which objects are in the test split. ``--methods`` reads only the listed methods from the files
(e.g. a seed's file that also scored ``capt_without_dv``). ``--rename PATTERN=NAME`` names the
methods matching a shell-style pattern, before ``--methods`` reads them: two checkpoints of one
variant scored in one run are named by ``capt evaluate`` after their paths
(``capt (runs/laptop/capt_seed3/best.pt)``), so ``--rename 'capt (*capt_seed*)=capt'`` makes
every seed's file name them alike.

    .venv/bin/python scripts/compare_variants.py benchmarks/perception_laptop.json \
        benchmarks/perception_oven.json --markdown benchmarks/variants_mean.md \
        --json benchmarks/variants_mean.json
"""

from __future__ import annotations

import argparse
import fnmatch
import gzip
import json
import statistics
from collections.abc import Callable
from pathlib import Path

from capt_common.json_report import script_command, write_json, write_markdown
from perception.paired_comparison import METRICS as PAIRED_METRICS
from perception.paired_comparison import RESAMPLE_UNITS, PairedDifference, paired_differences

# (key, column label); the keys are perception.paired_comparison's, in its order
METRICS = tuple(zip(PAIRED_METRICS, ("direction (deg)", "position (normalised)", "state, revolute (deg)",
                                     "state, prismatic (m)"), strict=True))
# the means table's columns: the paired metrics, then the share of axes pointing the wrong way (a
# direction error over 90 degrees, `capt evaluate`'s dir_flipped), which has no paired gap
COLUMNS = (*METRICS, ("dir_flipped", "direction flipped (share)"))
# what a `capt evaluate --json` file without "test_corruption" (older than the key) was scored with
CLEAN = {"jitter_m": 0.0, "outlier_fraction": 0.0}


def table_head(columns: tuple[tuple[str, str], ...]) -> list[str]:
    """A Markdown table's header lines for a category and a method column, then ``columns``."""
    return ["| category | method | " + " | ".join(label for _, label in columns) + " |",
            "|" + " --- |" * (len(columns) + 2)]


def joint_mean(values: list[float | None]) -> float | None:
    """Mean of the values that exist (over a category's joints, skipping joints without the metric,
    or over categories); None when none does."""
    present = [v for v in values if v is not None]
    return statistics.fmean(present) if present else None


def category_errors(s: dict) -> dict[str, float | None]:
    """One method's joint means on one category from its ``capt evaluate`` summary ``s``; the state
    is split by joint type (a joint with no position error is prismatic). ``dir_flipped`` is None for
    a summary older than it."""
    revolute = [p is not None for p in s["pos_aed"]]
    return {"dir_med": joint_mean(s["dir_med"]), "pos_aed": joint_mean(s["pos_aed"]),
            "state_deg": joint_mean([v for v, r in zip(s["state_med"], revolute, strict=True) if r]),
            "state_m": joint_mean([v for v, r in zip(s["state_med"], revolute, strict=True) if not r]),
            "dir_flipped": joint_mean(s.get("dir_flipped", []))}


def read_run(path: Path) -> dict:
    """A ``capt evaluate --json`` file, plain or gzip-compressed (``.json.gz``, as kept in
    ``benchmarks/robustness/``)."""
    if path.suffix == ".gz":
        with gzip.open(path, "rt") as fh:
            return json.load(fh)
    return json.loads(path.read_text())


def renamer(rules: list[tuple[str, str]] | None) -> Callable[[str], str]:
    """A function naming a method by the first ``(pattern, name)`` rule whose shell-style pattern
    matches it (``fnmatch``, case-sensitive); a name no rule matches is kept."""
    def name(method: str) -> str:
        return next((new for pattern, new in rules or () if fnmatch.fnmatchcase(method, pattern)), method)
    return name


def parse_rename(rule: str) -> tuple[str, str]:
    """``"PATTERN=NAME"`` -> ``(PATTERN, NAME)``; the last ``=`` splits (a pattern may hold one)."""
    pattern, sep, name = rule.rpartition("=")
    if not sep or not pattern or not name:
        raise ValueError(f"a --rename rule is PATTERN=NAME, got {rule!r}")
    return pattern, name


def compare(paths: list[Path], reference: str = "capt", draws: int = 2000, seed: int = 0,
            resample: str = "clouds", only: list[str] | None = None,
            rename: list[tuple[str, str]] | None = None) -> dict:
    """{"methods": [...], "categories": {cat: {method: {metric: value}}}, "mean": {method: {...}},
    "runs": {cat: {method: number of runs averaged}},
    "paired": {method: {cat or "mean": {metric: {difference, low, high, reference_lower_share}}}}}.
    ``paired`` is empty when ``draws`` is 0, when the files hold no per-sample results, or when the
    reference method is not in them. ``only``: read just these methods from the files (e.g. leave
    out a row one of several runs also scored); a listed method no file holds is a ValueError, and so
    are files scored in different test poses (``capt evaluate --test-pose``; absent means world) or
    with different sensor corruptions (``--test-jitter``, ``--test-outliers``; absent means none) or
    outlier filters (``--filter-outliers``; absent means none). ``rename``: ``(pattern, name)`` rules
    applied to every method name before ``only`` (see :func:`renamer`); two methods of one file given
    one name is a ValueError."""
    per_run: dict[str, dict[str, list[dict[str, float | None]]]] = {}
    samples: list[dict] = []
    seen: set[str] = set()

    def keep(method: str) -> bool:
        return only is None or method in only

    name = renamer(rename)

    poses: dict[str, list[str]] = {}
    corruptions: dict[str, list[str]] = {}
    for index, path in enumerate(paths):
        run = read_run(path)
        names = [name(m) for m in run["summary"]]
        clash = sorted({n for n in names if names.count(n) > 1})
        if clash:
            raise ValueError(f"{path}: --rename gives two of its methods the name(s) {clash}: "
                             f"{sorted(run['summary'])}")
        run["summary"] = dict(zip(names, run["summary"].values(), strict=True))
        poses.setdefault(run.get("test_pose", "world"), []).append(str(path))
        corruption = json.dumps({"test_corruption": run.get("test_corruption", CLEAN),
                                 "outlier_filter": run.get("outlier_filter")}, sort_keys=True)
        corruptions.setdefault(corruption, []).append(str(path))
        seen.update(run["summary"])
        renamed = ({**s, "method": name(s["method"])} for s in run.get("samples", []))
        samples.extend({**s, "run": index} for s in renamed if keep(s["method"]))
        for method, cats in run["summary"].items():
            if not keep(method):
                continue
            for cat, s in cats.items():
                per_run.setdefault(cat, {}).setdefault(method, []).append(category_errors(s))
    if len(poses) > 1:
        raise ValueError(f"the inputs were scored in different test poses, which do not average: {poses}")
    if len(corruptions) > 1:
        raise ValueError(f"the inputs were scored with different test corruptions or outlier filters, "
                         f"which do not average: {corruptions}")
    absent = sorted(set(only or ()) - seen)
    if absent:
        raise ValueError(f"no input scored the method(s) {absent}; they hold {sorted(seen)}")
    per_cat = {c: {m: {k: joint_mean([r[k] for r in runs]) for k, _ in COLUMNS} for m, runs in by_m.items()}
               for c, by_m in per_run.items()}
    methods = sorted(set.intersection(*(set(v) for v in per_cat.values())))
    if not methods:
        raise SystemExit("no method was evaluated on every category")
    mean = {m: {k: joint_mean([per_cat[c][m][k] for c in per_cat]) for k, _ in COLUMNS}
            for m in methods}
    paired: dict = {}
    if draws > 0 and any(x["method"] == reference for x in samples):
        paired = {m: {c: {k: _as_dict(d) for k, d in by_metric.items()} for c, by_metric in rows.items()}
                  for m, rows in paired_differences(samples, reference, draws, seed, resample).items()}
    return {"methods": methods, "categories": per_cat, "mean": mean, "inputs": [str(p) for p in paths],
            "only": only, "rename": [list(r) for r in rename or ()], "test_pose": next(iter(poses)),
            **json.loads(next(iter(corruptions))),
            "reference": reference, "draws": draws, "seed": seed, "resample": resample, "paired": paired,
            "runs": {c: {m: len(runs) for m, runs in by_m.items()} for c, by_m in per_run.items()}}


def _as_dict(d: PairedDifference | None) -> dict | None:
    return None if d is None else {"difference": d.difference, "low": d.low, "high": d.high,
                                   "reference_lower_share": d.reference_lower_share}


def markdown(result: dict) -> str:
    lines = table_head(COLUMNS)
    rows = [*((c, result["categories"][c]) for c in sorted(result["categories"])), ("mean", result["mean"])]
    runs = result.get("runs", {})
    for cat, by_method in rows:
        for m in result["methods"]:
            cells = ["-" if by_method[m][k] is None else f"{by_method[m][k]:.4g}" for k, _ in COLUMNS]
            n = runs.get(cat, {}).get(m, 1)
            label = f"{m} (mean of {n} runs)" if n > 1 else m
            lines.append(f"| {cat} | {label} | " + " | ".join(cells) + " |")
    if result.get("paired"):
        ref = result["reference"]
        unit = ("the test instances (every view of a drawn instance)"
                if result.get("resample") == "instances" else "the test clouds")
        lines += ["", f"{ref} minus each method, with a 95% paired bootstrap interval over {unit} "
                  f"({result['draws']} draws, seed {result['seed']}; negative: {ref} has the lower "
                  "error):", "", *table_head(METRICS)]
        for other, rows in result["paired"].items():
            for cat in [*sorted(c for c in rows if c != "mean"), "mean"]:
                cells = ["-" if rows[cat][k] is None else _gap(rows[cat][k]) for k, _ in METRICS]
                lines.append(f"| {cat} | {ref} - {other} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _gap(d: dict) -> str:
    return f"{d['difference']:+.3g} [{d['low']:+.3g}, {d['high']:+.3g}]"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="+", type=Path, help="capt evaluate --json files (.json or .json.gz)")
    parser.add_argument("--markdown", type=Path, default=None)
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--reference", default="capt",
                        help="method whose gaps to the others are bootstrapped")
    parser.add_argument("--draws", type=int, default=2000, help="bootstrap draws (0: no paired gaps)")
    parser.add_argument("--seed", type=int, default=0, help="bootstrap seed")
    parser.add_argument("--methods", nargs="+", default=None,
                        help="read only these methods from the inputs (default: all)")
    parser.add_argument("--resample", choices=RESAMPLE_UNITS, default="clouds",
                        help="what a bootstrap draw resamples: test clouds, or test instances with all "
                             "their views (needs instance ids in the files)")
    parser.add_argument("--rename", action="append", default=None, metavar="PATTERN=NAME",
                        help="name the methods matching a shell-style pattern (repeatable; the first "
                             "matching rule wins), e.g. 'capt (*capt_seed*)=capt'")
    args = parser.parse_args()
    if args.draws < 0:
        parser.error(f"--draws must be >= 0, got {args.draws}")
    missing = [str(p) for p in args.inputs if not p.is_file()]
    if missing:
        parser.error(f"no such capt evaluate --json file: {', '.join(missing)}")
    resolved = [p.resolve() for p in args.inputs]
    twice = sorted({str(p) for p, r in zip(args.inputs, resolved, strict=True) if resolved.count(r) > 1})
    if twice:
        parser.error(f"an input is given twice (it would count as two training runs): {', '.join(twice)}")
    try:
        rename = [parse_rename(r) for r in args.rename or ()]
        result = compare(args.inputs, args.reference, args.draws, args.seed, args.resample, args.methods,
                         rename)
    except ValueError as err:
        parser.error(str(err))
    table = markdown(result)
    print(table, end="")
    command = script_command()
    write_markdown(args.markdown, table, command)
    write_json(args.json, result, command)


if __name__ == "__main__":
    main()
