#!/usr/bin/env python3
"""Where discomfort comes from: the share of CAV samples with |a| > a_th (1.47 m/s^2) by what
drove the CAV at that moment, per arm of a recorded run (trajectories.csv).

usage: comfort_breakdown.py RUN_DIR [--threshold A] [--by-lane-change]
       (RUN_DIR holds <arm>/trajectories.csv)

Rows: an advised lane change under way, an ACCELERATE command holding, the CAV's own car
following (no command); for SUMO-native every CAV sample is its own driving. Prints a
Markdown table: samples, share of all CAV samples, share of them uncomfortable, and the
share of them braking harder than -a_th.

--by-lane-change: rows by the time from the CAV's nearest lane change (its lane or road part
differs from its previous sample's; advised or its own), from 5 s before to 5 s after, and
the samples further from any; each row's uncomfortable samples speeding up (a > a_th) and
braking (a < -a_th) as shares of ALL CAV samples, so the rows add up to the arm's
discomfort."""
import argparse
import bisect
import collections
import csv
import pathlib

# Windows around a lane change [s]: (label, from, to), the sample's time minus the change's.
LANE_CHANGE_WINDOWS = (("5-2 s before", -5.0, -2.0), ("2-0 s before", -2.0, 0.0),
                       ("0-2 s after", 0.0, 2.0), ("2-5 s after", 2.0, 5.0))
FURTHER = "further from any lane change"


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


def window_of(offset_s):
    """Each window holds its start, not its end; the last one holds its end too."""
    for label, lo, hi in LANE_CHANGE_WINDOWS:
        if lo <= offset_s < hi:
            return label
    last_label, _, last_end = LANE_CHANGE_WINDOWS[-1]
    return last_label if offset_s == last_end else FURTHER


def by_lane_change(path, threshold):
    """{window: [samples, speeding up > a_th, braking < -a_th]}, total CAV samples."""
    tracks = collections.defaultdict(list)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["cav"] == "1":
                tracks[row["vehicle"]].append((float(row["time_s"]), row["lane"], row["part"],
                                               float(row["accel_mps2"])))
    counts = {label: [0, 0, 0] for label, _, _ in LANE_CHANGE_WINDOWS}
    counts[FURTHER] = [0, 0, 0]
    total = 0
    for track in tracks.values():
        track.sort()
        changes = [track[i][0] for i in range(1, len(track)) if track[i][1:3] != track[i - 1][1:3]]
        for t, _, _, a in track:
            i = bisect.bisect_left(changes, t)
            near = [t - changes[j] for j in (i - 1, i) if 0 <= j < len(changes)]
            c = counts[window_of(min(near, key=abs)) if near else FURTHER]
            c[0] += 1
            c[1] += a > threshold
            c[2] += a < -threshold
            total += 1
    return counts, total


def print_by_lane_change(files, threshold):
    print("| arm | time from the nearest lane change | share of samples (%) | speeding up > a_th (% of all) | braking < -a_th (% of all) |")
    print("|---|---|---|---|---|")
    for f in files:
        counts, total = by_lane_change(f, threshold)
        if total == 0:
            continue
        for label in [w[0] for w in LANE_CHANGE_WINDOWS] + [FURTHER]:
            n, up, down = counts[label]
            print(f"| {f.parent.name} | {label} | {100 * n / total:.1f} | {100 * up / total:.2f} | {100 * down / total:.2f} |")
        unc = sum(c[1] + c[2] for c in counts.values())
        print(f"| {f.parent.name} | **all** (comfort {100 - 100 * unc / total:.1f} %) | 100 | "
              f"{100 * sum(c[1] for c in counts.values()) / total:.2f} | {100 * sum(c[2] for c in counts.values()) / total:.2f} |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir")
    ap.add_argument("--threshold", type=float, default=1.47)
    ap.add_argument("--by-lane-change", action="store_true",
                    help="rows by the time from the nearest lane change instead of by command")
    a = ap.parse_args(argv)
    files = sorted(pathlib.Path(a.run_dir).glob("*/trajectories.csv"))
    if not files:
        raise SystemExit(f"comfort_breakdown: no <arm>/trajectories.csv under {a.run_dir}")
    if a.by_lane_change:
        print_by_lane_change(files, a.threshold)
        return
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
