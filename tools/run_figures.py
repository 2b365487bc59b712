#!/usr/bin/env python3
"""The paper's figures from what a run records (trajectories.csv, decisions.csv,
episodes.csv): no simulation is rerun. Every figure is a PNG with the CSV behind it.

usage: run_figures.py RUN_DIR --out DIR
  RUN_DIR holds one folder per arm (<arm>/trajectories.csv ...), as ./palcas run writes it.
  Learning curves come from each learning arm's training record (policies/<arm>/ or
  the policy a run names in its metrics.json).

Figures:
  speed_over_time      mean speed of the vehicles on the mainline over time, a line per arm
  space_time_<arm>     speed over x along the mainline and time, per arm
  accel_profiles       acceleration of the same CAV on each of the four routes, per arm,
                       with the comfort band +/- a_th
  lane_trajectories    lane over x of those same CAVs
  decision_cdf_<arm>   decision-time CDF per RSU, p50 / p90 / p99 marked
  learning_curves      every learning arm's training curves on one page
"""
import csv
import json
import math
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import policy_folder  # noqa: E402
from palcas_arms import sort_arms  # noqa: E402

COMFORT_MPS2 = 1.47  # a_th, paper "Driving Comfort"
ROUTES = ("main_through", "main_exit", "ramp_through", "ramp_exit")
ROUTE_TITLES = {"main_through": "mainline -> mainline", "main_exit": "mainline -> off-ramp",
                "ramp_through": "on-ramp -> mainline", "ramp_exit": "on-ramp -> off-ramp"}
ON_MAINLINE = ("mainline", "accel_lane")


def read_trajectories(path):
    """Columns of trajectories.csv as numpy arrays (strings stay strings)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{path}: no samples")
    cols = {}
    for key in rows[0]:
        vals = [r[key] for r in rows]
        try:
            cols[key] = np.array(vals, dtype=float)
        except ValueError:
            cols[key] = np.array(vals, dtype=object)
    return cols


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def save(fig, prefix):
    fig.tight_layout()
    fig.savefig(f"{prefix}.png", dpi=110)
    plt.close(fig)


def speed_over_time(trajs, prefix, bin_s=30.0):
    """Mean speed of the vehicles on the mainline per time bin, one line per arm."""
    series = {}
    for arm, t in trajs.items():
        on = np.isin(t["part"], ON_MAINLINE)
        b = np.floor(t["time_s"][on] / bin_s).astype(int)
        sums = np.bincount(b, weights=t["speed_mps"][on])
        counts = np.bincount(b)
        series[arm] = {int(i): sums[i] / counts[i] for i in range(len(counts)) if counts[i] > 0}
    bins = sorted({i for s in series.values() for i in s})
    arms = sort_arms(series)
    write_csv(f"{prefix}.csv", ["time_s"] + [f"{a}_mps" for a in arms],
              [[(i + 0.5) * bin_s] + [round(series[a].get(i, float("nan")), 3) for a in arms] for i in bins])
    fig, ax = plt.subplots(figsize=(8, 4))
    for a in arms:
        ks = sorted(series[a])
        ax.plot([(k + 0.5) * bin_s for k in ks], [series[a][k] for k in ks], label=a)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"mean speed on the mainline (m/s, {bin_s:g} s bins)")
    ax.grid(alpha=0.3)
    ax.legend()
    save(fig, prefix)


def space_time(t, arm, prefix, dx_m=50.0, dt_s=10.0):
    """Mean speed per (time bin, x bin) of the vehicles on the mainline."""
    on = np.isin(t["part"], ON_MAINLINE)
    x, tt, v = t["x_m"][on], t["time_s"][on], t["speed_mps"][on]
    nx = int(math.ceil((x.max() + 1e-9) / dx_m))
    nt = int(math.ceil((tt.max() + 1e-9) / dt_s))
    ix = np.clip((x / dx_m).astype(int), 0, nx - 1)
    it = np.clip((tt / dt_s).astype(int), 0, nt - 1)
    flat = it * nx + ix
    sums = np.bincount(flat, weights=v, minlength=nt * nx)
    counts = np.bincount(flat, minlength=nt * nx)
    mean = np.full(nt * nx, np.nan)
    mean[counts > 0] = sums[counts > 0] / counts[counts > 0]
    grid = mean.reshape(nt, nx)
    write_csv(f"{prefix}.csv", ["time_start_s", "x_start_m", "mean_speed_mps", "samples"],
              [[i // nx * dt_s, i % nx * dx_m, round(mean[i], 3), int(counts[i])]
               for i in range(nt * nx) if counts[i] > 0])
    fig, ax = plt.subplots(figsize=(8, 4.5))
    mesh = ax.pcolormesh(np.arange(nx + 1) * dx_m, np.arange(nt + 1) * dt_s, grid,
                         cmap="RdYlGn", vmin=0, vmax=35, shading="flat")
    fig.colorbar(mesh, ax=ax, label="speed (m/s)")
    ax.set_xlabel("x along the mainline (m)")
    ax.set_ylabel("time (s)")
    ax.set_title(f"{arm}: speed over space and time")
    save(fig, prefix)


def pick_vehicles(trajs):
    """Per route, the CAV seen longest in every arm (same seed = same vehicle ids): the same
    vehicle under each arm, as the paper compares them."""
    picks = {}
    arms = list(trajs)
    for route in ROUTES:
        best = None
        per_arm = []
        for a in arms:
            t = trajs[a]
            sel = (t["cav"] == 1) & (t["route"] == route)
            ids, counts = np.unique(t["vehicle"][sel], return_counts=True)
            per_arm.append(dict(zip(ids, counts)))
        common = set(per_arm[0]).intersection(*per_arm[1:]) if per_arm else set()
        for vid in sorted(common):
            score = min(c[vid] for c in per_arm)
            if best is None or score > best[0]:
                best = (score, vid)
        if best:
            picks[route] = best[1]
    return picks


def vehicle_track(t, vid):
    sel = t["vehicle"] == vid
    order = np.argsort(t["time_s"][sel])
    return {k: t[k][sel][order] for k in ("time_s", "x_m", "lane", "accel_mps2", "part")}


def accel_and_lanes(trajs, prefix_accel, prefix_lanes):
    picks = pick_vehicles(trajs)
    arms = sort_arms(trajs)
    rows = []
    fig_a, axes_a = plt.subplots(2, 2, figsize=(10, 6.5), squeeze=False)
    fig_l, axes_l = plt.subplots(2, 2, figsize=(10, 6.5), squeeze=False)
    for k, route in enumerate(ROUTES):
        ax_a, ax_l = axes_a[k // 2][k % 2], axes_l[k // 2][k % 2]
        ax_a.set_title(ROUTE_TITLES[route], fontsize=10)
        ax_l.set_title(ROUTE_TITLES[route], fontsize=10)
        if route not in picks:
            ax_a.text(0.5, 0.5, "no CAV on this route in every arm", ha="center", transform=ax_a.transAxes)
            ax_l.text(0.5, 0.5, "no CAV on this route in every arm", ha="center", transform=ax_l.transAxes)
            continue
        vid = picks[route]
        for a in arms:
            tr = vehicle_track(trajs[a], vid)
            rel = tr["time_s"] - tr["time_s"][0]
            ax_a.plot(rel, tr["accel_mps2"], label=a, lw=1)
            on = tr["lane"] > 0
            ax_l.step(tr["x_m"][on], tr["lane"][on], where="post", label=a, lw=1.2)
            rows += [[route, vid, a, round(r, 2), round(x, 1), int(l), round(acc, 3)]
                     for r, x, l, acc in zip(rel, tr["x_m"], tr["lane"], tr["accel_mps2"])]
        ax_a.axhspan(-COMFORT_MPS2, COMFORT_MPS2, color="green", alpha=0.12, label=f"|a| <= {COMFORT_MPS2}")
        ax_a.set_xlabel(f"time since departure (s), CAV {vid}")
        ax_a.set_ylabel("acceleration (m/s²)")
        ax_l.set_xlabel(f"x along the mainline (m), CAV {vid}")
        ax_l.set_ylabel("lane (1 = rightmost)")
        ax_l.yaxis.get_major_locator().set_params(integer=True)
    axes_a[0][0].legend(fontsize=8)
    axes_l[0][0].legend(fontsize=8)
    write_csv(f"{prefix_accel}.csv", ["route", "vehicle", "arm", "time_since_departure_s", "x_m", "lane",
                                      "accel_mps2"], rows)
    write_csv(f"{prefix_lanes}.csv", ["route", "vehicle", "arm", "x_m", "lane"],
              [[r[0], r[1], r[2], r[4], r[5]] for r in rows if r[5] > 0])
    save(fig_a, prefix_accel)
    save(fig_l, prefix_lanes)
    return picks


def decision_cdf(path, arm, prefix):
    by_rsu = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            by_rsu.setdefault(r["rsu"], []).append(float(r["decision_ms"]))
    if not by_rsu:
        return False
    fig, ax = plt.subplots(figsize=(7, 4))
    rows = []
    for rsu in sorted(by_rsu):
        v = np.sort(np.array(by_rsu[rsu]))
        p = {q: float(np.percentile(v, q)) for q in (50, 90, 99)}
        line, = ax.plot(v, np.arange(1, len(v) + 1) / len(v), label=f"{rsu} (p99 {p[99]:.2f} ms)")
        for q, val in p.items():
            ax.axvline(val, color=line.get_color(), ls=":", lw=0.8)
            ax.text(val, 0.02 + 0.05 * (q == 90) + 0.1 * (q == 99), f"p{q}", color=line.get_color(), fontsize=7)
        rows.append([rsu, len(v), round(p[50], 4), round(p[90], 4), round(p[99], 4), round(float(v.max()), 4)])
    ax.set_xscale("log")
    ax.set_xlabel("decision time (ms)")
    ax.set_ylabel("share of decisions")
    ax.set_title(f"{arm}: decision time per RSU")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, prefix)
    write_csv(f"{prefix}.csv", ["rsu", "decisions", "p50_ms", "p90_ms", "p99_ms", "max_ms"], rows)
    return True


CURVES = (("dsr_pct", "DSR (%)"), ("efficiency_all_mps", "efficiency, all (m/s)"),
          ("collision_rate_pct", "CR (%)"), ("comfort_share_pct", "comfort share (%)"))


def learning_curves(policies, prefix):
    """Per-episode training metrics of every learning arm, one page."""
    data = {}
    for arm, d in policies.items():
        f = pathlib.Path(d) / policy_folder.EPISODES
        if f.exists():
            with open(f, newline="") as fh:
                data[arm] = list(csv.DictReader(fh))
    if not data:
        return False
    fig, axes = plt.subplots(2, 2, figsize=(10, 6.5), squeeze=False)
    rows = []
    for k, (key, label) in enumerate(CURVES):
        ax = axes[k // 2][k % 2]
        for arm in sort_arms(data):
            eps = [int(r["episode"]) for r in data[arm]]
            ax.plot(eps, [float(r[key]) for r in data[arm]], marker=".", label=arm)
        ax.set_xlabel("training episode")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    for arm in sort_arms(data):
        rows += [[arm, r["episode"], r["seed"]] + [r[k] for k, _ in CURVES] for r in data[arm]]
    write_csv(f"{prefix}.csv", ["arm", "episode", "seed"] + [k for k, _ in CURVES], rows)
    save(fig, prefix)
    return True


def figures_for_run(run_dir, out_dir, policies=None):
    """Every figure the arm folders of one run support. Returns the list of PNGs written."""
    run_dir, out_dir = pathlib.Path(run_dir), pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    trajs, written = {}, []
    for f in sorted(run_dir.glob("*/trajectories.csv")):
        trajs[f.parent.name] = read_trajectories(f)
    if trajs:
        speed_over_time(trajs, str(out_dir / "speed_over_time"))
        written.append("speed_over_time")
        for arm, t in trajs.items():
            space_time(t, arm, str(out_dir / f"space_time_{arm}"))
            written.append(f"space_time_{arm}")
        accel_and_lanes(trajs, str(out_dir / "accel_profiles"), str(out_dir / "lane_trajectories"))
        written += ["accel_profiles", "lane_trajectories"]
    for f in sorted(run_dir.glob("*/decisions.csv")):
        if decision_cdf(f, f.parent.name, str(out_dir / f"decision_cdf_{f.parent.name}")):
            written.append(f"decision_cdf_{f.parent.name}")
    if policies is None:
        policies = {}
        for m in run_dir.glob("*/metrics.json"):
            pol = json.loads(m.read_text()).get("policy")
            if pol:
                policies[m.parent.name] = str(pathlib.Path(pol))
    if policies and learning_curves(policies, str(out_dir / "learning_curves")):
        written.append("learning_curves")
    return [str(out_dir / f"{w}.png") for w in written]


def main(argv):
    if len(argv) != 3 or argv[1] != "--out":
        sys.exit(__doc__)
    pngs = figures_for_run(argv[0], argv[2])
    if not pngs:
        sys.exit(f"run_figures: {argv[0]} has no <arm>/trajectories.csv or decisions.csv "
                 "(record with trajectory_period_steps > 0, as ./palcas run does)")
    print("\n".join(pngs))


if __name__ == "__main__":
    main(sys.argv[1:])
