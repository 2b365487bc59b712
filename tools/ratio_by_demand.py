#!/usr/bin/env python3
"""Speed of each arm over SUMO-native's on the same seed, against demand: one panel per PR.

usage: ratio_by_demand.py --out PNG --native CSV [--native CSV ...] LABEL=CSV[,CSV...] ...

Every LABEL=CSV list is a setting (e.g. "with the option", "without"); its ./palcas experiment
results.csv rows (any arm but sumo_native) are paired with the sumo_native row of the same PR,
demand and seed from the --native CSVs. A line per (setting, arm) gives the mean ratio over
the seeds at each demand, the bar its worst and best seed; the first setting's lines are
solid, the next dotted. Grey lines at 1 (SUMO-native) and, dashed, 0.95 / 1.05 (issue 18's
worst-seed and capacity bounds). Also prints the points as CSV.
"""
import argparse
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path, newline="") as f:
        return [r for r in csv.DictReader(f) if r.get("status", "done") == "done"]


def key(r):
    return float(r["pr"]), float(r["demand"]), int(r["seed"])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True)
    p.add_argument("--native", action="append", required=True, metavar="CSV")
    p.add_argument("settings", nargs="+", metavar="LABEL=CSV[,CSV...]")
    a = p.parse_args(argv)
    native = {key(r): float(r["efficiency_all_mps"]) for path in a.native for r in rows(path)
              if r["arm"] == "sumo_native"}
    ratios = defaultdict(list)  # (label, arm, pr, demand) -> [ratio]
    line_style = {}  # a setting's line: the first solid, the next dotted, dashed, ...
    for setting in a.settings:
        label, _, paths = setting.partition("=")
        line_style[label] = ("-", ":", "--", "-.")[len(line_style) % 4]
        if not paths:
            sys.exit(f"ratio_by_demand: '{setting}' is not LABEL=CSV")
        for path in paths.split(","):
            for r in rows(path):
                if r["arm"] == "sumo_native" or key(r) not in native:
                    continue
                pr, demand, _ = key(r)
                ratios[(label, r["arm"], pr, demand)].append(float(r["efficiency_all_mps"]) / native[key(r)])
    if not ratios:
        sys.exit("ratio_by_demand: no point has a SUMO-native row on the same PR, demand and seed")
    prs = sorted({k[2] for k in ratios}, reverse=True)
    fig, axes = plt.subplots(1, len(prs), figsize=(6 * len(prs), 4.2), sharey=True, squeeze=False)
    print("setting,arm,pr,demand,seeds,mean,worst,best")
    for ax, pr in zip(axes[0], prs):
        lines = sorted({(k[0], k[1]) for k in ratios if k[2] == pr})
        for i, (label, arm) in enumerate(lines):
            pts = sorted((k[3], v) for k, v in ratios.items() if k[:3] == (label, arm, pr))
            xs = [d + (i - (len(lines) - 1) / 2) * 25 for d, _ in pts]  # side by side
            means = [sum(v) / len(v) for _, v in pts]
            low = [m - min(v) for m, (_, v) in zip(means, pts)]
            high = [max(v) - m for m, (_, v) in zip(means, pts)]
            ax.errorbar(xs, means, yerr=[low, high], marker="o", capsize=3,
                        linestyle=line_style[label], label=f"{arm}, {label}")
            for (d, v), m in zip(pts, means):
                print(f"{label},{arm},{pr:g},{d:g},{len(v)},{m:.4f},{min(v):.4f},{max(v):.4f}")
        for y, style in ((1.0, "-"), (0.95, "--"), (1.05, "--")):
            ax.axhline(y, color="grey", linestyle=style, linewidth=0.8)
        ax.set_title(f"PR {pr:g} %")
        ax.set_xlabel("mainline demand [veh/h per lane]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("speed / SUMO-native's on the same seed")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)


if __name__ == "__main__":
    main()
