#!/usr/bin/env bash
# ./palcas train killed outright (SIGKILL: no trap runs) three times at random points, each
# time resumed with --resume (tiny road, 3 episodes of 1200 s, small network):
#   - after each kill no process of the training is left (roslaunch gets SIGINT through its
#     parent-death signal and stops every node; they checkpoint);
#   - the resumed trainings end with exactly the episodes of an uninterrupted run: episode
#     numbers 0, 1, 2 once each, each a whole 1200 s (an interrupted one is redone);
#   - every checkpoint loads: the last resume starts its nodes from them and succeeds.
# And ./palcas run killed outright mid-run leaves no process either.
# Asserts on files and process lists, not on timing. About four minutes.
#
#   test/faults/train_sigkill_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
junit_script train_sigkill "$@"
OUT="$WORK/train"
train_pid=""
JUNIT_ON_EXIT='[ -z "$train_pid" ] || kill -9 "$train_pid" 2>/dev/null; pkill -9 -f "$OUT" 2>/dev/null'
leftovers() { pgrep -f "$OUT/" 2>/dev/null | grep -v "^$$\$" | tr '\n' ' '; }
wait_gone() {  # SECONDS: until no process of the training is left
  local end=$((SECONDS + $1))
  while [ -n "$(leftovers)" ]; do [ $SECONDS -lt $end ] || return 1; sleep 0.5; done
}
train() {  # extra options...: exec, so a background train's pid is ./palcas itself
  exec env PALCAS_NO_BUILD=1 "$ROOT/palcas" train --scenario tiny --episodes 3 --duration 1200 \
    --learning "$ROOT/config/training/tiny_fast_learning.yaml" --out "$OUT" "$@" >>"$WORK/train.log" 2>&1
}

# Kill points spread over the run: start-up, mid-episode, later episodes (seeded per run).
RANDOM=$$
for k in 1 2 3; do
  why=""
  if [ "$k" = 1 ]; then (train) & else (train --resume) & fi
  train_pid=$!
  sleep $((5 + RANDOM % 30))
  if kill -0 "$train_pid" 2>/dev/null; then
    kill -9 "$train_pid"
    wait "$train_pid" 2>/dev/null
    wait_gone 60 || why="processes left after SIGKILL $k: $(leftovers)"
  else
    wait "$train_pid" 2>/dev/null  # it finished before the kill: nothing to check
  fi
  train_pid=""
  rows=$(($( (cat "$OUT/episodes.csv" 2>/dev/null || echo header) | wc -l) - 1))
  echo "kill $k: episodes.csv rows $rows" >>"$WORK/train.log"
  result "sigkill_${k}_no_orphans" "$why"
done

why=""
(train --resume) || why="the final resume failed: $(tail -3 "$WORK/train.log" | tr '\n' ' ')"
result final_resume_succeeds "$why"

why=""
/usr/bin/python3 - "$OUT/episodes.csv" <<'EOF' || why="episodes.csv is not one whole row per episode 0..2 (see $OUT)"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
episodes = sorted(int(r["episode"]) for r in rows)
ok = episodes == [0, 1, 2] and all(float(r["sim_seconds"]) >= 1200 - 1e-6 for r in rows)
print("episodes", episodes, "sim_seconds", [r["sim_seconds"] for r in rows])
sys.exit(0 if ok else 1)
EOF
result episodes_once_each_and_whole "$why"
# ./palcas run, SIGKILLed while its simulation runs: roslaunch gets SIGINT from its
# parent-death signal and stops every node.
RUN_OUT="$WORK/run"
why=""
(exec env PALCAS_NO_BUILD=1 "$ROOT/palcas" run --scenario tiny --arm keep --no-compare --duration 36000 \
  --out "$RUN_OUT" >>"$WORK/run.log" 2>&1) &
run_pid=$!
end=$((SECONDS + 120))
until grep -q "palcas bridge: " "$RUN_OUT"/*/console.log 2>/dev/null || [ $SECONDS -ge $end ]; do sleep 0.5; done
if ! pgrep -f "$RUN_OUT/" >/dev/null; then
  why="./palcas run started no node within 120 s: $(tail -3 "$WORK/run.log" | tr '\n' ' ')"
else
  kill -9 "$run_pid"
  wait "$run_pid" 2>/dev/null
  end=$((SECONDS + 60))
  while pgrep -f "$RUN_OUT/" >/dev/null && [ $SECONDS -lt $end ]; do sleep 0.5; done
  left="$(pgrep -af "$RUN_OUT/" | cut -c1-120 | tr '\n' ';')"
  [ -z "$left" ] || why="processes left 60 s after SIGKILL of ./palcas run: $left"
fi
pkill -9 -f "$RUN_OUT/" 2>/dev/null
result run_sigkill_no_orphans "$why"

grep -a -E "^kill [0-9]|training folder|error|ended early|resum" "$WORK/train.log" | head -20
