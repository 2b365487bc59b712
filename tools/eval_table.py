#!/usr/bin/env python3
"""Mean and 95 % interval over evaluation seeds, per arm, from ./palcas run folders.

usage: eval_table.py RUN_DIR [RUN_DIR ...]   (each holds <arm>/metrics.json)

Prints a Markdown table: one row per metric, one column per arm, "mean ± half-width" of
the two-sided 95 % Student-t interval over the runs (one run per seed)."""
import json
import math
import pathlib
import sys

METRICS = [
    ("dsr_pct", "DSR (%)", 1),
    ("msr_pct", "MSR (%)", 1),
    ("collision_rate_pct", "CR (%)", 2),
    ("efficiency_all_mps", "efficiency, all (m/s)", 2),
    ("efficiency_cav_mps", "efficiency, CAVs (m/s)", 2),
    ("comfort_share_pct", "comfort share (%)", 1),
    ("decision_ms_p99", "decision p99 (ms)", 2),
    ("lane_changes_dropped", "advised lane changes dropped", 0),
    ("real_time_factor", "real-time factor", 1),
]
# Two-sided 95 % Student-t quantiles by degrees of freedom.
T95 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262}


def interval(values):
    n = len(values)
    mean = sum(values) / n
    if n < 2:
        return mean, float("nan")
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))
    return mean, T95.get(n - 1, 1.96) * sd / math.sqrt(n)


def main(dirs):
    runs = [pathlib.Path(d) for d in dirs]
    arms = []
    for r in runs:
        for m in sorted(r.glob("*/metrics.json")):
            if m.parent.name not in arms:
                arms.append(m.parent.name)
    order = [a for a in ("palcas", "keep", "sumo_native") if a in arms] + [a for a in arms if a not in ("palcas", "keep", "sumo_native")]
    print("| metric | " + " | ".join(order) + " |")
    print("|---|" + "---|" * len(order))
    for key, label, digits in METRICS:
        cells = []
        for arm in order:
            vals = []
            for r in runs:
                f = r / arm / "metrics.json"
                if f.exists():
                    v = json.loads(f.read_text()).get(key)
                    if isinstance(v, (int, float)) and math.isfinite(v):
                        vals.append(float(v))
            if not vals:
                cells.append("n/a")
                continue
            mean, half = interval(vals)
            cells.append(f"{mean:.{digits}f} ± {half:.{digits}f}" if math.isfinite(half) else f"{mean:.{digits}f}")
        print(f"| {label} | " + " | ".join(cells) + " |")
    print(f"\n{len(runs)} evaluation run(s): " + ", ".join(r.name for r in runs))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
