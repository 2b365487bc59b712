#!/usr/bin/env bash
# End to end: ./palcas experiment on the tiny road, two arms (keep, sumo_native), one PR,
# two short seeds; then the same command again (nothing reruns), an interrupted point
# redone, and --plan / --collect. Needs a built workspace (./palcas test builds first).
#
#   test/tools/experiment_e2e_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
junit_script experiment_e2e "$@"
OUT="$WORK/exp"

# The dev seed set (101, 102): a tool check, not a result; the point names below are its seeds'.
exp=(env PALCAS_NO_BUILD=1 "$ROOT/palcas" experiment --arms keep,sumo_native --prs 60 --seeds 2
     --seed-set dev --duration 30 --scenario tiny --jobs 2 --out "$OUT")
"${exp[@]}" >"$WORK/first.log" 2>&1
status=$?
why=""
[ "$status" -eq 0 ] || why="exit $status: $(tail -3 "$WORK/first.log")"
[ -n "$why" ] || [ "$(grep -c ',done,' "$OUT/results.csv")" -eq 4 ] || why="results.csv: $(cat "$OUT/results.csv")"
[ -n "$why" ] || grep -q '| 60 | ' "$OUT/tables.md" || why="tables.md has no PR 60 row"
for f in speed_over_time accel_profiles lane_trajectories space_time_keep space_time_sumo_native; do
  [ -n "$why" ] || [ -s "$OUT/figures/$f.png" ] || why="figure $f.png missing"
done
result four_points_tables_and_figures "$why"

"${exp[@]}" >"$WORK/again.log" 2>&1
why=""
grep -q '4 finished before, 0 to run' "$WORK/again.log" || why="a finished point would run again: $(head -3 "$WORK/again.log")"
result finished_points_never_rerun "$why"

# An interrupted point (its metrics cover 10 of 30 s) is run again, and only it.
m="$OUT/points/keep_pr60_s102/keep/metrics.json"
/usr/bin/python3 - "$m" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); d["sim_seconds"] = 10.0; json.dump(d, open(sys.argv[1], "w"))
PY
rm -f "$OUT/points/keep_pr60_s102/point.json"
"${exp[@]}" >"$WORK/resume.log" 2>&1
why=""
grep -q '3 finished before, 1 to run' "$WORK/resume.log" || why="$(head -3 "$WORK/resume.log")"
[ -n "$why" ] || grep -q '"sim_seconds": 30' "$m" || why="the interrupted point was not redone"
result interrupted_point_redone "$why"

"$ROOT/palcas" experiment --plan --arms keep --prs 5,60 --seeds 2 --seed-set dev --duration 30 --scenario tiny \
  --out "$WORK/plan" >/dev/null 2>&1
why=""
[ "$(wc -l <"$WORK/plan/plan.txt" 2>/dev/null)" = 4 ] || why="plan.txt has not 4 lines"
[ -n "$why" ] || grep -q 'array=1-4' "$WORK/plan/slurm_array.sh" || why="slurm_array.sh has no 1-4 array"
[ -n "$why" ] || [ ! -d "$WORK/plan/points" ] || why="--plan ran points"
result plan_writes_commands_only "$why"

rm -rf "$OUT/figures" "$OUT/tables.md"
"$ROOT/palcas" experiment --collect --out "$OUT" >/dev/null 2>&1
why=""
[ -s "$OUT/tables.md" ] && [ -s "$OUT/figures/speed_over_time.png" ] || why="--collect did not rebuild tables and figures"
result collect_rebuilds_results "$why"
