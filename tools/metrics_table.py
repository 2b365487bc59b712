#!/usr/bin/env python3
"""Print the metric table of one or more metrics.json files side by side."""
import json
import pathlib
import sys

ROWS = [
    ("efficiency_all_mps", "Efficiency, all vehicles (m/s)", "{:.2f}"),
    ("efficiency_cav_mps", "Efficiency, CAVs (m/s)", "{:.2f}"),
    ("collision_rate_pct", "CR (% of CAVs)", "{:.2f}"),
    ("dsr_pct", "DSR (% of exiting CAVs)", "{:.2f}"),
    ("msr_pct", "MSR (% of merging CAVs)", "{:.2f}"),
    ("comfort_share_pct", "Comfort (% |a|<=1.47)", "{:.2f}"),
    ("throughput_vph", "Throughput (veh/h arrived)", "{:.0f}"),
    ("insertion_dropped", "Dropped at insertion", "{}"),
    ("mean_travel_time_s", "Mean travel time (s)", "{:.1f}"),
    ("lane_changes_per_cav", "Lane changes per CAV", "{:.2f}"),
    ("mainline_flow_vphpl", "Demand (veh/h/lane)", "{:g}"),
    ("collisions", "Collisions", "{}"),
    ("teleports", "Teleports", "{}"),
    ("cavs_seen", "CAVs seen", "{}"),
    ("exiting_cavs", "Exiting CAVs", "{}"),
    ("merging_cavs", "Merging CAVs", "{}"),
    ("advisories", "Advisories applied", "{}"),
    ("advisories_rejected", "Advisories rejected", "{}"),
    ("late_rsu_steps", "Late RSU steps", "{}"),
    ("guard.busy_zone_pct", "Guard: zone time busy (%)", "{:.1f}"),
    ("guard.handback_cav_s", "Guard: CAV-s handed back", "{:.0f}"),
    ("guard.accelerate_guarded_pct", "Guard: ACCELERATE guarded (%)", "{:.1f}"),
    ("v2x.advisories_sent", "V2X: advisories sent", "{}"),
    ("v2x.advisories_delivered", "V2X: advisories delivered", "{}"),
    ("v2x.advisories_applied_late", "V2X: of them late", "{}"),
    ("v2x.advisories_lost", "V2X: advisories lost", "{}"),
    ("v2x.advisories_out_of_range", "V2X: advisories out of range", "{}"),
    ("v2x.advisories_too_old", "V2X: advisories too old", "{}"),
    ("v2x.advice_mean_age_s", "V2X: mean advice age (s)", "{:.3f}"),
    ("decision_ms_p50", "Decision p50 (ms)", "{:.2f}"),
    ("decision_ms_p90", "Decision p90 (ms)", "{:.2f}"),
    ("decision_ms_p99", "Decision p99 (ms)", "{:.2f}"),
    ("federation_rounds", "Federation rounds", "{}"),
    ("sim_seconds", "Simulated (s)", "{:.0f}"),
    ("wall_seconds", "Wall (s)", "{:.1f}"),
    ("real_time_factor", "Real-time factor", "{:.2f}"),
]


def fmt(value, pattern):
    if value is None:
        return "n/a"
    try:
        return pattern.format(value)
    except (ValueError, TypeError):
        return str(value)


def lookup(metrics, key):
    """metrics[key], where a dotted key reaches into a nested block (guard.handback_cav_s)."""
    value = metrics
    for part in key.split("."):
        if not isinstance(value, dict) or part not in value:
            return None
        value = value[part]
    return value


def table(paths):
    """The table of these metrics.json files, a column per run (its folder's name)."""
    runs = [(pathlib.Path(p).parent.name, json.loads(pathlib.Path(p).read_text())) for p in paths]
    # Rows no run has (e.g. decision latency of a SUMO-native run) are left out.
    rows = [r for r in ROWS if any(lookup(m, r[0]) is not None for _, m in runs)]
    # The channel's rows only when some run had it on (off, every advisory is delivered at once).
    if not any(lookup(m, "v2x.enabled") for _, m in runs):
        rows = [r for r in rows if not r[0].startswith("v2x.")]
    width = max(14, *(len(n) for n, _ in runs))
    lines = [f"{'metric':34s}" + "".join(f"{n:>{width + 2}s}" for n, _ in runs)]
    for key, label, pattern in rows:
        lines.append(f"{label:34s}" + "".join(f"{fmt(lookup(m, key), pattern):>{width + 2}s}" for _, m in runs))
    return "\n".join(lines) + "\n"


def main(paths):
    sys.stdout.write(table(paths))


if __name__ == "__main__":
    main(sys.argv[1:])
