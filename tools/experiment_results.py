"""Results of an experiment folder (see experiment.py): results.csv (one row per point),
the paper-shaped table per metric with mean +/- 95 % interval per (arm, PR), one table per
demand, beside the paper's published numbers (tables.md and table_<metric>.csv), and the
figures (with --demands: capacity.png, speed and throughput against demand).

A mean can hide a jam: every speed and DSR cell also shows its worst seed, and a point whose
mean speed is below JAM_SHARE x SUMO-native's on the same seed, PR and demand is a jam:
marked JAM in its cell, listed at the top of tables.md, "yes" in results.csv's jam column."""
import csv
import json
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from palcas_arms import title  # noqa: E402
from palcas_stats import format_ci, mean_ci95  # noqa: E402
import repo_paths  # noqa: E402

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
    ("throughput_vph", "Throughput, vehicles arrived (veh/h)", 0),
]
# Cells that show their worst seed beside the mean (the lowest value is the worst).
WORST_OF = ("efficiency_all_mps", "dsr_pct")
SPEED = "efficiency_all_mps"
JAM_SHARE = 0.5  # a point below this share of SUMO-native's speed on the same traffic jammed
REFERENCE_ARM = "sumo_native"
# Further columns of results.csv, straight from each point's metrics.json (a key the run's
# bridge did not write yet: an empty cell). The raw counts are here so rates can be pooled
# over seeds (e.g. CR = sum cav_collisions / sum cavs_seen; tools/trial_results.py).
EXTRA = ["efficiency_cav_mps", "insertion_dropped", "mean_travel_time_s", "lane_changes_per_cav",
         "decision_ms_p99", "lane_changes_dropped", "collisions",
         "teleports", "cavs_seen", "exiting_cavs", "merging_cavs", "sim_seconds",
         "wall_seconds", "real_time_factor",
         # the trial's columns: speed after the road filled, who never got on, time spent,
         # exit/merge success with the CAVs still on the road at the end counted as not served
         "efficiency_steady_mps", "insertion_waiting_end", "unserved_vehicles",
         "total_time_spent_veh_h", "exiting_cavs_censored", "dsr_censored_pct",
         "merging_cavs_censored", "msr_censored_pct", "cav_collisions", "exits_ok", "arrived"]


def read_paper(path=PAPER_RESULTS):
    """{(arm, pr, metric): (mean, pm)} from the paper's tables."""
    out = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(line for line in f if not line.startswith("#")):
            out[(r["arm"], float(r["pr"]), r["metric"])] = (float(r["mean"]), float(r["pm"]))
    return out


def scenario_demand(scenario):
    """mainline_flow_vphpl of config/scenarios/<scenario>/scenario.yaml (None when unknown)."""
    import yaml
    f = ROOT / "config" / "scenarios" / scenario / "scenario.yaml"
    try:
        return float(yaml.safe_load(f.read_text())["mainline_flow_vphpl"])
    except (OSError, KeyError, TypeError, ValueError):
        return None


def point_row(out, p, duration_s, own_demand=None):
    """A row of results.csv; `demand` is the point's, else the scenario's own (own_demand)."""
    d = out / "points" / p["name"]
    demand = p.get("demand")
    row = {"point": p["name"], "arm": p["arm"], "pr": p["pr"],
           "demand": demand if demand is not None else own_demand, "seed": p["seed"]}
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


def same_traffic(r):
    """What makes two points the same traffic: seed, PR and demand."""
    return (str(r["seed"]), number(r["pr"]), number(r.get("demand")))


def mark_jams(rows):
    """Sets each row's "jam": "yes" when its speed is below JAM_SHARE x SUMO-native's on
    the same seed, PR and demand, "no" when not, "" when there is nothing to compare with
    (no finished SUMO-native point of that traffic, or not finished itself)."""
    native = {same_traffic(r): number(r[SPEED]) for r in rows
              if r["arm"] == REFERENCE_ARM and r["status"] == "done"}
    for r in rows:
        ref, speed = native.get(same_traffic(r)), number(r[SPEED])
        if r["status"] != "done" or ref is None or speed is None:
            r["jam"] = ""
        else:
            r["jam"] = "yes" if speed < JAM_SHARE * ref else "no"
    return rows


def values_of(rows, key):
    return [number(r[key]) for r in rows if r["status"] == "done" and number(r[key]) is not None]


def aggregate(rows, arms, prs, demands):
    """{(arm, pr, demand, metric): cell} over the finished points; a cell is a dict with n,
    mean, half, worst and worst_seed (lowest value, for WORST_OF) and jams (seeds that jammed)."""
    agg = {}
    for arm in arms:
        for pr in prs:
            for demand in demands:
                sel = [r for r in rows if r["arm"] == arm and number(r["pr"]) == pr
                       and number(r.get("demand")) == demand and r["status"] == "done"]
                jams = sorted(str(r["seed"]) for r in sel if r.get("jam") == "yes")
                for key, _, _ in METRICS:
                    vals = [(number(r.get(key)), r["seed"]) for r in sel if number(r.get(key)) is not None]
                    if not vals:
                        continue
                    mean, half = mean_ci95([v for v, _ in vals])
                    worst, worst_seed = min(vals, key=lambda x: x[0])
                    agg[(arm, pr, demand, key)] = {"n": len(vals), "mean": mean, "half": half,
                                                   "worst": worst, "worst_seed": worst_seed,
                                                   "jams": jams}
    return agg


def demands_of(rows):
    out = []
    for r in rows:
        d = number(r.get("demand"))
        if d not in out:
            out.append(d)
    return sorted(out, key=lambda d: (d is None, d or 0.0))


def cell_text(c, key, digits):
    text = format_ci(c["mean"], c["half"], digits)
    if key in WORST_OF and c["n"] > 1:
        text += f" (worst {c['worst']:.{digits}f}, s{c['worst_seed']})"
    if c["jams"]:
        text += " **JAM** (s" + ", s".join(c["jams"]) + ")"
    return text


def demand_title(demand):
    return "demand: the scenario's own" if demand is None else f"demand {demand:g} veh/h/lane"


def write_tables(out, settings, rows, agg, paper):
    arms, prs = settings["arms"], settings["prs"]
    demands = demands_of(rows) or [None]
    md = [f"# Experiment results\n",
          f"Road `{settings['scenario']}`, {settings['duration_s']:g} s per point, evaluation seeds "
          f"{', '.join(str(s) for s in settings['seeds'])}, "
          + ", ".join(demand_title(d) for d in demands) + "; each cell: mean ± half-width of the "
          "two-sided 95 % Student-t interval over the seeds (n in the CSV); speed and DSR cells "
          "also give their worst seed. *paper*: the published value ± its printed spread (on the "
          f"paper's own road and demand). **JAM**: a seed whose speed was below {JAM_SHARE:g} x "
          "SUMO-native's on the same seed, PR and demand.\n"]
    bad = [r for r in rows if r["status"] != "done"]
    if bad:
        md.append("**Not in the tables** (" + str(len(bad)) + " point(s)): " +
                  ", ".join(f"{r['point']} ({r['status']})" for r in bad) + "\n")
    jammed = [r for r in rows if r.get("jam") == "yes"]
    if jammed:
        md.append(f"**JAM** ({len(jammed)} point(s) below {JAM_SHARE:g} x SUMO-native's speed on the same "
                  "traffic): " + ", ".join(f"{r['point']} ({number(r[SPEED]):.2f} m/s)" for r in jammed) + "\n")
    elif not any(r["arm"] == REFERENCE_ARM for r in rows):
        md.append(f"Jams not checked: no {REFERENCE_ARM} arm to compare with.\n")
    for key, label, digits in METRICS:
        md.append(f"\n## {label}\n")
        has_paper = [arm for arm in arms if any((arm, pr, key) in paper for pr in prs)]
        csv_rows = []
        for demand in demands:
            if len(demands) > 1 or demand is not None:
                md.append(f"\n### {demand_title(demand)}\n")
            head = ["PR (%)"]
            for arm in arms:
                head.append(title(arm))
                if arm in has_paper:
                    head.append(f"{title(arm)}, paper")
            md.append("| " + " | ".join(head) + " |")
            md.append("|" + "---|" * len(head))
            for pr in prs:
                cells = [f"{pr:g}"]
                for arm in arms:
                    c = agg.get((arm, pr, demand, key))
                    cells.append(cell_text(c, key, digits) if c else "n/a")
                    pm = paper.get((arm, pr, key))
                    if arm in has_paper:
                        cells.append(f"*{pm[0]:.{digits}f} ± {pm[1]:.{digits}f}*" if pm else "")
                    c = c or {"n": 0, "mean": float("nan"), "half": float("nan"), "worst": None,
                              "worst_seed": "", "jams": []}
                    csv_rows.append([arm, f"{pr:g}", "" if demand is None else f"{demand:g}", c["n"],
                                     "" if math.isnan(c["mean"]) else round(c["mean"], 4),
                                     "" if math.isnan(c["half"]) else round(c["half"], 4),
                                     "" if c["worst"] is None else round(c["worst"], 4), c["worst_seed"],
                                     " ".join(c["jams"]), pm[0] if pm else "", pm[1] if pm else ""])
                md.append("| " + " | ".join(cells) + " |")
        with open(out / f"table_{key}.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["arm", "pr", "demand", "n", "mean", "ci95_half", "worst", "worst_seed", "jam_seeds",
                        "paper_mean", "paper_pm"])
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


def draw_capacity(out, arms, prs, rows):
    """figures/capacity.png (+ .csv): mean speed and throughput against demand, a line per
    arm, 95 % intervals over the seeds as error bars; one row of panels per PR."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    demands = [d for d in demands_of(rows) if d is not None]
    table = []
    fig, axes = plt.subplots(len(prs), 2, figsize=(11, 3.6 * len(prs)), squeeze=False)
    for i, pr in enumerate(prs):
        for j, (key, label) in enumerate(((SPEED, "mean speed, all vehicles (m/s)"),
                                          ("throughput_vph", "throughput (veh/h arrived)"))):
            ax = axes[i][j]
            for arm in arms:
                xs, ys, hs = [], [], []
                for demand in demands:
                    sel = [r for r in rows if r["arm"] == arm and number(r["pr"]) == pr
                           and number(r.get("demand")) == demand]
                    vals = values_of(sel, key)
                    if not vals:
                        continue
                    mean, half = mean_ci95(vals)
                    xs.append(demand)
                    ys.append(mean)
                    hs.append(half if math.isfinite(half) else 0.0)
                    table.append([arm, f"{pr:g}", f"{demand:g}", key, len(vals), round(mean, 4),
                                  round(half, 4) if math.isfinite(half) else ""])
                if xs:
                    # One colour per arm in every panel (a panel without some arm would
                    # otherwise shift the others' colours).
                    ax.errorbar(xs, ys, yerr=hs, marker="o", capsize=3, label=title(arm),
                                color="C%d" % (arms.index(arm) % 10))
            ax.set_xlabel("mainline demand (veh/h per lane)")
            ax.set_ylabel(label)
            ax.set_title(f"PR {pr:g} %")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
    fig.suptitle("Capacity: mean and 95 % interval over seeds")
    fig.tight_layout()
    (out / "figures").mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "figures" / "capacity.png", dpi=110)
    plt.close(fig)
    with open(out / "figures" / "capacity.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["arm", "pr", "demand", "metric", "n", "mean", "ci95_half"])
        w.writerows(table)
    return str(out / "figures" / "capacity.png")


def draw_figures(out, settings, points):
    """The figures of the first seed at the highest PR (the paper's 60 %) and the first
    demand: one run folder per arm, gathered by symlinks so run_figures sees them side by
    side."""
    import run_figures
    pr = max(settings["prs"])
    seed = settings["seeds"][0]
    demand = (settings.get("demands") or [None])[0]
    gather = out / "figures" / "runs"
    gather.mkdir(parents=True, exist_ok=True)
    for p in points:
        if p["pr"] != pr or p["seed"] != seed or p.get("demand") != demand:
            continue
        src = out / "points" / p["name"] / p["arm"]
        link = gather / p["arm"]
        if link.is_symlink() or link.exists():
            link.unlink()
        if (src / "trajectories.csv").exists():
            link.symlink_to(src)
    policies = {a: repo_paths.usable(p) for a, p in settings.get("policies", {}).items()}
    pngs = run_figures.figures_for_run(gather, out / "figures", policies=policies)
    at = "" if demand is None else f", demand {demand:g} veh/h/lane"
    (out / "figures" / "README.md").write_text(
        f"Figures of seed {seed} at PR {pr:g} %{at} ({settings['duration_s']:g} s), drawn from the "
        "recorded trajectories.csv / decisions.csv of each arm's point (runs/ links to them) "
        "and the learning arms' training records. Each PNG has its CSV beside it."
        + (" capacity.png: speed and throughput against demand, every seed." if settings.get("demands") else "")
        + "\n")
    return pngs


def collect(out, settings, points):
    out = pathlib.Path(out)
    own = scenario_demand(settings["scenario"])
    rows = mark_jams([point_row(out, p, settings["duration_s"], own) for p in points])
    write_results_csv(out, rows)
    agg = aggregate(rows, settings["arms"], settings["prs"], demands_of(rows))
    write_tables(out, settings, rows, agg, read_paper())
    done = sum(r["status"] == "done" for r in rows)
    pngs = []
    if done:
        try:
            pngs = draw_figures(out, settings, points)
        except Exception as e:  # a figure must not lose the tables
            print(f"[experiment] figures failed: {e}", file=sys.stderr)
        if settings.get("demands"):
            try:
                pngs.append(draw_capacity(out, settings["arms"], settings["prs"], rows))
            except Exception as e:
                print(f"[experiment] capacity figure failed: {e}", file=sys.stderr)
    print(f"[experiment] {done}/{len(rows)} points in the tables: {out / 'tables.md'}, "
          f"{out / 'results.csv'}; {len(pngs)} figures in {out / 'figures'}")
    return 0 if done == len(rows) else 1


def merge(out, csv_paths, seeds, duration_s, scenario):
    """Tables from the results.csv of several experiments on the same road, seeds and
    duration (e.g. arms run in different sessions): rows are taken as they are, a point
    present twice is an error. Figures stay with each experiment (they need its runs), except
    the capacity figure, drawn from the rows when they hold more than one demand: it puts
    arms evaluated apart side by side."""
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
                if not r.get("demand"):  # a results.csv from before the demand column
                    r["demand"] = scenario_demand(scenario)
                if int(r["seed"]) not in seeds:
                    raise ValueError(f"{path}: point {r['point']} has seed {r['seed']}, not one of {seeds}")
                rows.append(r)
                if r["arm"] not in arms:
                    arms.append(r["arm"])
                if r["pr"] not in prs:
                    prs.append(r["pr"])
    settings = {"arms": arms, "prs": sorted(prs), "seeds": seeds, "duration_s": duration_s,
                "scenario": scenario}
    rows = mark_jams(rows)
    write_results_csv(out, rows)
    write_tables(out, settings, rows, aggregate(rows, arms, settings["prs"], demands_of(rows)), read_paper())
    if len([d for d in demands_of(rows) if d is not None]) > 1:
        draw_capacity(out, arms, settings["prs"], rows)
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
