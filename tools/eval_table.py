#!/usr/bin/env python3
"""Mean and 95 % interval over evaluation seeds, per arm, from ./palcas run folders.

usage: eval_table.py RUN_DIR [RUN_DIR ...]   (each holds <arm>/metrics.json)

Prints a Markdown table: one row per metric, one column per arm, "mean ± half-width" of
the two-sided 95 % Student-t interval over the runs (one run per seed)."""
import json
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from palcas_stats import format_ci, mean_ci95  # noqa: E402

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
            cells.append(format_ci(*mean_ci95(vals), digits))
        print(f"| {label} | " + " | ".join(cells) + " |")
    print(f"\n{len(runs)} evaluation run(s): " + ", ".join(r.name for r in runs))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
