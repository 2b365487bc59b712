#!/usr/bin/env bash
# ./palcas train --simulations K: K simulations train one federation.
#   1. --plan writes the Slurm job of 3 simulations (no ROS needed): valid shell, one task per
#      simulation with its own seed, namespace and folder, the server expecting every RSU;
#   2. a training of 2 simulations (tiny road, small network, short rounds) ends with exit 0,
#      a policy folder (the server's global model), one episode per simulation with seeds
#      seed and seed + 1000, the merged episodes.csv with its simulation column, and rounds
#      that closed with submissions from both simulations' RSUs (the server's log).
# Asserts on what the nodes logged and wrote, not on timing. Needs a built workspace; about
# a minute.
#
#   test/cli/train_simulations_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
junit_script train_simulations "$@"
export PATH="/usr/bin:$PATH"
train_pid=""
JUNIT_ON_EXIT='[ -z "$train_pid" ] || kill -INT "$train_pid" 2>/dev/null; [ -z "$train_pid" ] || wait "$train_pid"'
strip() { sed 's/\x1b\[[0-9;]*m//g' "$@"; }

# 1. The Slurm job.
PLAN="$WORK/plan"
why=""
PALCAS_NO_BUILD=1 "$ROOT/palcas" train --simulations 3 --scenario tiny --episodes 2 --duration 300 --seed 7 \
  --plan --out "$PLAN" >"$WORK/plan.log" 2>&1 || why="--plan exited non-zero: $(tail -2 "$WORK/plan.log")"
job="$PLAN/slurm_train.sh"
[ -n "$why" ] || [ -x "$job" ] || why="no executable $job"
[ -n "$why" ] || bash -n "$job" 2>"$WORK/syntax" || why="$job: $(head -2 "$WORK/syntax")"
# The tasks' script, the one argument of srun's bash -c, with its quotes undone, parses too.
[ -n "$why" ] || sed -n "/^srun /,/^  esac'\$/p" "$job" | sed "1d; \$s/'\$//; s/'\\\\''/'/g" >"$WORK/tasks.sh"
[ -n "$why" ] || bash -n "$WORK/tasks.sh" 2>"$WORK/syntax" || why="the tasks' script is not valid shell: $(head -2 "$WORK/syntax")"
[ -n "$why" ] || grep -q '^#SBATCH --ntasks=3$' "$job" || why="not one task per simulation (#SBATCH --ntasks=3)"
[ -n "$why" ] || grep -q 'roslaunch -p "$port" palcas_launch federation.launch .expected_rsus:=\[rsu_0, rsu_1, rsu_0_s1, rsu_1_s1, rsu_0_s2, rsu_1_s2\]' "$job" ||
  why="the server does not expect every simulation's RSUs"
[ -n "$why" ] || grep -q 'export ROS_MASTER_URI="http://$master_ip:$port" ROS_IP=' "$job" || why="no ROS_MASTER_URI / ROS_IP"
for k in 0 1 2; do
  [ -n "$why" ] || grep -q "^    $k) .*roslaunch --wait palcas_launch simulation.launch simulation:=$k .* seed:=$((7 + 1000 * k)) .*out_dir:=$PLAN/sim$k " "$WORK/tasks.sh" ||
    why="task $k does not run simulation $k with seed $((7 + 1000 * k)) into sim$k/"
done
[ -n "$why" ] || /usr/bin/python3 -c 'import json,sys; r = json.load(open(sys.argv[1])); sys.exit(r.get("simulations") != 3)' "$PLAN/train.json" ||
  why="train.json does not record simulations: 3"
result plan_writes_the_slurm_job "$why"

# 2. Two simulations, one federation.
OUT="$WORK/train"
PALCAS_NO_BUILD=1 "$ROOT/palcas" train --simulations 2 --scenario tiny --episodes 1 --duration 900 \
  --learning "$ROOT/config/training/tiny_fast_learning.yaml" --rsu-params "$ROOT/config/training/short_rsu.yaml" \
  --out "$OUT" >"$WORK/train.log" 2>&1 &
train_pid=$!
status=0
wait "$train_pid" || status=$?
train_pid=""
why=""
[ "$status" -eq 0 ] || why="./palcas train exited $status: $(grep -a error "$WORK/train.log" | head -2)"
[ -n "$why" ] || /usr/bin/python3 "$ROOT/tools/policy_folder.py" check "$OUT" >/dev/null 2>&1 || why="$OUT is no policy folder"
[ -n "$why" ] || [ -f "$OUT/checkpoints/fedserver/global_model.palcas" ] || why="no global model"
result training_of_two_simulations_succeeds "$why"

why=""
for k in 0 1; do
  rows="$(tail -n +2 "$OUT/sim$k/episodes.csv" 2>/dev/null | cut -d, -f1,2)"
  [ -n "$why" ] || [ "$rows" = "0,$((1 + 1000 * k))" ] || why="sim$k/episodes.csv: '$rows', not episode 0 of seed $((1 + 1000 * k))"
done
[ -n "$why" ] || [ "$(head -1 "$OUT/episodes.csv" | cut -d, -f1-3)" = "simulation,episode,seed" ] ||
  why="episodes.csv has no leading simulation column"
[ -n "$why" ] || [ "$(tail -n +2 "$OUT/episodes.csv" | cut -d, -f1-3 | tr '\n' ' ')" = "0,0,1 1,0,1001 " ] ||
  why="episodes.csv does not hold one row per simulation: $(tail -n +2 "$OUT/episodes.csv" | cut -d, -f1-3 | tr '\n' ' ')"
result one_episode_per_simulation_own_seed "$why"

# A round closed when every live RSU of both simulations had submitted: n_k lists all four.
why=""
both="$(strip "$OUT"/ros_log/*/rosout.log 2>/dev/null |
  grep -aoE 'round [0-9]+ closed \(every live RSU submitted\): global version [0-9]+, n_k: rsu_0=[0-9]+ rsu_0_s1=[0-9]+ rsu_1=[0-9]+ rsu_1_s1=[0-9]+' | sort -u)"
[ -n "$both" ] || why="no round closed with submissions from both simulations ($(strip "$OUT"/ros_log/*/rosout.log 2>/dev/null | grep -ac 'closed') closes in the log)"
[ -n "$why" ] || echo "$both" | head -3
[ -n "$why" ] || ! strip "$OUT/console.log" "$OUT"/sim*/console.log | grep -aq 'unknown_rsu\|refused.*unknown' ||
  why="the server refused an RSU as unknown"
result rounds_close_with_both_simulations "$why"
