#!/usr/bin/env bash
# The two ways to run the RSUs agree: RSU nodes over ROS topics, and the same decision code
# inside the bridge process (--in-process, palcas_sumo_bridge's InProcessRsus). Checks:
#   1. an evaluation of the shipped palcas policy (advisory mode, three RSUs with I2I, paper
#      road, 1400 veh/h/lane, PR 60 %, 300 s, a test seed) gives identical trajectories, the
#      same advice and the same metrics both ways;
#   2. a short training from one seed (tiny road, one 120 s episode, federation on, the
#      reproducible wall-time bounds of config/reproducible/ so that load cannot make an RSU
#      late) takes the same decisions and drives the same trajectories both ways over its
#      first 30 s. Later the ROS path may load a federation round's model one decision
#      earlier or later (the server aggregates beside the RSUs, in its own process), so the
#      rest of the episode is not compared.
# Needs a built workspace (./palcas test builds first); about two minutes.
#
#   test/cli/inprocess_parity_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
junit_script inprocess_parity "$@"

eval_point() {  # NAME [--in-process]
  local name="$1"; shift
  PALCAS_NO_BUILD=1 timeout -k 10 900 "$ROOT/palcas" run --arm palcas --no-compare --pr 60 --demand 1400 \
    --duration 300 --seed 1001 --out "$WORK/$name" "$@" >"$WORK/$name.log" 2>&1
}
train_short() {  # NAME --rsu-nodes | --in-process
  local name="$1"; shift
  PALCAS_NO_BUILD=1 timeout -k 10 900 "$ROOT/palcas" train --scenario tiny --episodes 1 --duration 120 --seed 7 \
    --record-decisions --bridge-params "$ROOT/config/reproducible/bridge.yaml" \
    --rsu-params "$ROOT/config/reproducible/rsu.yaml" --out "$WORK/$name" "$@" >"$WORK/$name.log" 2>&1
}

compare() {  # KIND A B: python prints the differences ("" = none)
  /usr/bin/python3 - "$@" <<'PY' 2>&1
import csv, json, pathlib, sys
kind, a, b = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
WALL = {"wall_seconds", "real_time_factor", "timing", "step_timing", "decision_ms_p50", "decision_ms_p90",
        "decision_ms_p99"}
def rows(path, drop=(), before_s=None):
    with open(path, newline="") as f:
        r = list(csv.reader(f))
    keep = [i for i, name in enumerate(r[0]) if name not in drop]
    t = r[0].index("time_s")
    out = [tuple(row[i] for i in keep) for row in r[1:] if before_s is None or float(row[t]) < before_s]
    return sorted(out)  # RSUs log in any order
def measured(path):
    return {k: v for k, v in json.loads(path.read_text()).items() if k not in WALL}
problems = []
if kind == "eval":
    fa, fb = a / "palcas", b / "palcas"
    ta, tb = rows(fa / "trajectories.csv"), rows(fb / "trajectories.csv")
    if len(ta) < 1000: problems.append("the ROS run recorded only %d trajectory rows" % len(ta))
    if ta != tb: problems.append("trajectories differ")
    da, db = rows(fa / "decisions.csv", drop=("decision_ms",)), rows(fb / "decisions.csv", drop=("decision_ms",))
    if len(da) < 100: problems.append("the ROS run recorded only %d decision rows" % len(da))
    if da != db: problems.append("decisions differ (%d rows against %d)" % (len(da), len(db)))
    ma, mb = measured(fa / "metrics.json"), measured(fb / "metrics.json")
else:
    da = rows(a / "decisions.csv", drop=("decision_ms",), before_s=30)
    db = rows(b / "decisions.csv", drop=("decision_ms",), before_s=30)
    if len(da) < 20: problems.append("the ROS training recorded only %d decision rows in its first 30 s" % len(da))
    if da != db: problems.append("first 30 s of training decisions differ (%d rows against %d)" % (len(da), len(db)))
    ta, tb = rows(a / "trajectories.csv", before_s=30), rows(b / "trajectories.csv", before_s=30)
    if len(ta) < 100: problems.append("the ROS training recorded only %d trajectory rows in its first 30 s" % len(ta))
    if ta != tb: problems.append("first 30 s of training trajectories (with each CAV's command) differ")
    ma = mb = {}
diff = sorted(k for k in set(ma) | set(mb) if ma.get(k) != mb.get(k))
if diff: problems.append("metrics differ in %s" % ", ".join(diff[:8]))
print("; ".join(problems))
PY
}

why=""
eval_point ros || why="ROS-node evaluation: exit $?: $(tail -3 "$WORK/ros.log")"
[ -n "$why" ] || eval_point inprocess --in-process || why="in-process evaluation: exit $?: $(tail -3 "$WORK/inprocess.log")"
[ -n "$why" ] || why="$(compare eval "$WORK/ros" "$WORK/inprocess")"
result evaluation_gives_the_same_trajectories_advice_and_metrics_both_ways "$why"

why=""
train_short train_ros --rsu-nodes || why="ROS-node training: exit $?: $(tail -3 "$WORK/train_ros.log")"
[ -n "$why" ] || train_short train_inprocess --in-process ||
  why="in-process training: exit $?: $(tail -3 "$WORK/train_inprocess.log")"
[ -n "$why" ] || why="$(compare train "$WORK/train_ros" "$WORK/train_inprocess")"
result short_training_takes_the_same_first_decisions_both_ways "$why"
