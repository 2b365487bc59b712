#!/usr/bin/env python3
"""Per-seed speed ratio of one set of experiment points to another, seed by seed.

usage: seed_ratio.py RESULTS_CSV [RESULTS_CSV ...] --of ARM[@DEMAND] --to ARM[@DEMAND]
                     [--metric COLUMN] [--below SHARE]

Pairs every finished point of --of with the point of --to at the same PR and seed (and the
same demand unless @DEMAND is given on either side) from ./palcas experiment results.csv
files, and prints a Markdown table per PR and demand pair: each seed's two values and their
ratio, then the mean ratio, the worst seed and how many seeds fall below --below (default
0.95, issue 18's worst-seed bound).

Two uses: an arm against SUMO-native on the same traffic (--of palcas --to sumo_native), and
SUMO-native against itself with a perturbation too small to matter on average
(--of sumo_native@1801 --to sumo_native@1800): near capacity the moment the road breaks down
follows every detail of the traffic, so the second gives the spread a same-seed ratio has
even when nothing systematic changed.
"""
import argparse
import csv
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from experiment_results import number  # noqa: E402


def side(text):
    """'ARM' or 'ARM@DEMAND' -> (arm, demand or None)."""
    arm, _, demand = text.partition("@")
    if not arm:
        raise SystemExit(f"seed_ratio: '{text}' names no arm (ARM or ARM@DEMAND)")
    if not demand:
        return arm, None
    try:
        value = float(demand)
    except ValueError:
        raise SystemExit(f"seed_ratio: demand '{demand}' in '{text}' is not a number") from None
    if not math.isfinite(value) or value <= 0:
        raise SystemExit(f"seed_ratio: demand '{demand}' in '{text}' must be > 0")
    return arm, value


def read_points(paths, metric):
    """{(arm, pr, demand, seed): value} of the finished points that have the metric."""
    points = {}
    for path in paths:
        try:
            with open(path, newline="") as f:
                rows = list(csv.DictReader(f))
        except OSError as e:
            raise SystemExit(f"seed_ratio: cannot read {path}: {e.strerror}") from None
        if rows and metric not in rows[0]:
            raise SystemExit(f"seed_ratio: {path} has no column '{metric}'")
        for row in rows:
            if row.get("status") != "done":
                continue
            value = number(row.get(metric))
            if value is None:
                continue
            key = (row["arm"], float(row["pr"]), number(row.get("demand")), int(row["seed"]))
            points[key] = value
    return points


def pairs(points, of, to):
    """{(pr, demand of, demand to): [(seed, value of, value to)]} of the seeds both sides have."""
    found = {}
    for (arm, pr, demand, seed), value in points.items():
        if arm != of[0] or (of[1] is not None and demand != of[1]):
            continue
        demand_to = to[1] if to[1] is not None else demand
        other = points.get((to[0], pr, demand_to, seed))
        if other is None or (arm, demand) == (to[0], demand_to):
            continue
        found.setdefault((pr, demand, demand_to), []).append((seed, value, other))
    return {k: sorted(v) for k, v in sorted(found.items(), key=lambda kv: tuple(x or 0 for x in kv[0]))}


def table(of, to, paired, metric, below):
    label_of, label_to = of[0], to[0]
    lines = []
    for (pr, demand_of, demand_to), rows in paired.items():
        d_of = f"@{demand_of:g}" if demand_of is not None else ""
        d_to = f"@{demand_to:g}" if demand_to is not None else ""
        lines.append(f"PR {pr:g} %: {label_of}{d_of} ÷ {label_to}{d_to} ({metric})")
        lines.append("")
        lines.append(f"| seed | {label_of}{d_of} | {label_to}{d_to} | ratio |")
        lines.append("|---|---|---|---|")
        ratios = []
        for seed, a, b in rows:
            ratio = a / b if b else float("nan")
            ratios.append(ratio)
            lines.append(f"| {seed} | {a:.2f} | {b:.2f} | {ratio:.3f} |")
        finite = [r for r in ratios if math.isfinite(r)]
        if finite:
            low = sum(1 for r in finite if r < below)
            lines.append(f"| mean of {len(finite)} | | | {sum(finite) / len(finite):.3f} |")
            lines.append(f"| worst seed | | | {min(finite):.3f} |")
            lines.append(f"| seeds below {below:g} | | | {low} of {len(finite)} |")
        lines.append("")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", nargs="+")
    parser.add_argument("--of", required=True, help="ARM or ARM@DEMAND")
    parser.add_argument("--to", required=True, help="ARM or ARM@DEMAND")
    parser.add_argument("--metric", default="efficiency_all_mps")
    parser.add_argument("--below", type=float, default=0.95)
    a = parser.parse_args(argv)
    if not math.isfinite(a.below) or a.below <= 0:
        raise SystemExit(f"seed_ratio: --below must be > 0, got {a.below}")
    of, to = side(a.of), side(a.to)
    paired = pairs(read_points(a.results, a.metric), of, to)
    if not paired:
        raise SystemExit(f"seed_ratio: no seed has both {a.of} and {a.to} at the same PR in {', '.join(a.results)}")
    print(table(of, to, paired, a.metric, a.below))
    return 0


if __name__ == "__main__":
    sys.exit(main())
