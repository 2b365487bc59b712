#!/usr/bin/env python3
"""Which zone's exits a policy serves: each off-ramp's exit-bound CAVs and the share served,
per arm, penetration rate and demand, pooled over the seeds with the worst seed beside it.

  /usr/bin/python3 tools/exit_check.py DIR [DIR ...] [--arm NAME] [--min-served-pct P] [--csv FILE]

DIR: an experiment's output (its points/), a ./palcas run folder, or one arm's folder; every
metrics.json below it is read (a training's top-level metrics.json, a copy of its last
episode's, is skipped for its episode_<k>/ ones). The episode's DSR pools the exits, so one
RSU letting its zone's exit-bound CAVs pass while the others serve theirs hides in it (the
case that led here: docs/journal/experiments.md). Served share counts the CAVs still before
their exit at the end as not served, like dsr_censored_pct.

--min-served-pct P: exit status 1, naming them, when an exit's pooled share in any cell is
below P (the check before a training is counted or shipped: policies/palcas/TRAINING.md)."""
import argparse
import collections
import csv
import json
import math
import pathlib
import sys

FIELDS = ("served", "missed", "lost", "censored")


class ExitCheckError(Exception):
    pass


def metrics_files(root):
    root = pathlib.Path(root)
    if not root.exists():
        raise ExitCheckError(f"{root}: no such folder")
    files = [root / "metrics.json"] if (root / "metrics.json").is_file() else []
    files += sorted(root.rglob("*/metrics.json"))
    # An experiment's figures/runs/<arm>/ holds a copy of one point's run for its figures.
    if (root / "points").is_dir():
        files = [f for f in files if f.relative_to(root).parts[0] != "figures"]
    # A training folder's own metrics.json repeats its last episode_<k>/metrics.json.
    return [f for f in files if not any(f.parent.glob("episode_*/metrics.json"))]


def read_run(path):
    """(arm, pr, demand, seed, [per-exit counts]) of one metrics.json."""
    try:
        m = json.loads(pathlib.Path(path).read_text())
    except (OSError, ValueError) as e:
        raise ExitCheckError(f"{path}: not readable as JSON ({e})")
    if not isinstance(m, dict) or "dsr_censored_pct" not in m:
        raise ExitCheckError(f"{path}: not a PALCAS run's metrics.json (no dsr_censored_pct)")
    exits = m.get("exits_by_cluster")
    if exits is None:
        raise ExitCheckError(f"{path}: no exits_by_cluster (written before runs tallied each exit; "
                             "run the point again)")
    try:
        counts = [{k: int(e[k]) for k in FIELDS} for e in exits]
    except (KeyError, TypeError, ValueError) as e:
        raise ExitCheckError(f"{path}: exits_by_cluster malformed ({e!r})")
    arm = pathlib.Path(path).parent.name
    if arm.startswith("episode_"):
        arm = pathlib.Path(path).parent.parent.name + "/" + arm
    return arm, m.get("pr_percent"), m.get("mainline_flow_vphpl"), m.get("seed"), counts


def served_pct(c):
    bound = sum(c[k] for k in FIELDS)
    return 100.0 * c["served"] / bound if bound else math.nan


def check(dirs, arm=None):
    """[(arm, pr, demand, exit, seeds, pooled counts, pooled %, worst seed %, worst seed)]."""
    cells = collections.defaultdict(list)
    for d in dirs:
        for f in metrics_files(d):
            run = read_run(f)
            if arm is None or run[0] == arm:
                cells[run[:3]].append(run[3:])
    if not cells:
        raise ExitCheckError("no metrics.json" + (f" of arm {arm}" if arm else "") +
                             " under " + ", ".join(map(str, dirs)))
    rows = []
    for (a, pr, demand), runs in sorted(cells.items(), key=lambda kv: tuple(map(str, kv[0]))):
        n_exits = max(len(c) for _, c in runs)
        for k in range(n_exits):
            pooled = {f: sum(c[k][f] for _, c in runs if k < len(c)) for f in FIELDS}
            if sum(pooled.values()) == 0:
                continue  # a cluster without an off-ramp
            per_seed = [(served_pct(c[k]), seed) for seed, c in runs
                        if k < len(c) and not math.isnan(served_pct(c[k]))]
            worst = min(per_seed)
            rows.append((a, pr, demand, k, len(runs), pooled, served_pct(pooled), worst[0], worst[1]))
    return rows


def fmt(v):
    return "—" if v is None else f"{v:g}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dirs", nargs="+", help="experiment, run or arm folders")
    ap.add_argument("--arm", help="only this arm's runs")
    ap.add_argument("--min-served-pct", type=float,
                    help="fail when an exit's pooled served share in a cell is below this")
    ap.add_argument("--csv", help="also write the table here")
    a = ap.parse_args(argv)
    if a.min_served_pct is not None and not 0.0 <= a.min_served_pct <= 100.0:
        ap.error(f"--min-served-pct {a.min_served_pct} is not a percentage in 0..100")
    try:
        rows = check(a.dirs, a.arm)
    except ExitCheckError as e:
        print(f"exit_check: {e}", file=sys.stderr)
        return 2
    header = ("arm", "pr", "demand", "exit", "runs", "exit_bound", "served", "missed", "lost",
              "censored", "served_pct", "worst_seed_pct", "worst_seed")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    table = []
    for arm, pr, demand, k, n, c, pct, worst, seed in rows:
        line = (arm, fmt(pr), fmt(demand), k, n, sum(c.values()), c["served"], c["missed"],
                c["lost"], c["censored"], f"{pct:.1f}", f"{worst:.1f}", fmt(seed))
        table.append(line)
        print("| " + " | ".join(map(str, line)) + " |")
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            w.writerows(table)
    if a.min_served_pct is not None:
        low = [r for r in rows if r[6] < a.min_served_pct]
        for arm, pr, demand, k, _, _, pct, _, _ in low:
            print(f"exit_check: {arm}, PR {fmt(pr)} %, {fmt(demand)} veh/h/lane: exit {k} served "
                  f"{pct:.1f} %, below {a.min_served_pct:g} %", file=sys.stderr)
        if low:
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
