#!/usr/bin/env python3
"""The V2X robustness table: one row per channel setting, from ./palcas experiment folders.

usage: v2x_table.py BASELINE_DIR [CHANNEL_DIR ...]

BASELINE_DIR is an experiment run without --v2x that holds the learning arm, keep and
sumo_native; each CHANNEL_DIR one run with --v2x over the same seeds, PR, demand and duration.
Prints a Markdown table: per setting the learning arm's speed (mean and worst seed), its ratio
to SUMO-native on the same seed (mean and worst), DSR, MSR, CR, comfort share, decision p99,
and what became of its advisories (lost, late, out of range, too old, mean age). keep and
SUMO-native have no advice to delay or lose: their rows come from BASELINE_DIR.
"""
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from palcas_stats import format_ci, mean_ci95  # noqa: E402

LEARNING_ARM = "palcas"


def points(out):
    """{(arm, seed): metrics} of an experiment folder's finished points."""
    found = {}
    for f in sorted(pathlib.Path(out, "points").glob("*/*/metrics.json")):
        point = json.loads((f.parent.parent / "point.json").read_text())
        found[(point["arm"], point["seed"])] = json.loads(f.read_text())
    if not found:
        raise SystemExit(f"v2x_table: {out} holds no finished point (points/*/<arm>/metrics.json)")
    return found


def setting(out):
    """How the channel was set in an experiment folder, as a short label."""
    settings = json.loads(pathlib.Path(out, "experiment.json").read_text())
    if not settings.get("v2x"):
        return "off"
    v = next(iter(points(out).values()))["v2x"]
    parts = []
    for cls in ("vehicle_state", "advisory", "cluster_state"):
        c = v[cls]
        parts.append((c["latency_s"], c["jitter_s"], c["loss_probability"]))
    if len(set(parts)) == 1:
        lat, jit, loss = parts[0]
        text = f"{lat * 1000:g} ms" + (f" + U(0, {jit * 1000:g} ms)" if jit else "") + f", {loss * 100:g} % lost"
    else:
        text = "; ".join(f"{cls} {lat * 1000:g} ms {loss * 100:g} %" for cls, (lat, _, loss)
                         in zip(("states", "advice", "I2I"), parts))
    return text


def cell(values, digits, worst=None):
    mean, half = mean_ci95(values)
    text = format_ci(mean, half, digits)
    if worst:
        text += f" (worst {worst(values):.{digits}f})"
    return text


def rows(baseline, channels):
    base = points(baseline)
    seeds = sorted({s for (a, s) in base if a == "sumo_native"})
    native = {s: base[("sumo_native", s)]["efficiency_all_mps"] for s in seeds}
    out = []
    for label, found in [("off", base)] + [(setting(c), points(c)) for c in channels]:
        runs = [(s, found[(LEARNING_ARM, s)]) for s in seeds if (LEARNING_ARM, s) in found]
        if not runs:
            continue
        speed = [m["efficiency_all_mps"] for _, m in runs]
        ratio = [m["efficiency_all_mps"] / native[s] for s, m in runs]
        v2x = [m.get("v2x", {}) for _, m in runs]
        sent = sum(c.get("advisories_sent", 0) for c in v2x)
        share = lambda key: f"{100.0 * sum(c.get(key, 0) for c in v2x) / sent:.1f}" if sent else "n/a"  # noqa: E731
        age = [c.get("advice_mean_age_s", 0.0) for c in v2x]
        out.append([f"{LEARNING_ARM}, {label}", str(len(runs)), cell(speed, 2, min), cell(ratio, 3, min),
                    cell([m["dsr_pct"] for _, m in runs], 1, min), cell([m["msr_pct"] for _, m in runs], 1),
                    cell([m["collision_rate_pct"] for _, m in runs], 2),
                    cell([m["comfort_share_pct"] for _, m in runs], 1),
                    cell([m["decision_ms_p99"] for _, m in runs], 2),
                    share("advisories_lost"), share("advisories_applied_late"),
                    share("advisories_out_of_range"), share("advisories_too_old"),
                    f"{sum(age) / len(age):.2f}"])
    for arm in ("keep", "sumo_native"):
        runs = [(s, base[(arm, s)]) for s in seeds if (arm, s) in base]
        if not runs:
            continue
        speed = [m["efficiency_all_mps"] for _, m in runs]
        out.append([f"{arm} (no advice to impair)", str(len(runs)), cell(speed, 2, min),
                    cell([m["efficiency_all_mps"] / native[s] for s, m in runs], 3, min),
                    cell([m["dsr_pct"] for _, m in runs], 1, min), cell([m["msr_pct"] for _, m in runs], 1),
                    cell([m["collision_rate_pct"] for _, m in runs], 2),
                    cell([m["comfort_share_pct"] for _, m in runs], 1), "n/a", "", "", "", "", ""])
    return out


HEADER = ["channel", "seeds", "speed (m/s)", "× SUMO-native", "DSR (%)", "MSR (%)", "CR (%)", "comfort (%)",
          "decision p99 (ms)", "advice lost (%)", "late (%)", "out of range (%)", "too old (%)", "mean age (s)"]


def main(argv):
    if not argv:
        print(__doc__, file=sys.stderr)
        return 2
    table = rows(argv[0], argv[1:])
    print("| " + " | ".join(HEADER) + " |")
    print("|" + "---|" * len(HEADER))
    for r in table:
        print("| " + " | ".join(r) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
