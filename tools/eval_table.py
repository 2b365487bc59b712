#!/usr/bin/env python3
"""Mean and 95 % interval over evaluation seeds, per arm, from ./palcas run folders.

usage: eval_table.py RUN_DIR [RUN_DIR ...]   (each holds <arm>/metrics.json)

Prints a Markdown table: one row per metric, one column per arm, "mean ± half-width" of
the two-sided 95 % Student-t interval over the runs (one run per seed); speed and DSR cells
add their worst run, and a run whose speed is below 0.5 x SUMO-native's in the same run
folder (same seed, PR and demand) is a jam: marked JAM in the cell and listed below."""
import json
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from experiment_results import JAM_SHARE, REFERENCE_ARM, SPEED, WORST_OF  # noqa: E402
from palcas_stats import format_ci, mean_ci95  # noqa: E402

METRICS = [
    ("dsr_pct", "DSR (%)", 1),
    ("msr_pct", "MSR (%)", 1),
    ("collision_rate_pct", "CR (%)", 2),
    ("efficiency_all_mps", "efficiency, all (m/s)", 2),
    ("efficiency_cav_mps", "efficiency, CAVs (m/s)", 2),
    ("comfort_share_pct", "comfort share (%)", 1),
    ("throughput_vph", "throughput (veh/h)", 0),
    ("decision_ms_p99", "decision p99 (ms)", 2),
    ("lane_changes_dropped", "advised lane changes dropped", 0),
    ("real_time_factor", "real-time factor", 1),
]
def value(run, arm, key):
    f = run / arm / "metrics.json"
    if not f.exists():
        return None
    v = json.loads(f.read_text()).get(key)
    return float(v) if isinstance(v, (int, float)) and math.isfinite(v) else None


def jams(runs, arms):
    """(arm, run name, speed, SUMO-native's speed) of every jam."""
    out = []
    for r in runs:
        ref = value(r, REFERENCE_ARM, SPEED)
        for arm in arms:
            v = value(r, arm, SPEED)
            if ref is not None and v is not None and v < JAM_SHARE * ref:
                out.append((arm, r.name, v, ref))
    return out


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
    jammed = jams(runs, order)
    for key, label, digits in METRICS:
        cells = []
        for arm in order:
            vals = [(value(r, arm, key), r.name) for r in runs]
            vals = [(v, name) for v, name in vals if v is not None]
            if not vals:
                cells.append("n/a")
                continue
            text = format_ci(*mean_ci95([v for v, _ in vals]), digits)
            if key in WORST_OF and len(vals) > 1:
                worst, name = min(vals)
                text += f" (worst {worst:.{digits}f}, {name})"
            if key == SPEED and any(a == arm for a, _, _, _ in jammed):
                text += " **JAM**"
            cells.append(text)
        print(f"| {label} | " + " | ".join(cells) + " |")
    print(f"\n{len(runs)} evaluation run(s): " + ", ".join(r.name for r in runs))
    if not any((r / REFERENCE_ARM / "metrics.json").exists() for r in runs):
        print(f"Jams not checked: no {REFERENCE_ARM} run to compare with.")
    for arm, name, v, ref in jammed:
        print(f"JAM: {arm} in {name}: {v:.2f} m/s < {JAM_SHARE:g} x {REFERENCE_ARM}'s {ref:.2f} m/s")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
