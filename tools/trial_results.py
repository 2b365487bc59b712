#!/usr/bin/env python3
"""The fair trial's results page: docs/RESULTS.md and its figures and CSVs under
docs/results/, regenerated from the committed trial results.

  /usr/bin/python3 tools/trial_results.py docs/trial            write docs/RESULTS.md, docs/results/
  /usr/bin/python3 tools/trial_results.py docs/trial --check    regenerate in memory; exit 1 naming
                                                                 the first difference from the committed page
  ... --out DIR      the page as DIR/RESULTS.md, figures and CSVs in DIR/results/ (default docs)

Input: a folder holding one or more results.csv files of ./palcas experiment (FOLDER/*.csv
and FOLDER/*/results.csv, merged; a point in two files is an error) and optionally
FOLDER/trial.json naming the settings (the keys of an experiment.json: arms, prs, demands,
seeds, seed_set, duration_s, scenario, bridge_params, policies; and note, date, git_commit,
printed as they are; seeds_by_demand, {"1400": [seeds], ...}, for a part run with fewer seeds
than the trial's list). Sections of their own, each from its key: federation {reference, arms}
(the same training budget, another scheme; reference_what describes the reference), variants
{arm: {base, what, ships, replaced_as, own_control}} (a learned arm's policy run another way; with ships
true, the way the base arm's shipped policy now runs, which the targets and the federation table
read in place of the base's own rows; the federation table keeps those under replaced_as;
own_control {arm, what} or a list of them: the rows of the variant's hand-made mechanisms without
its network, each a control of that variant, paired with it and with the best control),
trainings {reference, arms: {arm: {seed, what}}, alternatives: {name: {what, arms, against}},
configuration} (the shipped configuration trained from other seeds, or the one `configuration`
names; another configuration trained from several seeds, compared training by training with
the shipped one, or with the alternative `against` names),
targets {key: value} (the learned advice's targets over TARGET_DEFAULTS), approaches [{for,
approach, seeds, outcome, journal}] (what was tried where a target is missed, quoted from the
journal entry it names). Without trial.json the grid is what the rows hold.

The page: what was run (failed and missing points named); each arm's mechanisms (the
registry config/arms.json and the bridge parameters it runs under: config/bridge.yaml, then
the arm's shipped policies/<arm>/bridge.yaml or its registry bridge_params, then the trial's
bridge_params); per cell (demand, PR) every arm's mean over seeds with its 95 % Student-t
interval and its worst seed, CR pooled over the seeds with its exact (Clopper-Pearson)
interval; each learned arm (advice "network") paired with each control on the seeds both have
(mean difference, paired bootstrap and paired-t 95 % intervals, worst seed), the best control
(highest mean speed) first; a reading in plain words generated from those intervals; two
figures. Deterministic: bootstrap generators seeded by what they compare, stable orders, no
clock. --check compares the page and every CSV exactly, and that every figure exists (a
figure's numbers are its CSV; its pixels depend on the matplotlib version)."""
import argparse
import csv
import io
import json
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import palcas_stats  # noqa: E402
import seed_sets  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
REGISTRY = ROOT / "config" / "arms.json"
BRIDGE_DEFAULTS = ROOT / "config" / "bridge.yaml"
RESAMPLES = 10000
MINUS = "\u2212"

# (key, label, decimals, better): the per-cell table's metrics. better: "higher", "lower" or
# "neutral" (lane changes: more is more weaving, not a loss by itself). The worst seed is the
# lowest value of a "higher" metric, the highest of the others. dsr / msr: the censored rates
# (exit- or merge-bound CAVs still on the road at the end count as not served), else the
# uncensored dsr_pct / msr_pct of a bridge from before them (marked).
METRICS = [
    ("efficiency_all_mps", "Mean speed, all vehicles (m/s)", 2, "higher"),
    ("efficiency_steady_mps", "Steady-state speed (m/s)", 2, "higher"),
    ("throughput_vph", "Throughput (veh/h)", 0, "higher"),
    ("unserved_vehicles", "Unserved vehicles", 1, "lower"),
    ("total_time_spent_veh_h", "Total time spent (veh·h)", 1, "lower"),
    ("dsr", "DSR (%)", 1, "higher"),
    ("msr", "MSR (%)", 1, "higher"),
    ("lane_changes_per_cav", "Lane changes per CAV", 2, "neutral"),
    ("comfort_share_pct", "Comfort share (%)", 1, "higher"),
]
CENSORED = {"dsr": ("dsr_censored_pct", "dsr_pct"), "msr": ("msr_censored_pct", "msr_pct")}
# The paired comparisons' metrics (speed also as a ratio).
PAIRED = ["efficiency_all_mps", "throughput_vph", "unserved_vehicles", "total_time_spent_veh_h",
          "dsr", "comfort_share_pct", "lane_changes_per_cav"]
SHORT = {"efficiency_all_mps": "speed", "efficiency_steady_mps": "steady speed", "throughput_vph": "throughput",
         "unserved_vehicles": "unserved", "total_time_spent_veh_h": "total time spent", "dsr": "DSR",
         "msr": "MSR", "lane_changes_per_cav": "lane changes per CAV", "comfort_share_pct": "comfort"}
UNIT = {"efficiency_all_mps": " m/s", "throughput_vph": " veh/h", "unserved_vehicles": " veh",
        "total_time_spent_veh_h": " veh·h", "dsr": " points", "msr": " points", "comfort_share_pct": " points",
        "lane_changes_per_cav": ""}
SPEED = "efficiency_all_mps"
GUARD_KEYS = ("guard_busy_handback", "guard_busy_lc_assertive", "guard_busy_change_max_accel_mps2",
              "lane_change_max_accel_mps2")


class TrialError(Exception):
    pass


# --- reading -------------------------------------------------------------------------------

from experiment_results import number  # noqa: E402  (a finite float, or None)


def shown_path(path):
    """A path as the page names it: repository-relative when inside the repository."""
    path = pathlib.Path(path).resolve()
    try:
        return str(path.relative_to(ROOT))
    except ValueError:
        return str(path)


def input_files(folder, out_dir=None):
    folder = pathlib.Path(folder)
    files = sorted(folder.glob("*.csv")) + sorted(folder.glob("*/results.csv"))
    if out_dir is not None:
        # The page's own CSVs (OUT/results/) are outputs, never inputs; the default OUT (docs)
        # holds the input folder docs/trial itself.
        made = (pathlib.Path(out_dir) / "results").resolve()
        files = [f for f in files if made not in f.resolve().parents]
    return files


def read_trial(folder, out_dir=None):
    """(rows, files, settings): the merged rows (pr, demand, seed as numbers), the CSV files
    read, and trial.json ({} without one)."""
    folder = pathlib.Path(folder)
    if not folder.is_dir():
        raise TrialError(f"{folder}: no such folder")
    files = input_files(folder, out_dir)
    if not files:
        raise TrialError(f"{folder}: no results.csv (*.csv or */results.csv) in it")
    settings = {}
    if (folder / "trial.json").exists():
        try:
            settings = json.loads((folder / "trial.json").read_text())
        except ValueError as e:
            raise TrialError(f"{folder / 'trial.json'}: not JSON ({e})")
    rows, seen = [], {}
    for path in files:
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                for key in ("arm", "pr", "seed", "status"):
                    if not r.get(key):
                        raise TrialError(f"{shown_path(path)}: a row without {key} ({r.get('point', '?')})")
                r["pr"] = float(r["pr"])
                r["demand"] = number(r.get("demand"))
                r["seed"] = int(r["seed"])
                r["file"] = shown_path(path)
                key = (r["arm"], r["pr"], r["demand"], r["seed"])
                if key in seen:
                    raise TrialError(f"{shown_path(path)}: point {r.get('point', key)} is also in {seen[key]}")
                seen[key] = r["file"]
                rows.append(r)
    return rows, files, settings


def load_registry(path=REGISTRY):
    """config/arms.json as it is (its own checks are tools/palcas_arms.py's)."""
    return json.loads(pathlib.Path(path).read_text())


def advice_of(entry):
    """network | rules | none: the registry's advice field, else a learning arm (RSUs) is a network."""
    if entry is None:
        return "unknown"
    return entry.get("advice") or ("network" if entry.get("rsus", "none") != "none" else "none")


def sort_arms(arms, registry):
    order = list(registry)
    return sorted(set(arms), key=lambda a: (order.index(a) if a in registry else len(order), a))


def cells_of(rows):
    cells = sorted({(r["demand"], r["pr"]) for r in rows}, key=lambda c: (c[0] is None, c[0] or 0.0, c[1]))
    return cells


# How a cell without a demand (the scenario's own, e.g. the printed 3200 + 600) is named:
# trial.json's own_demand_title / own_demand_short, set by generate() for its page and figures.
OWN_DEMAND = {"title": "the scenario's own demand", "short": "own"}


def name_own_demand(settings):
    OWN_DEMAND["title"] = settings.get("own_demand_title") or "the scenario's own demand"
    OWN_DEMAND["short"] = settings.get("own_demand_short") or "own"


def cell_title(cell):
    demand, pr = cell
    d = OWN_DEMAND["title"] if demand is None else f"demand {demand:g} veh/h/lane"
    return f"{d}, PR {pr:g} %"


def cell_short(cell):
    demand, pr = cell
    return (OWN_DEMAND["short"] if demand is None else f"{demand:g}") + f" / PR {pr:g}"


def done_rows(rows, arm, cell):
    return [r for r in rows if r["arm"] == arm and (r["demand"], r["pr"]) == cell and r["status"] == "done"]


def column_for(metric, rows):
    """The column a metric is read from for these rows, and whether it is the fallback."""
    if metric not in CENSORED:
        return metric, False
    censored, plain = CENSORED[metric]
    if rows and all(number(r.get(censored)) is not None for r in rows):
        return censored, False
    return plain, True


# --- bridge parameters and the mechanism table ---------------------------------------------

def read_yaml(path):
    import yaml
    data = yaml.safe_load(pathlib.Path(path).read_text())
    return data if isinstance(data, dict) else {}


def resolve_file(name, *bases):
    p = pathlib.Path(name)
    if p.is_absolute():
        return p if p.exists() else None
    for base in bases:
        if (base / p).exists():
            return base / p
    return None


def bridge_params(arm, entry, settings):
    """(params, sources): the bridge parameters the arm ran under, as the launch layers them
    (config/bridge.yaml; the shipped policy's bridge.yaml, else the registry's bridge_params;
    the trial's bridge_params), and the files read, repository-relative."""
    params, sources = dict(read_yaml(BRIDGE_DEFAULTS)), []
    policy = (settings.get("policies") or {}).get(arm)
    policy_yaml = None
    if policy:
        d = resolve_file(policy, ROOT)
        policy_yaml = d / "bridge.yaml" if d and (d / "bridge.yaml").exists() else None
    elif entry.get("shipped_policy") and (ROOT / "policies" / arm / "bridge.yaml").exists():
        policy_yaml = ROOT / "policies" / arm / "bridge.yaml"
    if policy_yaml is None and entry.get("bridge_params"):
        policy_yaml = resolve_file(entry["bridge_params"], ROOT / "config", ROOT)
        if policy_yaml is None:
            raise TrialError(f"arm '{arm}': its registry bridge_params {entry['bridge_params']} is not under config/")
    for f in (policy_yaml, resolve_file(settings["bridge_params"], ROOT) if settings.get("bridge_params") else None):
        if f is not None:
            params.update(read_yaml(f))
            sources.append(shown_path(f))
    if settings.get("bridge_params") and len(sources) < 1 + (policy_yaml is not None):
        raise TrialError(f"trial.json: bridge_params {settings['bridge_params']} is not in the repository")
    return params, sources


def yes(flag):
    return "yes" if flag else "no"


def accel_text(v):
    v = number(v) or 0.0
    return f"{v:g} m/s²" if v > 0 else "off"


ADVICE_WORDS = {"network": "learned network", "rules": "rule", "none": "none", "unknown": "?"}
MECHANISM_HEAD = ["arm", "title", "RSUs", "advice", "federation", "I2I", "advisory control",
                  "assist mode", "busy-zone hand-back", "busy-zone gap acceptance",
                  "busy-zone change bound", "advised-change accel. bound", "bridge files over config/bridge.yaml"]


def mechanism_rows(arms, registry, settings):
    """One row of MECHANISM_HEAD per arm (registry order); the guard columns are '—' for an
    arm without advisory control (SUMO's own models: nothing of the bridge's guard applies)."""
    out = []
    for arm in sort_arms(arms, registry):
        entry = registry.get(arm)
        if entry is None:
            out.append([arm, "(not in config/arms.json)"] + ["?"] * (len(MECHANISM_HEAD) - 2))
            continue
        params, sources = bridge_params(arm, entry, settings)
        row = [arm, entry.get("title", arm), entry.get("rsus", "?"), ADVICE_WORDS[advice_of(entry)],
               yes(entry.get("federation")), yes(entry.get("i2i")), yes(entry.get("advisory_control")),
               yes(entry.get("assist_mode"))]
        if entry.get("advisory_control"):
            guard_on = params.get("guard_enabled", True) is not False  # false: no guard rule acts
            lc = (number(params.get("guard_busy_lc_assertive")) or 0.0) if guard_on else 0.0
            row += ["on" if guard_on and params.get("guard_busy_handback") else "off",
                    f"lcAssertive {lc:.1f}" if lc > 0 else "off",
                    accel_text(params.get("guard_busy_change_max_accel_mps2") if guard_on else 0.0),
                    accel_text(params.get("lane_change_max_accel_mps2"))]
        else:
            row += ["—"] * 4
        row.append(", ".join(sources) if sources else "none")
        out.append(row)
    return out


# --- statistics per cell and per pair ------------------------------------------------------

def summary(values_by_seed, better):
    """{n, mean, lo, hi, worst, worst_seed} of [(seed, value)] (seed order)."""
    vals = [v for _, v in values_by_seed]
    mean, lo, hi = palcas_stats.t_interval(vals)
    pick = min if better == "higher" else max
    worst_seed, worst = pick(values_by_seed, key=lambda sv: (sv[1], sv[0]) if pick is min else (sv[1], -sv[0]))
    return {"n": len(vals), "mean": mean, "lo": lo, "hi": hi, "worst": worst, "worst_seed": worst_seed}


def arm_cell(rows, arm, cell):
    """Every metric's summary for one arm in one cell, the pooled CR and decision p99."""
    sel = sorted(done_rows(rows, arm, cell), key=lambda r: r["seed"])
    out = {"n": len(sel), "seeds": [r["seed"] for r in sel], "metrics": {}}
    for key, _, _, better in METRICS:
        column, fallback = column_for(key, sel)
        vals = [(r["seed"], number(r.get(column))) for r in sel if number(r.get(column)) is not None]
        if vals:
            out["metrics"][key] = dict(summary(vals, better), column=column, fallback=fallback)
    decided = [(r["seed"], number(r.get("dsr_pct"))) for r in sel if number(r.get("dsr_pct")) is not None]
    if decided:
        out["dsr_decided"] = summary(decided, "higher")
    k = n = 0
    derived = False
    for r in sel:
        seen = number(r.get("cavs_seen"))
        hit = number(r.get("cav_collisions"))
        if hit is None and seen is not None and number(r.get("collision_rate_pct")) is not None:
            hit, derived = round(number(r["collision_rate_pct"]) * seen / 100.0), True
        if seen is None or hit is None:
            continue
        k, n = k + int(round(hit)), n + int(round(seen))
    if n > 0:
        lo, hi = palcas_stats.clopper_pearson(k, n)
        out["cr"] = {"k": k, "n": n, "pct": 100.0 * k / n, "lo": 100.0 * lo, "hi": 100.0 * hi, "derived": derived}
    p99 = [(r["seed"], number(r.get("decision_ms_p99"))) for r in sel if number(r.get("decision_ms_p99")) is not None]
    if p99:
        seed, worst = max(p99, key=lambda sv: (sv[1], -sv[0]))
        out["p99"] = {"max": worst, "seed": seed}
    return out


def pair(rows, learned, control, cell, metric, seeds=None):
    """(pairs, left_out): pairs [(seed, learned value, control value)] of the seeds where both
    arms finished with a value of the metric (dsr/msr: censored when both have it on every
    paired seed, else both uncensored), and left_out [(seed, reason)] for every other seed of
    the cell (or of `seeds`, the trial's list)."""
    by = {}
    for arm in (learned, control):
        by[arm] = {r["seed"]: r for r in rows if r["arm"] == arm and (r["demand"], r["pr"]) == cell}
    universe = sorted(set(seeds) if seeds else set(by[learned]) | set(by[control]))
    both_done = [s for s in universe if all(s in by[a] and by[a][s]["status"] == "done" for a in by)]
    column, fallback = column_for(metric, [by[a][s] for a in by for s in both_done])
    pairs, left_out = [], []
    for s in universe:
        why = []
        for arm in (learned, control):
            r = by[arm].get(s)
            if r is None:
                why.append(f"{arm}: no row")
            elif r["status"] != "done":
                why.append(f"{arm}: {r['status']}")
            elif number(r.get(column)) is None:
                why.append(f"{arm}: no {column}")
        if why:
            left_out.append((s, "; ".join(why)))
        else:
            pairs.append((s, number(by[learned][s][column]), number(by[control][s][column])))
    return pairs, left_out, column, fallback


def compare(rows, learned, control, cell, metric, seeds=None, ratio=False):
    """The paired comparison of one metric: mean difference (or mean per-seed ratio, as a
    percentage change, with ratio=True), its bootstrap and paired-t intervals, the worst seed."""
    pairs, left_out, column, fallback = pair(rows, learned, control, cell, metric, seeds)
    better = dict((k, b) for k, _, _, b in METRICS)[metric]
    if ratio:
        per = [(s, 100.0 * (a / b - 1.0)) for s, a, b in pairs if b]
        left_out += [(s, f"{control}: zero {column}") for s, a, b in pairs if not b]
    else:
        per = [(s, a - b) for s, a, b in pairs]
    out = {"learned": learned, "control": control, "cell": cell, "metric": metric, "ratio": ratio,
           "column": column, "fallback": fallback, "pairs": pairs, "per_seed": per,
           "left_out": sorted(left_out), "n": len(per), "better": better}
    if not per:
        return out
    d = [v for _, v in per]
    mean, t_lo, t_hi = palcas_stats.t_interval(d)
    b_lo, b_hi = palcas_stats.bootstrap_mean_ci(
        d, palcas_stats.stable_seed(cell[0], cell[1], learned, control, metric, ratio), RESAMPLES)
    worst = summary(per, better)
    worst_seed, worst = worst["worst_seed"], worst["worst"]
    out.update(mean=mean, t_lo=t_lo, t_hi=t_hi, b_lo=b_lo, b_hi=b_hi, worst=worst, worst_seed=worst_seed,
               learned_mean=sum(a for _, a, _ in pairs) / len(pairs),
               control_mean=sum(b for _, _, b in pairs) / len(pairs))
    return out


def verdict(c):
    """gain / loss / more / fewer / none, from the span of both intervals (the paired-t one
    and the bootstrap one): the whole span above 0 or below 0, else no difference shown."""
    if c["n"] < 2 or not math.isfinite(c["t_lo"]):
        return "none"
    lo, hi = min(c["t_lo"], c["b_lo"]), max(c["t_hi"], c["b_hi"])
    if lo > 0:
        side = "up"
    elif hi < 0:
        side = "down"
    else:
        return "none"
    if c["better"] == "neutral":
        return "more" if side == "up" else "fewer"
    good = (side == "up") == (c["better"] == "higher")
    return "gain" if good else "loss"


def span(c):
    return min(c["t_lo"], c["b_lo"]), max(c["t_hi"], c["b_hi"])


def trial_grid(rows, settings, registry):
    arms = sort_arms(settings.get("arms") or {r["arm"] for r in rows}, registry)
    seeds = sorted(settings.get("seeds") or {r["seed"] for r in rows})
    if settings.get("prs"):
        demands = settings.get("demands") or sorted({r["demand"] for r in rows}, key=lambda d: (d is None, d or 0))
        cells = sorted({(number(d) if d is not None else None, float(p)) for d in demands for p in settings["prs"]},
                       key=lambda c: (c[0] is None, c[0] or 0.0, c[1]))
    else:
        cells = cells_of(rows)
    return arms, seeds, cells


def seeds_for(settings, cell, seeds):
    """The seeds planned for `cell`: trial.json's seeds_by_demand for its demand (a part run
    with fewer seeds), else the trial's list."""
    by_demand = settings.get("seeds_by_demand") or {}
    d = cell[0]
    key = "scenario" if d is None else (str(int(d)) if float(d).is_integer() else str(d))
    return sorted(by_demand[key]) if key in by_demand else seeds


def in_grid(rows, settings, registry):
    """(rows in the trial's grid, rows outside it): trial.json's arms, seeds and cells when it
    names them."""
    arms, seeds, cells = trial_grid(rows, settings, registry)
    inside = [r for r in rows if r["arm"] in arms and r["seed"] in seeds and (r["demand"], r["pr"]) in cells]
    return inside, [r for r in rows if r not in inside]


def analyse(rows, settings, registry):
    """Everything the page shows, as numbers (rows outside the trial's grid left out)."""
    arms, seeds, cells = trial_grid(rows, settings, registry)
    rows = in_grid(rows, settings, registry)[0]
    present = sort_arms({r["arm"] for r in rows}, registry)
    learned = [a for a in present if advice_of(registry.get(a)) == "network"]
    controls = [a for a in present if advice_of(registry.get(a)) not in ("network", "unknown")]
    result = {"arms": present, "seeds": seeds, "cells": [], "learned": learned, "controls": controls}
    for cell in cells:
        per_arm = {a: arm_cell(rows, a, cell) for a in present}
        speeds = {a: per_arm[a]["metrics"][SPEED]["mean"] for a in controls if SPEED in per_arm[a]["metrics"]}
        best = max(speeds, key=lambda a: (speeds[a], -controls.index(a))) if speeds else None
        # Every learned arm against the best control first, then against the others.
        order = [(L, best) for L in learned if best] + [(L, C) for L in learned for C in controls if C != best]
        comparisons = []
        for L, C in order:
            if not (per_arm[L]["n"] and per_arm[C]["n"]):
                continue
            planned = seeds_for(settings, cell, seeds)
            comparisons.append({"learned": L, "control": C, "best": C == best,
                                "ratio": compare(rows, L, C, cell, SPEED, planned, ratio=True),
                                "metrics": [compare(rows, L, C, cell, m, planned) for m in PAIRED]})
        result["cells"].append({"cell": cell, "arms": per_arm, "best": best, "best_speed": speeds.get(best),
                                "comparisons": comparisons})
    return result


# --- formatting ----------------------------------------------------------------------------

def fmt(v, digits, signed=False):
    if v is None or not math.isfinite(v):
        return "n/a"
    text = f"{v:+.{digits}f}" if signed else f"{v:.{digits}f}"
    if float(text) == 0.0:  # no "-0.0" / "+0.0"
        text = f"{0.0:.{digits}f}"
    return text.replace("-", MINUS)


def fmt_bound(v, digits, signed=False):
    """An interval's bound: with up to 3 more decimals when it would print as 0 but is not,
    so that a bound's side of 0 (what the reading turns on) shows."""
    for d in range(digits, digits + 4):
        text = fmt(v, d, signed)
        if not math.isfinite(v) or v == 0.0 or float(text.replace(MINUS, "-")) != 0.0:
            return text
    return text


def interval(lo, hi, digits):
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return "n/a (one seed)"
    return f"[{fmt_bound(lo, digits)}, {fmt_bound(hi, digits)}]"


def digits_of(metric):
    return dict((k, d) for k, _, d, _ in METRICS)[metric]


def label_of(metric):
    return dict((k, l) for k, l, _, _ in METRICS)[metric]


def seed_list(seeds):
    return seed_sets.describe(sorted(seeds)) if seeds else "none"


def md_table(head, rows):
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return lines


def csv_text(head, rows):
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(head)
    for r in rows:
        w.writerow(["" if v is None else (f"{v + 0.0:.6g}" if isinstance(v, float) else v) for v in r])
    return buf.getvalue()


def what_was_run(rows, files, settings, folder, a):
    seeds = a["seeds"]
    name = settings.get("seed_set") or seed_sets.set_of(seeds)
    arms = sort_arms(settings.get("arms") or a["arms"], load_registry())
    durations = sorted({number(r.get("sim_seconds")) for r in rows if r["status"] == "done"} - {None})
    if settings.get("duration_s"):
        duration = f"{float(settings['duration_s']):g} s per point"
    elif len(durations) == 1:
        duration = f"{durations[0]:g} s per point (the rows' sim_seconds; no trial.json)"
    else:
        duration = "not recorded"
    demands = sorted({c[0] for c in (x["cell"] for x in a["cells"])}, key=lambda d: (d is None, d or 0))
    prs = sorted({c[1] for c in (x["cell"] for x in a["cells"])})
    lines = ["## What was run", ""]
    lines.append(f"- Input: {', '.join(f'`{shown_path(f)}`' for f in files)}"
                 + (f"; settings: `{shown_path(pathlib.Path(folder) / 'trial.json')}`" if settings else
                    " (no trial.json: the grid is what the rows hold)"))
    for key in ("note", "date", "git_commit"):
        if settings.get(key):
            lines.append(f"- {key.replace('_', ' ')}: {settings[key]}")
    lines.append(f"- Road: `{settings.get('scenario', 'not recorded')}`; duration: {duration}")
    lines.append("- Demands (veh/h per lane): " + ", ".join("the scenario's own" if d is None else f"{d:g}"
                                                           for d in demands))
    lines.append("- PRs (%): " + ", ".join(f"{p:g}" for p in prs))
    lines.append("- Arms: " + ", ".join(f"`{x}`" for x in arms))
    set_text = (f"set `{name}` of config/seeds.yaml" if name else "in no one set of config/seeds.yaml")
    if name == "dev":
        set_text += " (**development seeds: settings were chosen on them; not a held-out result**)"
    lines.append(f"- Seeds ({len(seeds)}, {set_text}): {', '.join(str(s) for s in seeds)}")
    if settings.get("bridge_params"):
        lines.append(f"- Every point under the bridge override `{settings['bridge_params']}`")
    for key, planned in sorted((settings.get("seeds_by_demand") or {}).items()):
        own = settings.get("own_demand_title") or "the scenario's own demand"
        at = own if key == "scenario" else f"{key} veh/h/lane"
        lines.append(f"- Seeds at {at}: {len(planned)} planned, {', '.join(str(x) for x in planned)}")
    expected = [(arm, c, s) for arm in arms for c in (x["cell"] for x in a["cells"])
                for s in seeds_for(settings, c, seeds)]
    have = {(r["arm"], (r["demand"], r["pr"]), r["seed"]): r for r in rows}
    done = sum(1 for k in expected if k in have and have[k]["status"] == "done")
    fed_arms = federation_arms(settings)
    extra = [r for r in in_grid(rows, settings, load_registry())[1] if r["arm"] not in extra_arms(settings)]
    per_cell = "their seeds" if settings.get("seeds_by_demand") else f"{len(seeds)} seeds"
    lines.append(f"- Points: {len(expected)} planned ({len(arms)} arms × {len(a['cells'])} cells × "
                 f"{per_cell}), {done} finished")
    bad = []
    for arm, cell, seed in expected:
        r = have.get((arm, cell, seed))
        if r is None:
            bad.append(f"`{arm}` {cell_short(cell)} s{seed}: missing (no row)")
        elif r["status"] != "done":
            err = (r.get("error") or "").strip()
            bad.append(f"`{arm}` {cell_short(cell)} s{seed}: {r['status']}" + (f" ({err})" if err else ""))
    lines.append("- Failed or missing points: " + ("none" if not bad else str(len(bad))))
    lines += [f"  - {b}" for b in bad]
    fed_rows = [r for r in federation_rows(rows, settings) if r["arm"] in fed_arms]
    if fed_rows:
        lines.append(f"- The federation table: {len(fed_rows)} rows of "
                     + ", ".join(f"`{x}`" for x in sort_arms({r['arm'] for r in fed_rows}, load_registry()))
                     + f" ({sum(1 for r in fed_rows if r['status'] == 'done')} finished), against "
                     f"`{federation_reference(settings)}`'s own points")
    var_rows = [r for r in rows if r["arm"] in variant_arms(settings)]
    if var_rows:
        lines.append(f"- Variants chosen on the development seeds: {len(var_rows)} rows of "
                     + ", ".join(f"`{x}`" for x in sorted({r['arm'] for r in var_rows}))
                     + f" ({sum(1 for r in var_rows if r['status'] == 'done')} finished)")
    own_rows = [r for r in rows if r["arm"] in own_control_arms(settings)]
    if own_rows:
        lines.append(f"- Variants' own controls (their hand-made mechanisms without the network): {len(own_rows)} rows of "
                     + ", ".join(f"`{x}`" for x in sorted({r['arm'] for r in own_rows}))
                     + f" ({sum(1 for r in own_rows if r['status'] == 'done')} finished)")
    tr_rows = [r for r in rows if r["arm"] in training_arms(settings) and r["arm"] != training_reference(settings)]
    if tr_rows:
        lines.append(f"- Trainings of the shipped configuration from other seeds: {len(tr_rows)} rows of "
                     + ", ".join(f"`{x}`" for x in sorted({r['arm'] for r in tr_rows}))
                     + f" ({sum(1 for r in tr_rows if r['status'] == 'done')} finished)")
    alt_only = alternative_arms(settings) - set(variant_arms(settings))
    alt_rows = [r for r in rows if r["arm"] in alt_only]
    if alt_rows:
        lines.append(f"- Trainings of other configurations: {len(alt_rows)} rows of "
                     + ", ".join(f"`{x}`" for x in sorted({r['arm'] for r in alt_rows}))
                     + f" ({sum(1 for r in alt_rows if r['status'] == 'done')} finished)")
    if extra:
        lines.append(f"- Rows outside the planned grid, not in the tables: "
                     + ", ".join(f"{r.get('point') or r['arm']}" for r in extra))
    return lines


def mechanism_section(a, registry, settings):
    lines = ["", "## The arms and their mechanisms", "",
             "From `config/arms.json` and the bridge parameters each arm runs under. *advisory "
             "control*: the CAVs carry out the advice and make no lane changes of their own outside "
             "busy zones; *assist mode*: the CAVs keep their own route-aware lane changing and advice "
             "comes on top. The four guard columns are the bridge's (`config/bridge.yaml`: "
             "`guard_busy_handback`, `guard_busy_lc_assertive`, `guard_busy_change_max_accel_mps2`, "
             "`lane_change_max_accel_mps2`; a later file overrides an earlier one) and act on every "
             "arm with advisory control; an arm without it (SUMO's own models) has none of them (—). "
             "Learned arms (advice from a network) are compared below with the others (the controls).", ""]
    lines += md_table(MECHANISM_HEAD, [[f"`{r[0]}`"] + r[1:] for r in mechanism_rows(a["arms"], registry, settings)])
    return lines


def cell_value_text(m, digits):
    text = f"{fmt(m['mean'], digits)} ± {fmt((m['hi'] - m['lo']) / 2.0, digits)}" if math.isfinite(m["lo"]) \
        else fmt(m["mean"], digits)
    text += f" (worst {fmt(m['worst'], digits)}, s{m['worst_seed']})"
    return text + (" †" if m.get("fallback") else "")


def per_cell_section(a):
    lines = ["", "## Each arm, per cell", "",
             "Mean over the finished seeds ± half-width of the two-sided 95 % Student-t interval, and "
             "the worst seed (the lowest value; for unserved vehicles, time spent and lane changes the "
             "highest). DSR and MSR count the exit- and merge-bound CAVs still on the road at the end "
             "as not served (`dsr_censored_pct`, `msr_censored_pct`); † marks the uncensored rate of a "
             "bridge from before them (`dsr_pct`, `msr_pct`). CR is pooled over the seeds (CAVs that "
             "collided ÷ CAVs seen) with its exact Clopper–Pearson 95 % interval; decision p99 is the "
             "largest over the seeds."]
    fell_back = False
    for x in a["cells"]:
        arms = [arm for arm in a["arms"] if x["arms"][arm]["n"]]
        lines += ["", f"### {cell_title(x['cell'])}", ""]
        if not arms:
            lines.append("No finished point.")
            continue
        body = [["seeds finished"] + [str(x["arms"][arm]["n"]) for arm in arms]]
        for key, label, digits, _ in METRICS:
            cells = []
            for arm in arms:
                m = x["arms"][arm]["metrics"].get(key)
                fell_back |= bool(m and m.get("fallback"))
                cells.append(cell_value_text(m, digits) if m else "n/a")
            body.append([label] + cells)
        cr = []
        for arm in arms:
            c = x["arms"][arm].get("cr")
            cr.append("n/a" if not c else f"{fmt(c['pct'], 3)} [{fmt(c['lo'], 3)}, {fmt(c['hi'], 3)}] "
                      f"({c['k']} of {c['n']} CAVs{', from collision_rate_pct' if c['derived'] else ''})")
        body.append(["CR, pooled (%)"] + cr)
        body.append(["Decision p99, max (ms)"] + [
            f"{fmt(x['arms'][arm]['p99']['max'], 1)} (s{x['arms'][arm]['p99']['seed']})" if "p99" in x["arms"][arm]
            else "—" for arm in arms])
        lines += md_table(["metric"] + [f"`{arm}`" for arm in arms], body)
    if fell_back:
        lines += ["", "† uncensored (`dsr_pct` / `msr_pct`): these runs' bridge did not yet write the censored rate."]
    return lines


def diff_text(c, digits):
    if c["n"] == 0:
        return ["0", "n/a", "n/a", "n/a", "n/a", "n/a", "n/a", "n/a"]
    unit = " %" if c["ratio"] else ""
    lo, hi = span(c) if math.isfinite(c["t_lo"]) else (float("nan"), float("nan"))
    return [str(c["n"]), fmt(c["learned_mean"], digits_of(c["metric"])), fmt(c["control_mean"], digits_of(c["metric"])),
            fmt(c["mean"], digits, signed=True) + unit, interval(c["b_lo"], c["b_hi"], digits),
            interval(c["t_lo"], c["t_hi"], digits), f"{fmt(c['worst'], digits, signed=True)}{unit} (s{c['worst_seed']})",
            WORDS[verdict(c)] if math.isfinite(lo) else "one seed: none shown"]


WORDS = {"gain": "a gain", "loss": "a loss", "none": "no difference shown", "more": "more", "fewer": "fewer"}
PAIR_HEAD = ["learned vs control", "metric", "seeds", "learned", "control", "mean difference",
             "bootstrap 95 %", "paired-t 95 %", "worst seed", "reading"]


def paired_section(a):
    lines = ["", "## Learned arms against the controls, paired by seed", "",
             f"Each learned arm (advice from a network: {', '.join(f'`{x}`' for x in a['learned']) or 'none here'}) "
             f"against each control ({', '.join(f'`{x}`' for x in a['controls']) or 'none here'}) on the seeds "
             "both finished: the mean of the per-seed differences (learned − control; speed also as the "
             f"per-seed ratio learned ÷ control − 1, in %), its paired bootstrap interval ({RESAMPLES} "
             "resamples of the seeds, percentile, seeded by the comparison's name) and its paired-t "
             "interval, and the seed least favourable to the learned arm. The best control of a cell is "
             "the control with the highest mean speed there; its rows come first. Reading: *a gain* or "
             "*a loss* when both intervals lie entirely on one side of 0, else *no difference shown* "
             "(for lane changes: *more* / *fewer*). A seed without a pair is named under the table."]
    if not a["learned"] or not a["controls"]:
        lines += ["", "No pair to compare: the trial needs a learned arm and a control."]
        return lines
    for x in a["cells"]:
        best = x["best"]
        lines += ["", f"### {cell_title(x['cell'])}", "",
                  f"Best control: `{best}` ({fmt(x['best_speed'], 2)} m/s)." if best else "No control finished here."]
        body, notes = [], []
        for e in x["comparisons"]:
            name = f"`{e['learned']}` vs `{e['control']}`" + (" (best)" if e["best"] else "")
            body.append([name, "speed ratio − 1"] + diff_text(e["ratio"], 2))
            for c in e["metrics"]:
                if not e["best"] and c["metric"] != SPEED:
                    continue
                label = SHORT[c["metric"]] + (" †" if c["fallback"] else "")
                body.append([name, label] + diff_text(c, digits_of(c["metric"])))
            left = e["ratio"]["left_out"]
            if left:
                notes.append(f"- `{e['learned']}` vs `{e['control']}`: seeds left out: "
                             + "; ".join(f"s{s} ({why})" for s, why in left))
        if body:
            lines += [""] + md_table(PAIR_HEAD, body)
            lines += ([""] + notes) if notes else []
    lines += ["", "Against a control that is not the cell's best, only speed is shown here; every metric "
              "of every pair is in `results/paired.csv`."]
    return lines


def federation_arms(settings):
    """{arm: what it is} of trial.json's federation table (the same training budget as its
    reference, by default `palcas`); {} without one."""
    return dict((settings.get("federation") or {}).get("arms") or {})


def federation_reference(settings):
    return (settings.get("federation") or {}).get("reference") or "palcas"


def variant_arms(settings):
    """{arm: {"base": arm, "what": text}} of trial.json's variants: a learned arm's policy run
    another way (settings chosen on the development seeds), its rows named by the variant."""
    return dict(settings.get("variants") or {})


def own_controls(settings):
    """{variant: [{"arm": rows name, "what": text}, ...]} of the variants that name an
    `own_control` (one {arm, what}, or a list of them): the variant's hand-made mechanisms run
    with its network's choice replaced by a fixed one (KEEP, say, or a rule's advice), so that
    every mechanism the variant gets that is not learned is in a control too. Their rows are a
    control of that variant only, not of the trial's cells."""
    variants = variant_arms(settings)
    out = {}
    for arm, v in variants.items():
        declared = v.get("own_control")
        if declared is None:
            continue
        controls = []
        for own in (declared if isinstance(declared, list) else [declared]):
            name = (own.get("arm") or "").strip() if isinstance(own, dict) else ""
            if not name or not (own.get("what") or "").strip():
                raise TrialError(f"trial.json variants: '{arm}' own_control needs an arm and a what")
            if name == arm or name in variants:
                raise TrialError(f"trial.json variants: '{arm}' own_control '{name}' is a variant, not a control")
            if name in [c["arm"] for c in controls]:
                raise TrialError(f"trial.json variants: '{arm}' own_control '{name}' is named twice")
            controls.append({"arm": name, "what": own["what"].strip()})
        if not controls:
            raise TrialError(f"trial.json variants: '{arm}' own_control is an empty list")
        out[arm] = controls
    return out


def own_control_arms(settings):
    return {c["arm"] for controls in own_controls(settings).values() for c in controls}


def shipped_variants(settings):
    """{base arm: variant} of the variants trial.json marks `"ships": true`: the way the base
    arm's shipped policy now runs (its policy folder's rsu.yaml, say), so that the targets read
    what ships, not the rows the trial ran before."""
    out = {}
    for arm, v in variant_arms(settings).items():
        if not v.get("ships"):
            continue
        base = v.get("base")
        if not base:
            raise TrialError(f"trial.json variants: '{arm}' ships but names no base arm")
        if base in out:
            raise TrialError(f"trial.json variants: '{out[base]}' and '{arm}' both ship as '{base}'")
        out[base] = arm
    return out


def as_shipped(rows, shipped, replaced_as=None):
    """The rows with each shipping variant's rows standing for its base arm, whose own rows are
    left out (a cell where the variant did not run has no rows of the base), or kept under the
    name `replaced_as` {base arm: name} gives them."""
    base_of = {variant: base for base, variant in shipped.items()}
    replaced_as = replaced_as or {}
    out = []
    for r in rows:
        if r["arm"] in shipped:
            if r["arm"] in replaced_as:
                out.append(dict(r, arm=replaced_as[r["arm"]]))
        else:
            out.append(dict(r, arm=base_of.get(r["arm"], r["arm"])))
    return out


def federation_rows(rows, settings):
    """The rows the federation table reads. Its reference is the shipped federation: when a
    variant ships as the reference arm, the variant's rows stand for it, and the rows the trial
    ran of the reference are kept under the variant's `replaced_as` name (to be listed among the
    table's arms as the policy that shipped before)."""
    shipped = shipped_variants(settings)
    ref = federation_reference(settings)
    if ref not in shipped:
        return rows
    replaced = (variant_arms(settings)[shipped[ref]].get("replaced_as") or "").strip()
    return as_shipped(rows, {ref: shipped[ref]}, {ref: replaced} if replaced else None)


def training_arms(settings):
    """{arm: {"seed": training seed, "what": text}} of trial.json's trainings: the shipped
    configuration trained again from other seeds, its reference (the shipped policy) among them."""
    return dict((settings.get("trainings") or {}).get("arms") or {})


def training_reference(settings):
    return (settings.get("trainings") or {}).get("reference") or "palcas"


def training_alternatives(settings):
    """{name: {"what": text, "arms": {arm: {"seed", "what"}}, "against": name}} of trial.json's
    trainings: another configuration (an update schedule, say) trained from several seeds,
    compared with the shipped configuration's trainings, the training being the unit, or with
    the alternative its "against" names (one that differs from it in one setting)."""
    alternatives = dict((settings.get("trainings") or {}).get("alternatives") or {})
    for name, alt in alternatives.items():
        against = alt.get("against")
        if against is not None and (against == name or against not in alternatives
                                    or alternatives[against].get("against") is not None):
            raise TrialError(f"trial.json trainings: alternative '{name}' is against '{against}', "
                             f"which is not another alternative compared with the shipped configuration")
    return alternatives


def alternative_arms(settings):
    return {arm for alt in training_alternatives(settings).values() for arm in (alt.get("arms") or {})}


def extra_arms(settings):
    """Arms shown in a section of their own, not in the planned grid."""
    retrained = (set(training_arms(settings)) | alternative_arms(settings)) - {training_reference(settings)}
    return set(federation_arms(settings)) | set(variant_arms(settings)) | retrained | own_control_arms(settings)


FEDERATION_METRICS = ["dsr", "lane_changes_per_cav", "throughput_vph", "total_time_spent_veh_h"]


def analyse_federation(rows, settings, a):
    """The reference (the shipped federation) against each arm of the federation table, per
    cell where that arm has rows, paired by seed; and each of them against the cell's best
    control on speed."""
    arms, ref = federation_arms(settings), federation_reference(settings)
    if not arms:
        return []
    rows = federation_rows(rows, settings)
    shipped = shipped_variants(settings)
    reference_what = ((settings.get("federation") or {}).get("reference_what")
                      or "each RSU its own final model, trained through FedAvg")
    best = {x["cell"]: x["best"] for x in a["cells"]}
    out = []
    for cell in cells_of([r for r in rows if r["arm"] in arms]):
        entries = []
        for arm in sort_arms(arms, load_registry()):
            if done_rows(rows, arm, cell):
                entries.append(dict(paired_entry(rows, cell, ref, arm, FEDERATION_METRICS, best.get(cell)),
                                    arm=arm, what=arms[arm]))
        out.append({"cell": cell, "reference": ref, "reference_own": arm_cell(rows, ref, cell),
                    "best": best.get(cell), "entries": entries, "reference_what": reference_what,
                    "reference_rows_of": shipped.get(ref, ref)})
    return out


def paired_entry(rows, cell, left, right, metrics, best):
    """`left` against `right` in one cell (speed ratio and `metrics`), paired by seed, the
    right-hand arm's own numbers, and the arm that is not the reference against the cell's
    best control on speed."""
    e = {"own": arm_cell(rows, right, cell), "ratio": compare(rows, left, right, cell, SPEED, ratio=True),
         "metrics": [compare(rows, left, right, cell, m) for m in metrics]}
    if best:
        e["vs_best"] = compare(rows, right, best, cell, SPEED, ratio=True)
    return e


# The columns two arms' rows must agree on, seed by seed, to be the same runs (same_rows_as).
SAME_RUN_COLUMNS = ["efficiency_all_mps", "throughput_vph", "unserved_vehicles", "total_time_spent_veh_h",
                    "dsr_pct", "dsr_censored_pct", "comfort_share_pct", "lane_changes_per_cav", "collisions"]


def same_rows_as(rows, arm, cell, others):
    """The arms of `others` whose finished rows in the cell equal `arm`'s on every seed `arm` ran
    and every SAME_RUN_COLUMNS column: an own control that turns out to be a trial arm already
    (its hand-made mechanisms changed nothing when the fixed choice chose), so the page says so."""
    mine = {r["seed"]: r for r in done_rows(rows, arm, cell)}

    def equal(x, y):
        a, b = number(x), number(y)
        return a == b or (a is not None and b is not None and abs(a - b) <= 1e-9 * max(1.0, abs(a)))

    out = []
    for other in others:
        theirs = {r["seed"]: r for r in done_rows(rows, other, cell)}
        if mine and set(mine) <= set(theirs) and all(
                equal(mine[s].get(c), theirs[s].get(c)) for s in mine for c in SAME_RUN_COLUMNS):
            out.append(other)
    return out


def analyse_variants(rows, settings, a):
    """Each variant against the cell's best control (every paired metric), against its own
    control where it names one (every paired metric; and that control against the best control
    on speed) and against its base arm (speed and the metrics the base differs in), per cell
    where it has rows."""
    variants = variant_arms(settings)
    own = own_controls(settings)
    best = {x["cell"]: x["best"] for x in a["cells"]}
    out = []
    for cell in cells_of([r for r in rows if r["arm"] in variants]):
        entries = []
        for arm in sorted(variants):
            if not done_rows(rows, arm, cell):
                continue
            e = {"arm": arm, "what": variants[arm].get("what", ""), "base": variants[arm].get("base", "")}
            if best.get(cell):
                e["vs_best"] = dict(paired_entry(rows, cell, arm, best[cell], PAIRED, None), control=best[cell])
            e["vs_own"] = [dict(paired_entry(rows, cell, arm, c["arm"], PAIRED, best.get(cell)), control=c["arm"],
                                control_what=c["what"], same_as=same_rows_as(rows, c["arm"], cell, a["controls"]),
                                seeds=len(done_rows(rows, c["arm"], cell)))
                           for c in own.get(arm, []) if done_rows(rows, c["arm"], cell)]
            if e["base"] and done_rows(rows, e["base"], cell):
                e["vs_base"] = paired_entry(rows, cell, arm, e["base"], FEDERATION_METRICS, None)
            e["own"] = arm_cell(rows, arm, cell)
            entries.append(e)
        out.append({"cell": cell, "best": best.get(cell), "entries": entries})
    return out


def stdev(values):
    """The sample standard deviation (n - 1), nan for fewer than 2 values."""
    if len(values) < 2:
        return float("nan")
    m = sum(values) / len(values)
    return math.sqrt(sum((v - m) ** 2 for v in values) / (len(values) - 1))


def welch_interval(a, b):
    """(mean(a) - mean(b), low, high): the two-sided 95 % Welch interval of a difference of two
    means, with the Welch-Satterthwaite degrees of freedom rounded down (at least 1); the bounds
    are nan when either side has fewer than 2 values."""
    diff = sum(a) / len(a) - sum(b) / len(b)
    if len(a) < 2 or len(b) < 2:
        return diff, float("nan"), float("nan")
    va, vb = stdev(a) ** 2 / len(a), stdev(b) ** 2 / len(b)
    se = math.sqrt(va + vb)
    if se == 0.0:
        return diff, diff, diff
    df = (va + vb) ** 2 / (va ** 2 / (len(a) - 1) + vb ** 2 / (len(b) - 1))
    half = palcas_stats.t975(max(1, int(df))) * se
    return diff, diff - half, diff + half


def training_entry(rows, cell, arm, info, by_arm, ctrl, common):
    """One training in one cell: its speed ÷ the control's − 1 per seed of `common`, their mean,
    paired-t interval, SD and worst seed, and its own DSR and lane changes per CAV."""
    per = [(s, 100.0 * (by_arm[s] / ctrl[s] - 1.0)) for s in common if ctrl[s]]
    vals = [v for _, v in per]
    mean, lo, hi = palcas_stats.t_interval(vals) if vals else (float("nan"),) * 3
    worst = summary(per, "higher") if per else {"worst": float("nan"), "worst_seed": ""}
    own = arm_cell([r for r in rows if r["seed"] in common], arm, cell)["metrics"]
    return {"arm": arm, "seed": info.get("seed", ""), "what": info.get("what", ""),
            "n": len(vals), "mean": mean, "lo": lo, "hi": hi, "sd": stdev(vals),
            "worst": worst["worst"], "worst_seed": worst["worst_seed"],
            "dsr": (own.get("dsr") or {}).get("mean", float("nan")),
            "lane_changes": (own.get("lane_changes_per_cav") or {}).get("mean", float("nan"))}


def by_training_seed(arms):
    return sorted(arms, key=lambda x: (arms[x].get("seed", 0), x))


def analyse_trainings(rows, settings, a):
    """Per cell where the reference and at least one retraining have rows: each training's
    speed ratio to the cell's best control (per seed, on the seeds every training and the
    control finished), the spread between the trainings' means against the spread between
    traffic seeds within a training, and each retraining paired with the reference. Each
    alternative configuration with at least two finished trainings in the cell: its trainings
    on the same seeds, and the difference between the two configurations' mean training."""
    arms, ref = training_arms(settings), training_reference(settings)
    if not arms:
        return []
    alternatives = training_alternatives(settings)
    best = {x["cell"]: x["best"] for x in a["cells"]}
    order = [ref] + [x for x in by_training_seed(arms) if x != ref]
    out = []
    for cell in cells_of([r for r in rows if r["arm"] in arms and r["arm"] != ref]):
        control = best.get(cell)
        present = [x for x in order if done_rows(rows, x, cell)]
        if control is None or ref not in present or len(present) < 2:
            continue
        alt_present = {}
        for name, alt in sorted(alternatives.items()):
            have = [x for x in by_training_seed(alt.get("arms") or {}) if done_rows(rows, x, cell)]
            if len(have) >= 2:
                alt_present[name] = have
        everyone = present + [x for have in alt_present.values() for x in have]
        by_arm = {x: {s: v for s, v, _ in pair(rows, x, control, cell, SPEED)[0]} for x in everyone}
        ctrl = {s: c for s, _, c in pair(rows, ref, control, cell, SPEED)[0]}
        common = sorted(set(ctrl).intersection(*[set(v) for v in by_arm.values()]))
        entries = []
        for x in present:
            e = training_entry(rows, cell, x, arms.get(x, {}), by_arm[x], ctrl, common)
            if x != ref:
                e["vs_reference"] = compare(rows, x, ref, cell, SPEED, common, ratio=True)
            entries.append(e)
        ctrl_own = arm_cell([r for r in rows if r["seed"] in common], control, cell)["metrics"]
        means = [e["mean"] for e in entries]
        within = math.sqrt(sum(e["sd"] ** 2 for e in entries) / len(entries)) if entries else float("nan")
        n = len(common)
        alts, by_name = [], {}
        for name, have in alt_present.items():
            info = alternatives[name]
            alt_entries = [training_entry(rows, cell, x, info["arms"][x], by_arm[x], ctrl, common) for x in have]
            alt_means = [e["mean"] for e in alt_entries]
            by_name[name] = {"name": name, "what": info.get("what", ""), "entries": alt_entries,
                             "against": info.get("against"), "means": alt_means,
                             "mean_of_means": sum(alt_means) / len(alt_means), "between_sd": stdev(alt_means),
                             "dsr": sum(e["dsr"] for e in alt_entries) / len(alt_entries),
                             "lane_changes": sum(e["lane_changes"] for e in alt_entries) / len(alt_entries)}
        for name, alt in by_name.items():
            base = by_name.get(alt["against"]) if alt["against"] else None
            if alt["against"] and base is None:
                continue  # what it is compared with has fewer than two trainings in this cell
            diff, lo, hi = welch_interval(alt["means"], base["means"] if base else means)
            alts.append(dict(alt, diff=diff, lo=lo, hi=hi,
                             verdict="none" if not (math.isfinite(lo) and (lo > 0 or hi < 0))
                             else ("gain" if lo > 0 else "loss"),
                             base_mean=base["mean_of_means"] if base else sum(means) / len(means),
                             base_sd=base["between_sd"] if base else stdev(means),
                             base_n=len(base["entries"]) if base else len(entries),
                             base_dsr=base["dsr"] if base else sum(e["dsr"] for e in entries) / len(entries),
                             base_lane_changes=(base["lane_changes"] if base else
                                                sum(e["lane_changes"] for e in entries) / len(entries))))
        out.append({"cell": cell, "control": control, "reference": ref, "seeds": common, "entries": entries,
                    "between_sd": stdev(means), "between_range": (min(means), max(means)),
                    "mean_of_means": sum(means) / len(means), "within_sd": within,
                    "within_se": within / math.sqrt(n) if n else float("nan"),
                    "dsr": sum(e["dsr"] for e in entries) / len(entries),
                    "lane_changes": sum(e["lane_changes"] for e in entries) / len(entries),
                    "alternatives": alts,
                    "configuration": ((settings.get("trainings") or {}).get("configuration") or "").strip(),
                    "control_dsr": (ctrl_own.get("dsr") or {}).get("mean", float("nan")),
                    "control_lane_changes": (ctrl_own.get("lane_changes_per_cav") or {}).get("mean", float("nan"))})
    return out


def configuration_name(x, alt=None):
    """What an alternative is compared with: the alternative its "against" names, else the
    retrainings' reference configuration, called the shipped one unless trial.json's trainings
    configuration says they are of another."""
    if alt is not None and alt.get("against"):
        return f"`{alt['against']}`"
    return "the reference configuration" if x.get("configuration") else "the shipped configuration"


def trainings_section(tr):
    if not tr:
        return []
    ref = tr[0]["reference"]
    lines = ["", "## Variance across trainings of the shipped configuration", "",
             f"The shipped configuration trained again from other training seeds (other traffic, demand "
             f"and PR draws, network initialisation and exploration), each run on the same test seeds. "
             f"Per training: speed ÷ the cell's best control − 1, per seed, then its mean over the seeds "
             f"every training and the control finished. Between trainings: the standard deviation of "
             f"those means; between traffic seeds: the pooled standard deviation of the per-seed values "
             f"within a training, and the standard error it gives one training's mean. A difference "
             f"between two trained policies smaller than the spread between trainings of one "
             f"configuration is not a difference between their configurations. So another configuration "
             f"(trial.json's trainings alternatives) is compared with the training as the unit: its trainings' "
             f"mean against the shipped trainings' mean (or those of the alternative it is named against), "
             f"with the Welch 95 % interval over the trainings' "
             f"means (a configuration with one training has no such interval and is shown only as a variant)."]
    if tr[0]["configuration"]:  # trainings of a configuration that no longer ships, say
        lines += ["", f"**The configuration these trainings are of:** {tr[0]['configuration']}"]
    for x in tr:
        lines += ["", f"### {cell_title(x['cell'])}, against `{x['control']}`", ""]
        for e in x["entries"]:
            if e["what"]:
                lines.append(f"- `{e['arm']}` (training seed {e['seed']}): {e['what']}")
        lines += ["", *training_table(x["entries"], x["control"])]
        lo, hi = x["between_range"]
        lines += ["", f"- Between trainings ({len(x['entries'])}): mean {fmt(x['mean_of_means'], 2, signed=True)} %, "
                  f"SD {fmt(x['between_sd'], 2)} points, range {fmt(lo, 2, signed=True)} to {fmt(hi, 2, signed=True)} %",
                  f"- Between traffic seeds within a training: SD {fmt(x['within_sd'], 2)} points; the "
                  f"standard error of one training's mean over {len(x['seeds'])} seeds "
                  f"{fmt(x['within_se'], 2)} points",
                  f"- `{x['control']}` on the same seeds: DSR {fmt(x['control_dsr'], 1)} %, lane changes per CAV "
                  f"{fmt(x['control_lane_changes'], 2)}"]
        pairs = [e for e in x["entries"] if "vs_reference" in e]
        if pairs:
            body = [[f"`{e['arm']}` vs `{ref}`", "speed ratio − 1"] + diff_text(e["vs_reference"], 2) for e in pairs]
            lines += ["", *md_table(PAIR_HEAD, body)]
        for alt in x["alternatives"]:
            lines += ["", f"#### Another configuration, `{alt['name']}`, trained from {len(alt['entries'])} seeds", ""]
            if alt["what"]:
                lines += [alt["what"], ""]
            lines += training_table(alt["entries"], x["control"])
            base = configuration_name(x, alt)
            lines += ["", f"- `{alt['name']}` against {base}, the training as the unit "
                      f"({len(alt['entries'])} against {alt['base_n']} trainings, their means over the same "
                      f"{len(x['seeds'])} seeds): {fmt(alt['mean_of_means'], 2, signed=True)} % against "
                      f"{fmt(alt['base_mean'], 2, signed=True)} % vs `{x['control']}`, a difference of "
                      f"{fmt(alt['diff'], 2, signed=True)} points, Welch 95 % {interval(alt['lo'], alt['hi'], 2)}: "
                      f"{WORDS[alt['verdict']]}",
                      f"- Between its trainings: SD {fmt(alt['between_sd'], 2)} points "
                      f"({base}'s: {fmt(alt['base_sd'], 2)}); mean DSR {fmt(alt['dsr'], 1)} % against "
                      f"{fmt(alt['base_dsr'], 1)} %, lane changes per CAV {fmt(alt['lane_changes'], 2)} against "
                      f"{fmt(alt['base_lane_changes'], 2)}"]
    return lines


def training_table(entries, control):
    body = [[f"`{e['arm']}`", str(e["seed"]), str(e["n"]), fmt(e["mean"], 2, signed=True) + " %",
             interval(e["lo"], e["hi"], 2), fmt(e["sd"], 2), f"{fmt(e['worst'], 2, signed=True)} % (s{e['worst_seed']})",
             fmt(e["dsr"], 1), fmt(e["lane_changes"], 2)]
            for e in entries]
    return md_table(["training", "training seed", "seeds", f"speed vs `{control}`", "paired-t 95 %",
                     "SD over seeds", "worst seed", "DSR %", "lane changes per CAV"], body)


def trainings_csv(tr):
    head = ["demand", "pr", "training", "training_seed", "against", "seeds", "mean_ratio_pct", "t_lo", "t_hi",
            "sd_over_seeds", "worst", "worst_seed", "dsr_pct", "lane_changes_per_cav"]
    rows = []
    for x in tr:
        d, pr = x["cell"]
        rows += [[d, pr, e["arm"], e["seed"], x["control"], e["n"], e["mean"], e["lo"], e["hi"], e["sd"],
                  e["worst"], e["worst_seed"], e["dsr"], e["lane_changes"]] for e in x["entries"]]
        lo, hi = x["between_range"]
        rows.append([d, pr, "between trainings", "", x["control"], len(x["seeds"]), x["mean_of_means"], lo, hi,
                     x["between_sd"], "", "", "", ""])
        rows.append([d, pr, "within a training (pooled)", "", x["control"], len(x["seeds"]), "", "", "",
                     x["within_sd"], "", "", "", ""])
        for alt in x["alternatives"]:
            rows += [[d, pr, e["arm"], e["seed"], x["control"], e["n"], e["mean"], e["lo"], e["hi"], e["sd"],
                      e["worst"], e["worst_seed"], e["dsr"], e["lane_changes"]] for e in alt["entries"]]
            rows.append([d, pr, f"{alt['name']} minus {configuration_name(x, alt).strip('`')} (Welch, trainings)",
                         "", x["control"], len(x["seeds"]), alt["diff"], alt["lo"], alt["hi"], alt["between_sd"],
                         "", "", alt["dsr"] - alt["base_dsr"], alt["lane_changes"] - alt["base_lane_changes"]])
    return csv_text(head, rows)


def variants_section(var):
    if not var:
        return []
    lines = ["", "## Learned variants chosen on the development seeds", "",
             "A learned arm's policy run another way, its setting chosen on the development seeds "
             "before any test seed, then run on the test seeds: paired with the cell's best control "
             "(every metric, as above), with its own control where it has one (its hand-made mechanisms "
             "with the network's choice replaced by a fixed one: every metric, and that control against "
             "the best control), and with the arm it varies (variant − that arm)."]
    for x in var:
        lines += ["", f"### {cell_title(x['cell'])}", ""]
        body = []
        for e in x["entries"]:
            lines.append(f"- `{e['arm']}`: {e['what']}")
            for own in e["vs_own"]:
                lines.append(f"  - its own control `{own['control']}`: {own['control_what']}")
                for same in own["same_as"]:
                    lines.append(f"    - here its {own['seeds']} rows equal `{same}`'s seed for seed on every "
                                 f"metric: the mechanisms changed nothing, so the trial's `{same}` arm is this "
                                 "control already")
            read = ([(e["vs_best"], " (best control)")] if "vs_best" in e else []) \
                + [(own, " (its own control)") for own in e["vs_own"]]
            for entry, label in read + ([(dict(e["vs_base"], control=e["base"]), "")] if "vs_base" in e else []):
                name = f"`{e['arm']}` vs `{entry['control']}`{label}"
                body.append([name, "speed ratio − 1"] + diff_text(entry["ratio"], 2))
                for c in entry["metrics"]:
                    if c["metric"] != SPEED:
                        body.append([name, SHORT[c["metric"]] + (" †" if c["fallback"] else "")]
                                    + diff_text(c, digits_of(c["metric"])))
            for own in e["vs_own"]:
                if "vs_best" in own:
                    c = own["vs_best"]
                    body.append([f"`{own['control']}` vs `{c['control']}` (best control)", "speed ratio − 1"]
                                + diff_text(c, 2))
            for entry, _ in read:
                lines.append(f"  - reading against `{entry['control']}`: "
                             + reading_line(entry["ratio"], pct=True) + "; "
                             + "; ".join(reading_line(c) for c in entry["metrics"] if c["metric"] != SPEED))
        lines += [""] + md_table(PAIR_HEAD, body)
    return lines


def variants_csv(var):
    rows = []
    for x in var:
        d, pr = x["cell"]
        for e in x["entries"]:
            against = ([e["vs_best"]] if "vs_best" in e else []) + e["vs_own"] \
                + ([e["vs_base"]] if "vs_base" in e else [])
            for entry in against:
                rows += comparison_rows(d, pr, [entry["ratio"]] + entry["metrics"])
            rows += comparison_rows(d, pr, [own["vs_best"] for own in e["vs_own"] if "vs_best" in own])
    return csv_text(COMPARISON_HEAD, rows)


COMPARISON_HEAD = ["demand", "pr", "arm", "against", "metric", "seeds", "mean_difference", "bootstrap_lo",
                   "bootstrap_hi", "t_lo", "t_hi", "worst", "worst_seed", "reading"]


def comparison_rows(d, pr, comparisons):
    return [[d, pr, c["learned"], c["control"], c["metric"] + (" ratio %" if c["ratio"] else ""), c["n"],
             c.get("mean", ""), c.get("b_lo", ""), c.get("b_hi", ""), c.get("t_lo", ""), c.get("t_hi", ""),
             c.get("worst", ""), c.get("worst_seed", ""), verdict(c) if c["n"] else ""] for c in comparisons]


def federation_section(fed):
    if not fed:
        return []
    ref, rows_of = fed[0]["reference"], fed[0]["reference_rows_of"]
    read_as = "" if rows_of == ref else f"; its rows are those of the variant `{rows_of}`, as it ships"
    lines = ["", "## The federation against its alternatives, same training budget", "",
             f"`{ref}` (the shipped federation: {fed[0]['reference_what']}{read_as}) "
             "against policies trained with the same budget (episodes, durations, demand and PR draws, "
             "actuation) but another scheme, on the same seeds, paired as above: "
             f"`{ref}` − the other, and speed as `{ref}` ÷ the other − 1. Each is also paired with the "
             "cell's best control on speed (that arm ÷ best control − 1)."]
    for x in fed:
        lines += ["", f"### {cell_title(x['cell'])}", ""]
        for e in x["entries"]:
            lines.append(f"- `{e['arm']}`: {e['what']}")
        own = [[f"`{ref}`"] + federation_own_cells(x["reference_own"])]
        own += [[f"`{e['arm']}`"] + federation_own_cells(e["own"]) for e in x["entries"]]
        lines += ["", *md_table(["arm", "seeds", "speed m/s (95 %)", "worst seed", "DSR % (95 %)"], own)]
        body = []
        for e in x["entries"]:
            name = f"`{ref}` vs `{e['arm']}`"
            body.append([name, "speed ratio − 1"] + diff_text(e["ratio"], 2))
            for c in e["metrics"]:
                body.append([name, SHORT[c["metric"]] + (" †" if c["fallback"] else "")]
                            + diff_text(c, digits_of(c["metric"])))
            if "vs_best" in e:
                body.append([f"`{e['arm']}` vs `{x['best']}` (best control)", "speed ratio − 1"]
                            + diff_text(e["vs_best"], 2))
        lines += [""] + md_table(PAIR_HEAD, body)
    return lines


def federation_own_cells(own):
    m, d = own["metrics"].get(SPEED), own["metrics"].get("dsr") or {}
    if not m:
        return [str(own["n"]), "n/a", "n/a", "n/a"]
    dsr = (f"{fmt(d['mean'], 1)} {interval(d['lo'], d['hi'], 1)}" if d else "n/a")
    return [str(own["n"]), f"{fmt(m['mean'], 2)} {interval(m['lo'], m['hi'], 2)}",
            f"{fmt(m['worst'], 2)} (s{m['worst_seed']})", dsr]


def federation_csv(fed):
    rows = []
    for x in fed:
        d, pr = x["cell"]
        for e in x["entries"]:
            rows += comparison_rows(d, pr, [e["ratio"]] + e["metrics"] + ([e["vs_best"]] if "vs_best" in e else []))
    return csv_text(COMPARISON_HEAD, rows)


def reading_line(c, pct=False):
    name = "speed" if pct else SHORT[c["metric"]]
    if c["n"] == 0:
        return f"{name}: no paired seed"
    d = 1 if pct else digits_of(c["metric"])
    unit = " %" if pct else UNIT[c["metric"]]
    if c["n"] < 2:
        return f"{name} {fmt(c['mean'], d, signed=True)}{unit} on one seed: no difference shown"
    lo, hi = span(c)
    return (f"{name} {fmt(c['mean'], d, signed=True)}{unit} [{fmt_bound(lo, d, True)}, {fmt_bound(hi, d, True)}], "
            f"worst seed {fmt(c['worst'], d, signed=True)}{unit}: {WORDS[verdict(c)]}")


def reading_section(a):
    lines = ["", "## Reading", "",
             "Generated from the intervals above, nothing else: *a gain* / *a loss* when the whole span "
             "of the two 95 % intervals (bootstrap and paired t) lies above / below 0 in the learned "
             "arm's favour / against it, else *no difference shown*; the bracket is that span."]
    for x in a["cells"]:
        lines += ["", f"**{cell_title(x['cell'])}**", ""]
        if not x["comparisons"]:
            lines.append("- nothing to compare")
            continue
        for e in x["comparisons"]:
            n = e["ratio"]["n"]
            if e["best"]:
                lines.append(f"- `{e['learned']}` vs best control ({e['control']}), {n} paired seeds: "
                             + reading_line(e["ratio"], pct=True))
                for c in e["metrics"]:
                    if c["metric"] != SPEED:
                        lines.append(f"  - {reading_line(c)}")
            else:
                lines.append(f"- `{e['learned']}` vs {e['control']}, {n} paired seeds: " + reading_line(e["ratio"], pct=True))
    return lines


# --- the learned advice's targets -----------------------------------------------------------

TARGET_DEFAULTS = {
    "busy_demands": [1400, 1800, 2200],  # where the learned advice must beat the best control
    "busy_speed_gain_pct": 3.0,          # the better learned mode's speed ÷ best control − 1, at least
    "cr_margin_points": 0.05,            # CR at most the best control's + this
    "light_demand": 1000,
    "advisory_arm": "palcas", "assist_arm": "palcas_assist",
    "assist_control": "rules_assist", "native_arm": "sumo_native",
    # DSR: of the CAVs whose exit was decided (dsr_pct), at least; and censored counted, at
    # least this minus 100 points against native_arm's on the same seeds: CAVs still before
    # their exit when a run ends are not served, so no arm, SUMO's own drivers included,
    # reaches an absolute rate near 100 % on that count (docs/journal/experiments.md, "The
    # DSR targets read as no arm could meet them").
    "light_dsr_pct": 99.5,               # advisory mode's DSR, as above
    "light_lane_change_factor": 1.5,     # its lane changes per CAV ÷ SUMO-native's, at most
    "light_speed_floor_pct": -0.5,       # its speed ÷ best control − 1, at least
    "assist_dsr_pct": 100.0,             # assist mode's DSR of the decided exits, at least
    "decision_p99_ms": 5.0,              # every run's decision p99, below
    "federation_reference": "palcas", "federation_control": "independent",
}


def target_settings(settings):
    """trial.json's targets over the defaults; None when the trial names no targets."""
    if settings.get("targets") is None:
        return None
    unknown = set(settings["targets"]) - set(TARGET_DEFAULTS)
    if unknown:
        raise TrialError(f"trial.json targets: unknown key(s) {', '.join(sorted(unknown))} "
                         f"(known: {', '.join(sorted(TARGET_DEFAULTS))})")
    return dict(TARGET_DEFAULTS, **settings["targets"])


def target_row(name, cell, arm, measured, required, met, short=""):
    return {"target": name, "cell": cell, "arm": arm, "rows_of": arm, "measured": measured, "required": required,
            "met": bool(met), "short": short if not met else ""}


def comparison_of(x, learned, control):
    for e in x["comparisons"]:
        if e["learned"] == learned and e["control"] == control:
            return e
    return None


def metric_of(e, metric):
    return next(c for c in e["metrics"] if c["metric"] == metric)


def with_span(c, digits, unit=""):
    lo, hi = span(c)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return f"{fmt(c['mean'], digits, signed=True)}{unit}"
    return (f"{fmt(c['mean'], digits, signed=True)}{unit} "
            f"[{fmt_bound(lo, digits, signed=True)}, {fmt_bound(hi, digits, signed=True)}]")


def dsr_targets(mode, x, arm, least_pct, native, censored):
    """A learned mode's DSR targets in cell x: of the CAVs whose exit was decided, at least
    least_pct; with `censored`, also the rate that counts the CAVs still before their exit at
    the end, at most 100 - least_pct points below `native`'s on the same seeds (an absolute
    bar there is one SUMO's own drivers miss: the end of a run leaves exit-bound CAVs
    undecided whoever drives). Each row names the other rate and native's beside it."""
    own, ctl = x["arms"][arm], x["arms"].get(native) or {}
    dsr, ctl_dsr = own["metrics"].get("dsr"), (ctl.get("metrics") or {}).get("dsr")
    beside = (f"censored counted {fmt(dsr['mean'], 1)} %" if dsr else "")
    if dsr and ctl_dsr:
        beside += f", `{native}` {fmt(ctl_dsr['mean'], 1)} %"
    out = []
    decided = own.get("dsr_decided")
    if decided:
        out.append(target_row(f"{mode}: DSR of the decided exits", x["cell"], arm,
                              f"{fmt(decided['mean'], 1)} %" + (f" ({beside})" if beside else ""),
                              f"≥ {least_pct:g} %", decided["mean"] >= least_pct,
                              f"{fmt(least_pct - decided['mean'], 1)} points below"))
    e = comparison_of(x, arm, native)
    if censored and e and dsr and ctl_dsr:
        c, floor = metric_of(e, "dsr"), least_pct - 100.0
        out.append(target_row(f"{mode}: DSR, censored counted, vs `{native}`", x["cell"], arm,
                              f"{with_span(c, 1, ' points')} ({fmt(dsr['mean'], 1)} against "
                              f"{fmt(ctl_dsr['mean'], 1)} %)", f"≥ {fmt(floor, 1, signed=True)} points (mean)",
                              c["mean"] >= floor, f"{fmt(floor - c['mean'], 1)} points below"))
    return out


def analyse_targets(a, fed, settings, shipped=None):
    """Each of the learned advice's targets on each cell where its arms ran: what was measured,
    what is required, met or not, and by how much it fell short. `a` is analyse() of the rows as
    shipped (as_shipped()); `shipped` {base arm: variant} names whose rows stand for an arm."""
    t = target_settings(settings)
    if t is None:
        return []
    out = []
    for r in _targets(a, fed, t):
        r["rows_of"] = (shipped or {}).get(r["arm"], r["arm"])
        out.append(r)
    return out


def _targets(a, fed, t):
    out = []
    busy = {float(d) for d in t["busy_demands"]}
    for x in a["cells"]:
        cell, best = x["cell"], x["best"]
        if best is None:
            continue
        pairs = [e for e in x["comparisons"] if e["best"] and e["ratio"]["n"] >= 2]
        if cell[0] in busy and pairs:
            e = max(pairs, key=lambda e: e["ratio"]["mean"])
            c = e["ratio"]
            lo = span(c)[0]
            gain = t["busy_speed_gain_pct"]
            short = []
            if c["mean"] < gain:
                short.append(f"{fmt(gain - c['mean'], 2)} points below +{gain:g} %")
            if not lo > 0:
                short.append("interval not above 0")
            out.append(target_row(f"speed of the better learned mode vs `{best}`", cell, e["learned"],
                                  with_span(c, 2, " %"), f"≥ +{gain:g} %, interval above 0", not short,
                                  "; ".join(short)))
            for metric in ("throughput_vph", "unserved_vehicles", "total_time_spent_veh_h"):
                c = metric_of(e, metric)
                out.append(target_row(f"{SHORT[metric]} vs `{best}`", cell, e["learned"],
                                      with_span(c, digits_of(metric), UNIT[metric]), "no worse (no loss shown)",
                                      verdict(c) != "loss", "a loss"))
        for e in pairs:
            L = e["learned"]
            own, ctl = x["arms"][L], x["arms"][best]
            if own.get("cr") and ctl.get("cr"):
                limit = ctl["cr"]["pct"] + t["cr_margin_points"]
                out.append(target_row(f"CR vs `{best}`", cell, L, f"{fmt(own['cr']['pct'], 3)} %",
                                      f"≤ {fmt(limit, 3)} %", own["cr"]["pct"] <= limit,
                                      f"{fmt(own['cr']['pct'] - limit, 3)} points over"))
            c = metric_of(e, "comfort_share_pct")
            if c["n"]:
                out.append(target_row(f"comfort share vs `{best}`", cell, L, with_span(c, 1, " points"),
                                      "≥ 0 points (mean)", c["mean"] >= 0.0, f"{fmt(-c['mean'], 1)} points below"))
            if "p99" in own:
                limit = t["decision_p99_ms"]
                out.append(target_row("decision p99, worst run", cell, L, f"{fmt(own['p99']['max'], 2)} ms",
                                      f"< {limit:g} ms", own["p99"]["max"] < limit,
                                      f"{fmt(own['p99']['max'] - limit, 2)} ms over"))
        if cell[0] == float(t["light_demand"]):
            adv = comparison_of(x, t["advisory_arm"], best)
            if adv and adv["ratio"]["n"] >= 2:
                L = t["advisory_arm"]
                out += dsr_targets("advisory mode", x, L, t["light_dsr_pct"], t["native_arm"], censored=True)
                lc = x["arms"][L]["metrics"].get("lane_changes_per_cav")
                native = (x["arms"].get(t["native_arm"]) or {}).get("metrics", {}).get("lane_changes_per_cav")
                if lc and native and native["mean"] > 0:
                    factor = lc["mean"] / native["mean"]
                    limit = t["light_lane_change_factor"]
                    out.append(target_row(f"advisory mode: lane changes per CAV ÷ `{t['native_arm']}`'s", cell, L,
                                          f"{fmt(factor, 2)} × ({fmt(lc['mean'], 2)} against {fmt(native['mean'], 2)})",
                                          f"≤ {limit:g} ×", factor <= limit, f"{fmt(100.0 * (factor / limit - 1.0), 0)} % over"))
                c, floor = adv["ratio"], t["light_speed_floor_pct"]
                out.append(target_row(f"advisory mode: speed vs `{best}`", cell, L, with_span(c, 2, " %"),
                                      f"≥ {fmt(floor, 1, signed=True)} % (mean)", c["mean"] >= floor,
                                      f"{fmt(floor - c['mean'], 2)} points below"))
            assist = comparison_of(x, t["assist_arm"], t["assist_control"])
            if assist and assist["ratio"]["n"] >= 2:
                L, c = t["assist_arm"], assist["ratio"]
                out.append(target_row(f"assist mode: speed vs `{t['assist_control']}`", cell, L, with_span(c, 2, " %"),
                                      "≥ 0 % (mean)", c["mean"] >= 0.0, f"{fmt(-c['mean'], 2)} points below"))
                out += dsr_targets("assist mode", x, L, t["assist_dsr_pct"], t["native_arm"], censored=False)
    for x in fed:
        e = next((e for e in x["entries"] if e["arm"] == t["federation_control"]), None)
        if e is None or x["reference"] != t["federation_reference"] or e["ratio"]["n"] < 2:
            continue
        dsr = next(c for c in e["metrics"] if c["metric"] == "dsr")
        short = [f"{what} {WORDS[verdict(c)]}" for what, c in (("speed", e["ratio"]), ("DSR", dsr))
                 if verdict(c) != "gain"]
        out.append(target_row(f"federation: `{x['reference']}` vs `{e['arm']}`, same budget", x["cell"],
                              x["reference"], f"speed {with_span(e['ratio'], 2, ' %')}; DSR "
                              f"{with_span(dsr, 1, ' points')}", "a gain on both (intervals above 0)",
                              not short, "; ".join(short)))
    return out


APPROACH_KEYS = ("for", "approach", "seeds", "outcome", "journal")
JOURNAL = ROOT / "docs" / "journal" / "experiments.md"


def approaches(settings, journal=JOURNAL):
    """trial.json's approaches: what was tried where a target is missed, each {for, approach,
    seeds, outcome, journal}, in the order given. Written by hand from the journal, so each must
    name a heading of the journal that exists: the page names it, and a renamed or missing entry
    is refused rather than pointed to."""
    items = settings.get("approaches") or []
    if not isinstance(items, list):
        raise TrialError("trial.json approaches: not a list")
    headings = None
    for i, item in enumerate(items):
        missing = [k for k in APPROACH_KEYS if not str((item or {}).get(k, "")).strip()]
        if missing:
            raise TrialError(f"trial.json approaches[{i}]: no {', '.join(missing)}")
        if headings is None:
            headings = {line.lstrip("#").strip() for line in journal.read_text().splitlines()
                        if line.startswith("#")}
        if item["journal"] not in headings:
            raise TrialError(f"trial.json approaches[{i}]: journal heading '{item['journal']}' is not in "
                             f"{shown_path(journal)}")
    return items


def approaches_section(items):
    if not items:
        return []
    lines = ["", "## What was tried where a target is missed", "",
             "Not computed on this page: written in trial.json's `approaches` from the journal "
             "(docs/journal/experiments.md), whose entry each row names, with the seeds the approach "
             "reached. Settings are chosen on development seeds, so an approach that failed there never "
             "ran on the test seeds."]
    body = [[x["for"], x["approach"], x["seeds"], x["outcome"], x["journal"]] for x in items]
    return lines + [""] + md_table(["for", "approach", "seeds", "outcome", "journal entry"], body)


def targets_section(targets):
    if not targets:
        return []
    met = sum(1 for r in targets if r["met"])
    stand_ins = sorted({(r["arm"], r["rows_of"]) for r in targets if r["rows_of"] != r["arm"]})
    lines = ["", "## The learned advice against its targets", "",
             "Each target of the learned advice (trial.json's `targets` over the generator's defaults) "
             "on each cell where its arms ran, from the numbers above: against the cell's best control "
             "unless named; intervals are the span of the bootstrap and paired-t 95 % intervals. A "
             "comparison made on one training of each side is read with the spread between trainings "
             "(the section above) in mind. A DSR target reads the exits decided by the end of a run "
             "(served or missed) against its bar; advisory mode's also reads the rate that counts the "
             "exit-bound CAVs still on the road at the end as not served, against `sumo_native`'s on the "
             "same seeds, since the end of a run leaves such CAVs whoever drives."]
    for arm, variant in stand_ins:
        lines[-1] += (f" `{arm}` is read as it ships: from the rows of the variant `{variant}` (above), "
                      f"not the trial's own `{arm}` rows; a cell where the variant did not run has no "
                      f"`{arm}` target.")
    lines += ["", f"**{met} of {len(targets)} met.**", ""]
    body = [[r["target"], cell_short(r["cell"]), arm_shown(r), r["measured"], r["required"],
             "met" if r["met"] else f"**missed**: {r['short']}"] for r in targets]
    lines += md_table(["target", "cell", "arm", "measured", "required", "reading"], body)
    return lines


def arm_shown(r):
    return f"`{r['arm']}`" if r["rows_of"] == r["arm"] else f"`{r['arm']}` (`{r['rows_of']}`)"


def targets_csv(targets):
    return csv_text(["target", "demand", "pr", "arm", "rows_of", "measured", "required", "met", "short"],
                    [[r["target"], r["cell"][0], r["cell"][1], r["arm"], r["rows_of"], r["measured"], r["required"],
                      "yes" if r["met"] else "no", r["short"]] for r in targets])


# --- CSVs and figures ----------------------------------------------------------------------

def cells_csv(a):
    rows = []
    for x in a["cells"]:
        d, pr = x["cell"]
        for arm in a["arms"]:
            ac = x["arms"][arm]
            for key, _, _, _ in METRICS:
                m = ac["metrics"].get(key)
                if m:
                    rows.append([d, pr, arm, key, m["column"], m["n"], m["mean"], m["lo"], m["hi"], m["worst"],
                                 m["worst_seed"]])
            if "cr" in ac:
                c = ac["cr"]
                rows.append([d, pr, arm, "cr_pooled_pct", "cav_collisions/cavs_seen", ac["n"], c["pct"], c["lo"],
                             c["hi"], f"{c['k']} of {c['n']}", ""])
            if "p99" in ac:
                rows.append([d, pr, arm, "decision_ms_p99_max", "decision_ms_p99", ac["n"], ac["p99"]["max"], "", "",
                             ac["p99"]["max"], ac["p99"]["seed"]])
    return csv_text(["demand", "pr", "arm", "metric", "column", "n", "mean", "ci95_lo", "ci95_hi", "worst",
                     "worst_seed"], rows)


def comparisons(a):
    for x in a["cells"]:
        for e in x["comparisons"]:
            for c in [e["ratio"]] + e["metrics"]:
                yield x, e, c


def paired_csv(a):
    rows = []
    for x, e, c in comparisons(a):
        d, pr = x["cell"]
        metric = "speed_ratio_pct" if c["ratio"] else c["metric"]
        if c["n"]:
            rows.append([d, pr, e["learned"], e["control"], "yes" if e["best"] else "no", metric, c["column"], c["n"],
                         c["mean"], c["b_lo"], c["b_hi"], c["t_lo"], c["t_hi"], c["worst"], c["worst_seed"], verdict(c),
                         " ".join(f"s{s}" for s, _ in c["left_out"])])
        else:
            rows.append([d, pr, e["learned"], e["control"], "yes" if e["best"] else "no", metric, c["column"], 0,
                         None, None, None, None, None, None, None, "none", " ".join(f"s{s}" for s, _ in c["left_out"])])
    return csv_text(["demand", "pr", "learned", "control", "best_control", "metric", "column", "n", "mean_diff",
                     "bootstrap_lo", "bootstrap_hi", "t_lo", "t_hi", "worst_diff", "worst_seed", "reading",
                     "seeds_left_out"], rows)


def paired_seeds_csv(a):
    rows = []
    for x, e, c in comparisons(a):
        if not e["best"]:
            continue
        d, pr = x["cell"]
        metric = "speed_ratio_pct" if c["ratio"] else c["metric"]
        for (s, lv, cv), (_, diff) in zip([p for p in c["pairs"] if not c["ratio"] or p[2]], c["per_seed"]):
            rows.append([d, pr, e["learned"], e["control"], metric, s, lv, cv, diff])
    return csv_text(["demand", "pr", "learned", "control", "metric", "seed", "learned_value", "control_value",
                     "difference"], rows)


def speed_ratio_csv(a):
    rows = []
    for x, e, c in comparisons(a):
        if e["best"] and c["ratio"] and c["n"]:
            lo, hi = span(c) if math.isfinite(c["t_lo"]) else (None, None)
            rows.append([x["cell"][0], x["cell"][1], e["learned"], e["control"], c["n"], 1.0 + c["mean"] / 100.0,
                         None if lo is None else 1.0 + lo / 100.0, None if hi is None else 1.0 + hi / 100.0,
                         1.0 + c["worst"] / 100.0, c["worst_seed"]])
    return csv_text(["demand", "pr", "learned", "best_control", "n", "ratio_mean", "ratio_lo", "ratio_hi",
                     "ratio_worst", "worst_seed"], rows)


def draw_speed_ratio(a, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cells = [x["cell"] for x in a["cells"]]
    fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * len(cells) + 2), 4.2))
    width = 0.8 / max(1, len(a["learned"]))
    for i, L in enumerate(a["learned"]):
        xs, ys, lo, hi = [], [], [], []
        for j, x in enumerate(a["cells"]):
            for e in x["comparisons"]:
                c = e["ratio"]
                if e["best"] and e["learned"] == L and c["n"]:
                    lo_, hi_ = span(c) if math.isfinite(c["t_lo"]) else (c["mean"], c["mean"])
                    m = 1.0 + c["mean"] / 100.0
                    xs.append(j - 0.4 + width * (i + 0.5))
                    ys.append(m)
                    lo.append(m - (1.0 + lo_ / 100.0))
                    hi.append((1.0 + hi_ / 100.0) - m)
        if xs:
            ax.errorbar(xs, ys, yerr=[lo, hi], fmt="o", capsize=4, color=f"C{i % 10}", label=L)
    ax.axhline(1.0, color="0.4", lw=1, ls="--")
    ax.set_xticks(range(len(cells)))
    ax.set_xticklabels([f"{cell_short(c)}\nvs {x['best'] or '-'}" for c, x in zip(cells, a["cells"])], fontsize=8)
    ax.set_xlabel("demand (veh/h/lane) / PR (%), best control")
    ax.set_ylabel("mean speed ÷ best control's (same seeds)")
    ax.set_title("Learned arm's speed relative to the best control\n(95 % interval: span of paired t and bootstrap)")
    ax.grid(alpha=0.3)
    if a["learned"]:
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90, metadata={"Software": None})
    plt.close(fig)


def draw_paired_seeds(a, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = [("speed", None)] + [(SHORT[m], m) for m in PAIRED if m != SPEED]
    cols = 4
    nrows = math.ceil(len(panels) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(4.0 * cols, 3.4 * nrows), squeeze=False)
    width = 0.8 / max(1, len(a["learned"]))
    for p, (label, metric) in enumerate(panels):
        ax = axes[p // cols][p % cols]
        for i, L in enumerate(a["learned"]):
            for j, x in enumerate(a["cells"]):
                for e in x["comparisons"]:
                    if not e["best"] or e["learned"] != L:
                        continue
                    c = e["ratio"] if metric is None else next(m for m in e["metrics"] if m["metric"] == metric)
                    if not c["n"]:
                        continue
                    x0 = j - 0.4 + width * (i + 0.5)
                    vals = [v for _, v in c["per_seed"]]
                    offs = [(k - (len(vals) - 1) / 2.0) * min(0.6 * width / max(1, len(vals)), 0.05)
                            for k in range(len(vals))]
                    ax.scatter([x0 + o for o in offs], vals, s=12, color=f"C{i % 10}",
                               label=None if L in ax.get_legend_handles_labels()[1] else L)
                    ax.hlines(c["mean"], x0 - width * 0.4, x0 + width * 0.4, color=f"C{i % 10}", lw=2)
        ax.axhline(0.0, color="0.4", lw=1, ls="--")
        ax.set_xticks(range(len(a["cells"])))
        ax.set_xticklabels([cell_short(x["cell"]) for x in a["cells"]], fontsize=7)
        ax.set_title(f"{label}: learned − best control" + (" (%)" if metric is None else ""), fontsize=9)
        ax.grid(alpha=0.3)
    for p in range(len(panels), nrows * cols):
        axes[p // cols][p % cols].axis("off")
    handles, labels = axes[0][0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="lower right", fontsize=8)
    fig.suptitle("Per-seed paired differences against each cell's best control (bar: mean)")
    fig.tight_layout()
    fig.savefig(path, dpi=80, metadata={"Software": None})
    plt.close(fig)


FIGURES = [("speed_ratio.png", draw_speed_ratio, "speed ratio to the best control per cell, per learned arm, "
            "with the span of the two 95 % intervals (`results/speed_ratio.csv`)"),
           ("paired_seeds.png", draw_paired_seeds, "every seed's paired difference against the cell's best "
            "control, per metric (`results/paired_seeds.csv`)")]


# --- the page ------------------------------------------------------------------------------

def command_line(folder, out_dir):
    cmd = f"/usr/bin/python3 tools/trial_results.py {shown_path(folder)}"
    if pathlib.Path(out_dir).resolve() != (ROOT / "docs").resolve():
        cmd += f" --out {shown_path(out_dir)}"
    return cmd


def generate(folder, out_dir):
    """{relative path: text} of the page and its CSVs, and the analysis (for the figures)."""
    rows, files, settings = read_trial(folder, out_dir)
    name_own_demand(settings)  # for the page's cell names and the figures drawn after it
    registry = load_registry()
    a = analyse(rows, settings, registry)
    page = ["# Results of the fair trial", "",
            f"<!-- Generated by tools/trial_results.py from {shown_path(folder)}; do not edit: run "
            f"`{command_line(folder, out_dir)}` (`--check` tells whether this page is current). -->", "",
            "Learned arms against non-learned controls on the same seeds, demands and PRs. Every number "
            "and every word of judgement on this page is computed from the trial's rows by the generator, "
            "except the section on what was tried, which says where its words come from."]
    page += [""] + what_was_run(rows, files, settings, folder, a)
    page += mechanism_section(a, registry, settings)
    page += per_cell_section(a)
    page += paired_section(a)
    fed = analyse_federation(rows, settings, a)
    page += federation_section(fed)
    var = analyse_variants(rows, settings, a)
    page += variants_section(var)
    tr = analyse_trainings(rows, settings, a)
    page += trainings_section(tr)
    shipped = shipped_variants(settings)
    as_run = analyse(as_shipped(rows, shipped), settings, registry) if shipped else a
    targets = analyse_targets(as_run, fed, settings, shipped)
    page += targets_section(targets)
    page += approaches_section(approaches(settings))
    page += reading_section(a)
    page += ["", "## Figures", ""]
    for name, _, what in FIGURES:
        page += [f"![{name}](results/{name})", "", f"{what}.", ""]
    page += ["CSVs in `results/`: `cells.csv` (every arm's numbers per cell), `paired.csv` (every "
             "comparison), `paired_seeds.csv` and `speed_ratio.csv` (the figures' numbers)."]
    texts = {"RESULTS.md": "\n".join(page) + "\n", "results/cells.csv": cells_csv(a),
             "results/paired.csv": paired_csv(a), "results/paired_seeds.csv": paired_seeds_csv(a),
             "results/speed_ratio.csv": speed_ratio_csv(a)}
    if fed:
        texts["results/federation.csv"] = federation_csv(fed)
    if var:
        texts["results/variants.csv"] = variants_csv(var)
    if tr:
        texts["results/trainings.csv"] = trainings_csv(tr)
    if targets:
        texts["results/targets.csv"] = targets_csv(targets)
    return texts, a


def write(folder, out_dir):
    out_dir = pathlib.Path(out_dir)
    texts, a = generate(folder, out_dir)
    (out_dir / "results").mkdir(parents=True, exist_ok=True)
    wanted = set(texts) | {f"results/{n}" for n, _, _ in FIGURES}
    for old in sorted((out_dir / "results").glob("*")):
        if old.suffix in (".csv", ".png") and f"results/{old.name}" not in wanted:
            old.unlink()
    for rel, text in texts.items():
        (out_dir / rel).write_text(text)
    for name, draw, _ in FIGURES:
        draw(a, out_dir / "results" / name)
    return sorted(wanted)


def check(folder, out_dir):
    """None when the committed page and CSVs are what the folder gives (and every figure
    exists), else the first difference, in words."""
    out_dir = pathlib.Path(out_dir)
    texts, _ = generate(folder, out_dir)
    for rel in sorted(texts, key=lambda r: (r != "RESULTS.md", r)):
        f = out_dir / rel
        if not f.exists():
            return f"{shown_path(f)} is missing"
        have, want = f.read_text().splitlines(), texts[rel].splitlines()
        for i, (h, w) in enumerate(zip(have, want)):
            if h != w:
                return f"{shown_path(f)} line {i + 1} differs:\n  committed:   {h}\n  regenerated: {w}"
        if len(have) != len(want):
            i = min(len(have), len(want))
            return (f"{shown_path(f)} has {len(have)} lines, regenerated {len(want)}; first extra line "
                    f"{i + 1}: {(have if len(have) > len(want) else want)[i]}")
    for name, _, _ in FIGURES:
        if not (out_dir / "results" / name).exists():
            return f"{shown_path(out_dir / 'results' / name)} is missing"
    wanted = {pathlib.PurePath(r).name for r in texts} | {n for n, _, _ in FIGURES}
    for f in sorted((out_dir / "results").glob("*")):
        if f.suffix in (".csv", ".png") and f.name not in wanted:
            return f"{shown_path(f)} is not generated by the trial (a stale file)"
    return None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", help="the trial's results: *.csv (results.csv of ./palcas experiment) and trial.json")
    ap.add_argument("--out", default=str(ROOT / "docs"), help="RESULTS.md and results/ go here (default docs)")
    ap.add_argument("--check", action="store_true", help="compare with the committed page; write nothing")
    a = ap.parse_args(argv)
    try:
        if a.check:
            diff = check(a.folder, a.out)
            if diff:
                print(f"trial_results --check: {diff}\n(regenerate: {command_line(a.folder, a.out)})", file=sys.stderr)
                return 1
            print(f"trial_results --check: {shown_path(pathlib.Path(a.out) / 'RESULTS.md')} is current")
            return 0
        written = write(a.folder, a.out)
    except (TrialError, seed_sets.SeedSetError, OSError) as e:
        print(f"trial_results: {e}", file=sys.stderr)
        return 2
    print(f"trial_results: {len(written)} files in {shown_path(a.out)}: " + ", ".join(written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
