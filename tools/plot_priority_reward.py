#!/usr/bin/env python3
"""Draw the paper's priority lane-change reward r_lc = u*w + p_stage over distance to exit
and lane, by feeding a grid of CAV situations through the palcas_reward inspector.

usage: plot_priority_reward.py --inspector PATH --out FILE.png [--speed MPS]
                               [--lanes L] [--max-distance M] [--param name=value ...]

The target lane is free (no target leader / follower, so the feasibility p = 1), the CAV
has no neighbours and drives at --speed; only distance_to_exit and lane vary. Runs on the
system Python (numpy, matplotlib, Agg backend).
"""
import argparse
import json
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def situation(distance, lane, lanes, speed):
    return {"v": speed, "a": 0.0, "lane": lane, "num_lanes": lanes, "length": 5.0,
            "distance_to_exit": distance, "lead": None, "follow": None, "lateral": None,
            "target_lead": None, "target_follow": None, "cluster_mean_speed": speed,
            "accel_lane": None}


def number(value):
    """The inspector prints +inf as the string "inf"."""
    return float(value) if value is not None else float("nan")


def run_inspector(inspector, params, rows):
    cmd = [inspector]
    for p in params:
        cmd += ["--param", p]
    text = "\n".join(json.dumps(r) for r in rows) + "\n"
    proc = subprocess.run(cmd, input=text, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit("palcas_reward failed (%d): %s" % (proc.returncode, proc.stderr.strip()))
    return [json.loads(line) for line in proc.stdout.splitlines()]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--inspector", required=True, help="path to the palcas_reward binary")
    ap.add_argument("--out", required=True, help="PNG file to write")
    ap.add_argument("--speed", type=float, default=25.0, help="ego speed [m/s] (default 25)")
    ap.add_argument("--lanes", type=int, default=5, help="number of lanes L (default 5)")
    ap.add_argument("--max-distance", type=float, default=3000.0, help="[m] (default 3000)")
    ap.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                    help="reward constant override, passed to the inspector (repeatable)")
    args = ap.parse_args()

    distances = np.linspace(0.0, args.max_distance, 241)
    lanes = list(range(1, args.lanes + 1))
    rows = [situation(float(d), lane, args.lanes, args.speed) for lane in lanes for d in distances]
    out = run_inspector(args.inspector, args.param, rows)
    shape = (len(lanes), len(distances))
    grid = {k: np.array([number(o[k]) for o in out]).reshape(shape) for k in ("r_lc", "u", "w", "p_stage")}
    uw = grid["u"] * grid["w"]

    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5), constrained_layout=True)
    ax = axes[0, 0]
    lim = max(1e-9, np.nanmax(np.abs(grid["r_lc"])))
    im = ax.pcolormesh(distances, np.array(lanes), grid["r_lc"], cmap="RdBu", vmin=-lim, vmax=lim,
                       shading="nearest")
    fig.colorbar(im, ax=ax, label="r_lc")
    ax.set_yticks(lanes)
    ax.set_xlabel("distance to exit d [m]")
    ax.set_ylabel("lane (1 = exit lane, rightmost)")
    ax.set_title("r_lc = u w + p_stage")
    for ax, key, title in ((axes[0, 1], "r_lc", "r_lc per lane"),
                           (axes[1, 0], None, "urgency u w per lane"),
                           (axes[1, 1], "p_stage", "staging penalty p_stage per lane")):
        values = uw if key is None else grid[key]
        for i, lane in enumerate(lanes):
            ax.plot(distances, values[i], label="lane %d" % lane)
        ax.axhline(0.0, color="grey", lw=0.5)
        ax.set_xlabel("distance to exit d [m]")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    overrides = (", " + ", ".join(args.param)) if args.param else ""
    fig.suptitle("Priority lane-change reward, v = %.1f m/s, free target lane (p = 1), L = %d%s"
                 % (args.speed, args.lanes, overrides))
    fig.savefig(args.out, dpi=110)
    print(args.out)


if __name__ == "__main__":
    main()
