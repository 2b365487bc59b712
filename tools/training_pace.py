#!/usr/bin/python3
"""Training pace against the simulator's own: for each training variant, the real-time factor
of a short `./palcas train` divided by that of SUMO-native evaluations of the same episodes'
traffic (same seeds, demand, PR and duration), all in one run and interleaved, so that every
variant sees the machine as the others do.

    tools/training_pace.py --out DIR [--episodes 2] [--duration 900] [--demand 1000] [--pr 60]
        [--rounds 1] --variant NAME=RSU_PARAMS_YAML ... [-- MORE TRAIN OPTIONS]

A variant's YAML is given to `./palcas train --rsu-params` ('' for none: the shipped
configuration). Training episode k runs seed 1 + k, as `./palcas train --seed 1` draws it; the
SUMO-native evaluation of seed 1 + k is `./palcas run --arm sumo_native --no-compare`. Real-
time factors come from the runs' own records (episodes.csv and metrics.json: the episode loop,
without start-up); the whole commands' wall times are printed beside them. The options every
training gets by default are the shipped policy's (see policies/palcas/train.json).

A measurement of this machine at that moment: run it when nothing else runs."""
import argparse
import csv
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHIPPED_TRAINING = ["--arm", "palcas", "--explore-fraction", "0.4",
                    "--bridge-params", "config/training/gentle_lane_changes.yaml"]


def timed(command, log_path):
    """Runs command (its output to log_path); (exit status, wall seconds)."""
    os.makedirs(os.path.dirname(log_path) or ".", exist_ok=True)
    start = time.monotonic()
    with open(log_path, "w") as log:
        status = subprocess.call(command, cwd=ROOT, stdout=log, stderr=subprocess.STDOUT)
    return status, time.monotonic() - start


def training_rtf(folder):
    """Simulated over wall seconds of a training's episodes (episodes.csv)."""
    with open(os.path.join(folder, "episodes.csv")) as f:
        rows = list(csv.DictReader(f))
    return sum(float(r["sim_seconds"]) for r in rows) / sum(float(r["wall_seconds"]) for r in rows), len(rows)


def evaluation_rtf(folders):
    """Simulated over wall seconds of evaluation runs (their metrics.json)."""
    sim = wall = 0.0
    for folder in folders:
        with open(os.path.join(folder, "sumo_native", "metrics.json")) as f:
            m = json.load(f)
        sim += float(m["sim_seconds"])
        wall += float(m["wall_seconds"])
    return sim / wall


def variant(text):
    name, sep, path = text.partition("=")
    if not sep or not name:
        raise argparse.ArgumentTypeError("--variant wants NAME=RSU_PARAMS_YAML (YAML may be empty), got %r" % text)
    if path and not os.path.isfile(os.path.join(ROOT, path)) and not os.path.isfile(path):
        raise argparse.ArgumentTypeError("--variant %s: no file %s" % (name, path))
    return name, path


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="a folder for the runs")
    ap.add_argument("--episodes", type=int, default=2, help="training episodes = evaluation seeds (default 2)")
    ap.add_argument("--duration", type=float, default=900, help="simulated seconds each (default 900)")
    ap.add_argument("--demand", type=float, default=1000, help="veh/h/lane (default 1000)")
    ap.add_argument("--pr", type=float, default=60, help="CAV share in %% (default 60)")
    ap.add_argument("--rounds", type=int, default=1, help="repeat the whole set this often (default 1)")
    ap.add_argument("--variant", type=variant, action="append", required=True, help="NAME=RSU_PARAMS_YAML")
    ap.add_argument("train", nargs=argparse.REMAINDER, help="-- then more ./palcas train options")
    args = ap.parse_args(argv)
    if args.episodes < 1 or args.rounds < 1 or args.duration <= 0:
        ap.error("--episodes, --rounds and --duration must be positive")
    extra = args.train[1:] if args.train[:1] == ["--"] else args.train
    palcas = os.path.join(ROOT, "palcas")
    common = ["--duration", "%g" % args.duration, "--demand", "%g" % args.demand, "--pr", "%g" % args.pr]
    results = {}
    for r in range(args.rounds):
        eval_folders, eval_wall = [], 0.0
        for k in range(args.episodes):
            folder = os.path.join(args.out, "round%d" % r, "sumo_native_s%d" % (1 + k))
            status, wall = timed([palcas, "run", "--arm", "sumo_native", "--no-compare", "--no-trajectories",
                                  "--seed", str(1 + k), "--out", folder] + common, folder + ".log")
            if status != 0:
                print("sumo_native seed %d: ./palcas run exited %d (%s.log)" % (1 + k, status, folder))
                return 1
            eval_folders.append(folder)
            eval_wall += wall
        native = evaluation_rtf(eval_folders)
        results.setdefault("sumo_native", []).append((native, eval_wall))
        print("round %d  sumo_native: %.1fx real time (%d runs, %.0f s whole commands)"
              % (r, native, args.episodes, eval_wall), flush=True)
        for name, path in args.variant:
            folder = os.path.join(args.out, "round%d" % r, "train_" + name)
            command = ([palcas, "train"] + SHIPPED_TRAINING + common
                       + ["--episodes", str(args.episodes), "--seed", "1", "--out", folder]
                       + (["--rsu-params", path] if path else []) + extra)
            status, wall = timed(command, folder + ".log")
            if status != 0:
                print("%s: ./palcas train exited %d (%s.log)" % (name, status, folder))
                return 1
            rtf, rows = training_rtf(folder)
            results.setdefault(name, []).append((rtf, wall))
            print("round %d  %s: %.1fx real time over %d episodes (%.0f s whole command); ÷ sumo_native %.3f"
                  % (r, name, rtf, rows, wall, rtf / native), flush=True)
    print("\n| run | real-time factor (per round) | ÷ SUMO-native (per round) | whole command s |")
    print("|---|---|---|---|")
    natives = [n for n, _ in results["sumo_native"]]
    for name, rows in results.items():
        print("| %s | %s | %s | %s |" % (
            name, " / ".join("%.1f" % x for x, _ in rows),
            " / ".join("%.3f" % (x / natives[i]) for i, (x, _) in enumerate(rows)),
            " / ".join("%.0f" % w for _, w in rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
