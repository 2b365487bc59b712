#!/usr/bin/python3
"""Learning curves of a training run: merges the bridge's episodes.csv (traffic metrics per
episode) with every RSU's learning.csv (reward, epsilon, losses per episode) into
learning_curves.csv and draws learning_curves.png.

    learning_curves.py RUN_DIR
"""
import csv
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import policy_folder  # noqa: E402

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def number(row, key):
    try:
        value = float(row[key])
    except (KeyError, TypeError, ValueError):
        return math.nan
    return value


def main(run_dir):
    run = pathlib.Path(run_dir)
    episodes = read(run / policy_folder.EPISODES)
    rsu_logs = {p.parent.name: read(p) for p in policy_folder.learning_logs(run)}
    merged = []
    for i, ep in enumerate(episodes):
        row = {k: ep[k] for k in ("episode", "efficiency_all_mps", "collision_rate_pct", "dsr_pct",
                                   "msr_pct", "comfort_share_pct", "advisories_rejected")}
        rewards, eps = [], []
        for log in rsu_logs.values():
            if i < len(log):
                rewards.append(number(log[i], "mean_reward"))
                eps.append(number(log[i], "epsilon"))
        good = [r for r in rewards if not math.isnan(r)]
        row["mean_reward"] = sum(good) / len(good) if good else math.nan
        row["epsilon"] = sum(eps) / len(eps) if eps else math.nan
        merged.append(row)
    out_csv = run / "learning_curves.csv"
    with open(out_csv, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(merged[0].keys()) if merged else ["episode"])
        writer.writeheader()
        writer.writerows(merged)
    x = [int(r["episode"]) + 1 for r in merged]
    panels = [("mean_reward", "mean per-CAV reward"), ("dsr_pct", "DSR (%)"), ("msr_pct", "MSR (%)"),
              ("collision_rate_pct", "CR (%)"), ("efficiency_all_mps", "mean speed (m/s)"),
              ("epsilon", "epsilon")]
    fig, axes = plt.subplots(2, 3, figsize=(13, 6.5))
    for ax, (key, label) in zip(axes.flat, panels):
        ax.plot(x, [float(r[key]) for r in merged], marker="o")
        ax.set_title(label)
        ax.set_xlabel("episode")
        ax.grid(alpha=0.3)
    fig.suptitle("PALCAS training: %s" % run.name)
    fig.tight_layout()
    out_png = run / "learning_curves.png"
    fig.savefig(out_png, dpi=110)
    print("learning curves: %s, %s" % (out_csv, out_png))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
