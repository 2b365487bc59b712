#!/usr/bin/env python3
"""Where a run's CAV lane changes go: per route, how many each CAV made on the mainline, how
many its route needed, which way they went and how many were undone soon after.

  /usr/bin/python3 tools/lane_change_breakdown.py RUN_DIR [RUN_DIR ...] [--undone-within S] [--csv FILE]

RUN_DIR: a run's arm folder holding trajectories.csv (./palcas run or an experiment point,
recorded once per simulated second). A lane change is a CAV's lane index changing between two
samples on the same part of the road (mainline; the merge from the acceleration lane is not
one). Lower lane indices are nearer the off-ramps; the exit lane is the mainline lane exit-bound
CAVs leave it from (the run's most common). An exit-bound CAV (route *_exit) needs, at least, as
many changes towards the exit as lanes between the one it first appears in on the mainline and
the exit lane; a through CAV needs none. Each change is *towards the exit* (exit-bound, to a lower lane),
*away from the exit* (exit-bound, to a higher lane) or *through* (a through CAV's), and
*undone* when the same CAV changes back to the lane it left within --undone-within simulated
seconds (default 30). With a 1 s record a double change inside one second counts once (the
count is within 1 % of the bridge's own cav_lane_changes on the paper road)."""
import argparse
import collections
import csv
import pathlib
import sys


class BreakdownError(Exception):
    pass


COLUMNS = ("time_s", "vehicle", "cav", "route", "part", "lane")


def read_tracks(path):
    """{vehicle: (route, [(time, part, lane)])} of the CAVs in a trajectories.csv, in time order."""
    tracks = {}
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                raise BreakdownError(f"{path}: not a PALCAS trajectories.csv (no column {', '.join(missing)})")
            for n, r in enumerate(reader, start=2):
                if r["cav"] != "1":
                    continue
                try:
                    sample = (float(r["time_s"]), r["part"], int(r["lane"]))
                except (TypeError, ValueError):
                    raise BreakdownError(f"{path} line {n}: time_s {r['time_s']!r} or lane {r['lane']!r} is not a "
                                         f"number (a cut-off file?)")
                tracks.setdefault(r["vehicle"], (r["route"], []))[1].append(sample)
    except OSError as e:
        raise BreakdownError(f"{path}: {e.strerror}")
    for _, samples in tracks.values():
        samples.sort()
    return tracks


def exit_lane(tracks):
    """The mainline lane exit-bound CAVs leave it from (the most common last mainline lane of
    those that reached an off-ramp); 0 when none did."""
    last = collections.Counter()
    for route, samples in tracks.values():
        main = [s for s in samples if s[1] == "mainline"]
        if route.endswith("_exit") and main and any(s[1] == "off_ramp" for s in samples):
            last[main[-1][2]] += 1
    return last.most_common(1)[0][0] if last else 0


def breakdown(tracks, undone_within=30.0):
    """{route: counts} and the totals under "all": cavs, changes, needed, towards, away,
    through, undone."""
    out = collections.defaultdict(collections.Counter)
    lowest = exit_lane(tracks)
    for route, samples in tracks.values():
        exit_bound = route.endswith("_exit")
        c = out[route]
        c["cavs"] += 1
        main = [s for s in samples if s[1] == "mainline"]
        if exit_bound and main:
            c["needed"] += max(0, main[0][2] - lowest)
        changes = [(b[0], a[2], b[2]) for a, b in zip(samples, samples[1:]) if a[1] == b[1] == "mainline"
                   and a[2] != b[2]]
        for i, (t, src, dst) in enumerate(changes):
            c["changes"] += 1
            if not exit_bound:
                c["through"] += 1
            elif dst < src:
                c["towards"] += 1
            else:
                c["away"] += 1
            later = changes[i + 1] if i + 1 < len(changes) else None
            if later and later[2] == src and later[0] - t <= undone_within:
                c["undone"] += 1
    total = collections.Counter()
    for c in out.values():
        total.update(c)
    result = {route: dict(c) for route, c in sorted(out.items())}
    result["all"] = dict(total)
    return result


FIELDS = ["cavs", "changes", "needed", "towards", "away", "through", "undone"]


def table(runs):
    head = ["run", "route", "CAVs", "changes per CAV", "needed per CAV", "towards the exit", "away from the exit",
            "through CAVs'", "undone"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for name, b in runs:
        for route, c in b.items():
            n = c.get("cavs", 0) or 1
            lines.append("| " + " | ".join([name, route, str(c.get("cavs", 0)),
                                             f"{c.get('changes', 0) / n:.2f}", f"{c.get('needed', 0) / n:.2f}"]
                                            + [str(c.get(k, 0)) for k in ("towards", "away", "through", "undone")]) + " |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="folders holding trajectories.csv")
    ap.add_argument("--undone-within", type=float, default=30.0, help="simulated seconds (default 30)")
    ap.add_argument("--csv", help="also write the counts here")
    a = ap.parse_args(argv)
    if not a.undone_within > 0:
        print(f"lane_change_breakdown: --undone-within must be > 0 s, got {a.undone_within}", file=sys.stderr)
        return 2
    runs = []
    try:
        for run in a.runs:
            path = pathlib.Path(run) / "trajectories.csv"
            if not path.exists():
                raise BreakdownError(f"{run}: no trajectories.csv (a run recorded with --no-trajectories?)")
            runs.append((run, breakdown(read_tracks(path), a.undone_within)))
    except BreakdownError as e:
        print(f"lane_change_breakdown: {e}", file=sys.stderr)
        return 2
    print(table(runs))
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(["run", "route"] + FIELDS)
            for name, b in runs:
                for route, c in b.items():
                    w.writerow([name, route] + [c.get(k, 0) for k in FIELDS])
    return 0


if __name__ == "__main__":
    sys.exit(main())
