#!/usr/bin/python3
"""Pace of a training of K simulations against one: simulated seconds trained per wall
second for each K, and their ratio to K = 1. Runs `./palcas train --simulations K` once per K
with the same options (the RSUs in process for every K, as K > 1 runs them), each into its
own folder under --out, timing the whole command (start-up included) and reading the
episodes' own wall time from each simulation's episodes.csv (without start-up).

    tools/simulations_pace.py --out DIR [--simulations 1,2] -- TRAIN OPTIONS...
e.g.
    tools/simulations_pace.py --out /tmp/pace -- --scenario tiny --episodes 2 --duration 900 \\
        --learning config/training/tiny_fast_learning.yaml --rsu-params config/training/short_rsu.yaml

A measurement of this machine at that moment (other jobs included), not a benchmark."""
import argparse
import csv
import glob
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def episode_rows(folder):
    """Each simulation's episodes.csv rows of a training folder (one simulation: its own)."""
    files = sorted(glob.glob(os.path.join(folder, "sim*", "episodes.csv"))) or [os.path.join(folder, "episodes.csv")]
    per_simulation = []
    for path in files:
        with open(path) as f:
            per_simulation.append(list(csv.DictReader(f)))
    return per_simulation


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="a folder for the trainings (train-k<K>/ each)")
    ap.add_argument("--simulations", default="1,2", help="the K to compare, the first the reference")
    ap.add_argument("train", nargs=argparse.REMAINDER, help="-- then ./palcas train's options")
    args = ap.parse_args(argv)
    train = args.train[1:] if args.train[:1] == ["--"] else args.train
    counts = [int(k) for k in args.simulations.split(",")]
    paces = {}
    for k in counts:
        folder = os.path.join(args.out, "train-k%d" % k)
        command = [os.path.join(ROOT, "palcas"), "train", "--simulations", str(k), "--in-process",
                   "--out", folder] + train
        start = time.monotonic()
        status = subprocess.call(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall = time.monotonic() - start
        if status != 0:
            print("K=%d: ./palcas train exited %d (see %s/console.log)" % (k, status, folder))
            return 1
        per_simulation = episode_rows(folder)
        rows = [r for sim in per_simulation for r in sim]
        sim_s = sum(float(r["sim_seconds"]) for r in rows)
        # The simulations run side by side: their episodes take the slowest one's wall time.
        episode_wall = max(sum(float(r["wall_seconds"]) for r in sim) for sim in per_simulation)
        paces[k] = (sim_s / wall, sim_s / episode_wall)
        print("K=%d: %d episodes, %.0f simulated s in %.0f wall s (command) = %.2f sim-s/wall-s; "
              "episodes alone %.2f sim-s/wall-s" % (k, len(rows), sim_s, wall, paces[k][0], paces[k][1]), flush=True)
    ref = counts[0]
    for k in counts[1:]:
        print("K=%d / K=%d: %.2f (whole command), %.2f (episodes alone)"
              % (k, ref, paces[k][0] / paces[ref][0], paces[k][1] / paces[ref][1]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
