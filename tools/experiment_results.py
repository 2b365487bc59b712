"""Results of an experiment folder (see experiment.py): results.csv (one row per point),
the paper-shaped table per metric with mean +/- 95 % interval per (arm, PR) beside the
paper's published numbers (tables.md and table_<metric>.csv), and the figures."""
import csv
import json
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from palcas_stats import format_ci, mean_ci95  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAPER_RESULTS = ROOT / "config" / "paper_results.csv"
# The paper's five metrics (Table "Performance of PALCAS and Baselines" has four; comfort is
# its figure), then what a reader of this suite also needs.
METRICS = [
    ("efficiency_all_mps", "Efficiency, all vehicles (m/s)", 2),
    ("collision_rate_pct", "CR (%)", 2),
    ("dsr_pct", "DSR (%)", 1),
    ("msr_pct", "MSR (%)", 1),
    ("comfort_share_pct", "Comfort share, |a| <= 1.47 (%)", 1),
]
EXTRA = ["efficiency_cav_mps", "decision_ms_p99", "lane_changes_dropped", "collisions",
         "teleports", "cavs_seen", "exiting_cavs", "merging_cavs", "sim_seconds",
         "wall_seconds", "real_time_factor"]
ARM_TITLES = {"palcas": "PALCAS", "palcas_assist": "PALCAS (assist mode)", "centralized": "Baseline-1 (centralized)",
              "independent": "Baseline-2 (independent)", "no_priority": "no priority (ablation)",
              "keep": "keep", "sumo_native": "SUMO-native"}


def read_paper(path=PAPER_RESULTS):
    """{(arm, pr, metric): (mean, pm)} from the paper's tables."""
    out = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(line for line in f if not line.startswith("#")):
            out[(r["arm"], float(r["pr"]), r["metric"])] = (float(r["mean"]), float(r["pm"]))
    return out


def point_row(out, p, duration_s):
    d = out / "points" / p["name"]
    row = {"point": p["name"], "arm": p["arm"], "pr": p["pr"], "seed": p["seed"]}
    info = {}
    if (d / "point.json").exists():
        info = json.loads((d / "point.json").read_text())
    m = d / p["arm"] / "metrics.json"
    metrics = json.loads(m.read_text()) if m.exists() else None
    if info.get("status") == "failed":
        row["status"] = "failed"
    elif metrics is None:
        row["status"] = "missing"
    elif float(metrics.get("sim_seconds", 0.0)) < duration_s - 1e-6:
        row["status"] = "incomplete"  # interrupted: a partial episode is not a result
    else:
        row["status"] = "done"
    row["point_wall_s"] = info.get("wall_s", "")
    row["error"] = info.get("error", "")
    for key, _, _ in METRICS:
        row[key] = metrics.get(key, "") if metrics else ""
    for key in EXTRA:
        row[key] = metrics.get(key, "") if metrics else ""
    return row


def number(v):
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def aggregate(rows, arms, prs):
    """{(arm, pr, metric): (n, mean, half)} over the finished points."""
    agg = {}
    for arm in arms:
        for pr in prs:
            sel = [r for r in rows if r["arm"] == arm and r["pr"] == pr and r["status"] == "done"]
            for key, _, _ in METRICS:
                vals = [number(r[key]) for r in sel]
                vals = [v for v in vals if v is not None]
                if vals:
                    mean, half = mean_ci95(vals)
                    agg[(arm, pr, key)] = (len(vals), mean, half)
    return agg


def write_tables(out, settings, rows, agg, paper):
    arms, prs = settings["arms"], settings["prs"]
    md = [f"# Experiment results\n",
          f"Road `{settings['scenario']}`, {settings['duration_s']:g} s per point, evaluation seeds "
          f"{', '.join(str(s) for s in settings['seeds'])}; each cell: mean ± half-width of the "
          "two-sided 95 % Student-t interval over the seeds (n in the CSV). *paper*: the "
          "published value ± its printed spread (on the paper's own road and demand).\n"]
    bad = [r for r in rows if r["status"] != "done"]
    if bad:
        md.append("**Not in the tables** (" + str(len(bad)) + " point(s)): " +
                  ", ".join(f"{r['point']} ({r['status']})" for r in bad) + "\n")
    for key, label, digits in METRICS:
        md.append(f"\n## {label}\n")
        head = ["PR (%)"]
        for arm in arms:
            head.append(ARM_TITLES.get(arm, arm))
            if any((arm, pr, key) in paper for pr in prs):
                head.append(f"{ARM_TITLES.get(arm, arm)}, paper")
        md.append("| " + " | ".join(head) + " |")
        md.append("|" + "---|" * len(head))
        csv_rows = []
        for pr in prs:
            cells = [f"{pr:g}"]
            for arm in arms:
                if (arm, pr, key) in agg:
                    n, mean, half = agg[(arm, pr, key)]
                    cells.append(format_ci(mean, half, digits))
                else:
                    n, mean, half = 0, float("nan"), float("nan")
                    cells.append("n/a")
                pm = paper.get((arm, pr, key))
                if any((arm, p2, key) in paper for p2 in prs):
                    cells.append(f"*{pm[0]:.{digits}f} ± {pm[1]:.{digits}f}*" if pm else "")
                csv_rows.append([arm, f"{pr:g}", n, "" if math.isnan(mean) else round(mean, 4),
                                 "" if math.isnan(half) else round(half, 4),
                                 pm[0] if pm else "", pm[1] if pm else ""])
            md.append("| " + " | ".join(cells) + " |")
        with open(out / f"table_{key}.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["arm", "pr", "n", "mean", "ci95_half", "paper_mean", "paper_pm"])
            w.writerows(csv_rows)
    walls = {}
    for r in rows:
        if r["status"] == "done" and number(r["point_wall_s"]):
            walls.setdefault(r["arm"], []).append(number(r["point_wall_s"]))
    if walls:
        md.append("\n## Wall time per point kind\n")
        md.append("| arm | points | mean wall (s) | min | max |")
        md.append("|---|---|---|---|---|")
        for arm in arms:
            if arm in walls:
                w = walls[arm]
                md.append(f"| {arm} | {len(w)} | {sum(w) / len(w):.1f} | {min(w):.1f} | {max(w):.1f} |")
    (out / "tables.md").write_text("\n".join(md) + "\n")


def write_results_csv(out, rows):
    keys = list(rows[0].keys())
    with open(out / "results.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def draw_figures(out, settings):
    """The figures of the first seed at the highest PR (the paper's 60 %): one run folder
    per arm, gathered by symlinks so run_figures sees them side by side."""
    import run_figures
    pr = max(settings["prs"])
    seed = settings["seeds"][0]
    gather = out / "figures" / "runs"
    gather.mkdir(parents=True, exist_ok=True)
    for arm in settings["arms"]:
        src = out / "points" / f"{arm}_pr{pr:g}_s{seed}" / arm
        link = gather / arm
        if link.is_symlink() or link.exists():
            link.unlink()
        if (src / "trajectories.csv").exists():
            link.symlink_to(src)
    policies = {a: p for a, p in settings.get("policies", {}).items()}
    pngs = run_figures.figures_for_run(gather, out / "figures", policies=policies)
    (out / "figures" / "README.md").write_text(
        f"Figures of seed {seed} at PR {pr:g} % ({settings['duration_s']:g} s), drawn from the "
        "recorded trajectories.csv / decisions.csv of each arm's point (runs/ links to them) "
        "and the learning arms' training records. Each PNG has its CSV beside it.\n")
    return pngs


def collect(out, settings, points):
    out = pathlib.Path(out)
    rows = [point_row(out, p, settings["duration_s"]) for p in points]
    write_results_csv(out, rows)
    agg = aggregate(rows, settings["arms"], settings["prs"])
    write_tables(out, settings, rows, agg, read_paper())
    done = sum(r["status"] == "done" for r in rows)
    pngs = []
    if done:
        try:
            pngs = draw_figures(out, settings)
        except Exception as e:  # a figure must not lose the tables
            print(f"[experiment] figures failed: {e}", file=sys.stderr)
    print(f"[experiment] {done}/{len(rows)} points in the tables: {out / 'tables.md'}, "
          f"{out / 'results.csv'}; {len(pngs)} figures in {out / 'figures'}")
    return 0 if done == len(rows) else 1


def merge(out, csv_paths, seeds, duration_s, scenario):
    """Tables from the results.csv of several experiments on the same road, seeds and
    duration (e.g. arms run in different sessions): rows are taken as they are, a point
    present twice is an error. Figures stay with each experiment (they need its runs)."""
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows, seen, arms, prs = [], set(), [], []
    for path in csv_paths:
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                if r["point"] in seen:
                    raise ValueError(f"{path}: point {r['point']} is already in another results.csv")
                seen.add(r["point"])
                r["pr"] = float(r["pr"])
                if int(r["seed"]) not in seeds:
                    raise ValueError(f"{path}: point {r['point']} has seed {r['seed']}, not one of {seeds}")
                rows.append(r)
                if r["arm"] not in arms:
                    arms.append(r["arm"])
                if r["pr"] not in prs:
                    prs.append(r["pr"])
    settings = {"arms": arms, "prs": sorted(prs), "seeds": seeds, "duration_s": duration_s,
                "scenario": scenario}
    write_results_csv(out, rows)
    write_tables(out, settings, rows, aggregate(rows, arms, settings["prs"]), read_paper())
    return rows


if __name__ == "__main__":
    import argparse
    parser = argparse.ArgumentParser(description="merge the results.csv of experiments run "
                                     "apart (same road, seeds, duration) into one set of tables")
    parser.add_argument("command", choices=["merge"])
    parser.add_argument("--out", required=True)
    parser.add_argument("--seeds", default="101,102,103")
    parser.add_argument("--duration", type=float, default=1800.0)
    parser.add_argument("--scenario", default="paper")
    parser.add_argument("results", nargs="+")
    a = parser.parse_args()
    try:
        merged = merge(a.out, a.results, [int(s) for s in a.seeds.split(",")], a.duration, a.scenario)
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"experiment_results merge: {e}")
    print(f"[experiment] {len(merged)} points merged: {pathlib.Path(a.out) / 'tables.md'}")
