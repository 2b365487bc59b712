#!/usr/bin/env python3
"""Where a run's wall time goes, per arm: the bridge's per-step split (metrics.json ->
step_timing: SUMO's own step, the bridge's work around it, the lockstep = waiting for the
RSUs' answers and applying them) weighted over all steps, and each arm's wall time against
sumo_native's of the same run folder (the ratio issue 20 asks for: measure it in one run).

usage: loop_cost.py RUN_DIR [RUN_DIR ...] [--markdown]
  RUN_DIR: a ./palcas run folder (one subfolder per arm with its metrics.json)."""
import argparse
import json
import pathlib
import sys

PARTS = ("sumo_ms_per_step", "bridge_ms_per_step", "lockstep_ms_per_step")


def arm_cost(metrics):
    """Steps, wall and the step-weighted mean of each part [ms/step] of one arm's metrics."""
    buckets = metrics.get("step_timing") or []
    steps = sum(b["steps"] for b in buckets)
    parts = {p: (sum(b[p] * b["steps"] for b in buckets) / steps if steps else float("nan")) for p in PARTS}
    return {"steps": steps, "wall_s": float(metrics["wall_seconds"]), **parts}


def run_costs(run_dir):
    """{arm: cost} for every arm folder of run_dir with a metrics.json."""
    run_dir = pathlib.Path(run_dir)
    out = {}
    for f in sorted(run_dir.glob("*/metrics.json")):
        out[f.parent.name] = arm_cost(json.loads(f.read_text()))
    if not out:
        raise SystemExit("loop_cost: %s holds no <arm>/metrics.json (a ./palcas run folder?)" % run_dir)
    return out


def rows(run_dir):
    costs = run_costs(run_dir)
    native = costs.get("sumo_native")
    for arm, c in costs.items():
        ratio = c["wall_s"] / native["wall_s"] if native and native["wall_s"] > 0 else float("nan")
        yield [str(run_dir), arm, c["steps"], c["wall_s"], c["sumo_ms_per_step"], c["bridge_ms_per_step"],
               c["lockstep_ms_per_step"], ratio]


HEADER = ["run", "arm", "steps", "wall (s)", "SUMO (ms/step)", "bridge (ms/step)", "lockstep (ms/step)",
          "wall / sumo_native"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--markdown", action="store_true", help="a Markdown table instead of aligned text")
    a = ap.parse_args(argv)
    table = [r for run in a.runs for r in rows(run)]
    cells = [[c if isinstance(c, str) else (str(c) if isinstance(c, int) else "%.3f" % c) for c in r] for r in table]
    if a.markdown:
        print("| " + " | ".join(HEADER) + " |")
        print("|" + "---|" * len(HEADER))
        for r in cells:
            print("| " + " | ".join(r) + " |")
        return 0
    widths = [max(len(h), *(len(r[i]) for r in cells)) for i, h in enumerate(HEADER)]
    print("  ".join(h.ljust(w) for h, w in zip(HEADER, widths)))
    for r in cells:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
