#!/usr/bin/env python3
"""Where discomfort comes from: the share of CAV samples with |a| > a_th (1.47 m/s^2) by what
drove the CAV at that moment, per arm of a recorded run (trajectories.csv).

usage: comfort_breakdown.py RUN_DIR [--threshold A]   (RUN_DIR holds <arm>/trajectories.csv)

Rows: an advised lane change under way, an ACCELERATE command holding, the CAV's own car
following (no command); for SUMO-native every CAV sample is its own driving. Prints a
Markdown table: samples, share of all CAV samples, share of them uncomfortable, and the
share of them braking harder than -a_th."""
import argparse
import csv
import pathlib


def state_of(row):
    if int(row["lane_change_target"]) > 0:
        return "advised lane change under way"
    if row["command"] == "accelerate":
        return "ACCELERATE holding"
    if row["command"] == "keep_speed":
        return "speed frozen (paper actuation)"
    return "own car following"


def breakdown(path, threshold):
    counts = {}
    total = 0
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["cav"] != "1":
                continue
            a = float(row["accel_mps2"])
            c = counts.setdefault(state_of(row), [0, 0, 0])
            c[0] += 1
            c[1] += abs(a) > threshold
            c[2] += a < -threshold
            total += 1
    return counts, total


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir")
    ap.add_argument("--threshold", type=float, default=1.47)
    a = ap.parse_args()
    files = sorted(pathlib.Path(a.run_dir).glob("*/trajectories.csv"))
    if not files:
        raise SystemExit(f"comfort_breakdown: no <arm>/trajectories.csv under {a.run_dir}")
    print("| arm | CAV state | samples | share of samples (%) | uncomfortable (%) | braking < -a_th (%) |")
    print("|---|---|---|---|---|---|")
    for f in files:
        counts, total = breakdown(f, a.threshold)
        unc = sum(c[1] for c in counts.values())
        for state, (n, u, b) in sorted(counts.items(), key=lambda kv: -kv[1][0]):
            print(f"| {f.parent.name} | {state} | {n} | {100 * n / total:.1f} | {100 * u / n:.1f} | {100 * b / n:.1f} |")
        print(f"| {f.parent.name} | **all** | {total} | 100 | {100 * unc / total:.1f} | |")


if __name__ == "__main__":
    main()
