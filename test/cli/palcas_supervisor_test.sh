#!/usr/bin/env bash
# ./palcas train must not report success when an RSU dies, and SIGTERM of train or run must
# leave no process behind. First: a tiny training whose RSUs die
# at start (an out-of-range parameter) exits non-zero with one line naming the node and its
# error. Needs a built workspace (./palcas test builds first); about two minutes.
#
#   test/cli/palcas_supervisor_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
junit_script palcas_supervisor "$@"

# The same refusal on both paths: RSU nodes that die, and in-process RSUs (the default) that the
# bridge refuses at start; three episodes asked, so a refusal retried per episode would show.
printf 'rsu:\n  gradient_steps_per_decision: -1.0\n' >"$WORK/bad_rsu.yaml"
for path in rsu_nodes in_process; do
  status=0
  PALCAS_NO_BUILD=1 timeout -k 10 300 "$ROOT/palcas" train --scenario tiny --episodes 3 --duration 20 \
    $([ "$path" = rsu_nodes ] && echo --rsu-nodes) --rsu-params "$WORK/bad_rsu.yaml" --out "$WORK/train_$path" \
    >"$WORK/out_$path.log" 2>"$WORK/err_$path.log" || status=$?
  why=""
  if [ "$status" -eq 0 ]; then why="exit 0 although every RSU died"
  elif ! grep -q "error: training lost node(s) rsu_0" "$WORK/err_$path.log"; then why="no line naming rsu_0: $(cat "$WORK/err_$path.log")"
  elif ! grep -q "gradient_steps_per_decision" "$WORK/err_$path.log"; then why="the node's error is not named: $(cat "$WORK/err_$path.log")"
  elif ! grep -q "run without it" "$WORK/train_$path/aborted_episodes.txt" 2>/dev/null; then why="aborted_episodes.txt does not record the lost episodes"
  elif [ "$(grep -c "^launch " "$WORK/train_$path/aborted_episodes.txt")" != 1 ]; then why="more than one launch: $(cat "$WORK/train_$path/aborted_episodes.txt")"
  fi
  result "train_fails_when_an_rsu_dies_$path" "$why"
done

# RSU zones that are not the bridge's road (tiny: [0, 300, 600]): the RSUs refuse at start,
# naming both, and the training fails instead of running zones without CAVs.
printf 'zones_m: [0.0, 250.0, 600.0]\n' >"$WORK/bad_zones.yaml"
status=0
PALCAS_NO_BUILD=1 timeout -k 10 300 "$ROOT/palcas" train --scenario tiny --episodes 1 --duration 20 \
  --rsu-params "$WORK/bad_zones.yaml" --out "$WORK/train_zones" >"$WORK/zones_out.log" 2>"$WORK/zones_err.log" || status=$?
why=""
if [ "$status" -eq 0 ]; then why="exit 0 although the RSUs' zones are not on the road"
elif ! grep -q "error: training lost node(s) rsu_" "$WORK/zones_err.log"; then why="no line naming the RSUs: $(cat "$WORK/zones_err.log")"
elif ! grep -q "this RSU's zone is \[.*) m but zone [01] of the bridge's road is \[" "$WORK/zones_err.log"; then
  why="the error does not name both zones: $(cat "$WORK/zones_err.log")"
fi
result train_refuses_zones_not_on_the_road "$why"

# The shipped policy on a road with twice its zones (--scenario takes an absolute folder): the
# RSUs of zones the training had load their own models, the others the policy's default
# model, and every RSU advises. 240 s: CAVs reach the last zone (x >= 4000 m) by then.
mkdir -p "$WORK/paper6"
sed 's/^  clusters: 3$/  clusters: 6/' "$ROOT/config/scenarios/paper/scenario.yaml" >"$WORK/paper6/scenario.yaml"
cp "$ROOT/config/scenarios/paper/vtypes.xml" "$WORK/paper6/"
status=0
PALCAS_NO_BUILD=1 timeout -k 10 600 "$ROOT/palcas" run --scenario "$WORK/paper6" --no-compare --duration 240 \
  --seed 104 --out "$WORK/six" >"$WORK/six.log" 2>&1 || status=$?
why=""
if [ "$status" -ne 0 ]; then why="exit $status: $(tail -3 "$WORK/six.log")"
elif ! grep -q 'clusters: 6' "$WORK/paper6/scenario.yaml"; then why="the test's road is not 6 clusters"
elif ! grep -aq "rsu_0: evaluating policy .*/checkpoints/rsu_0/model.palcas" "$WORK/six/palcas/console.log"; then why="rsu_0 did not load its own model"
elif ! grep -aq "rsu_5: evaluating policy .*/checkpoints/default/model.palcas" "$WORK/six/palcas/console.log"; then why="rsu_5 did not load the default model"
elif ! /usr/bin/python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); g=m["guard"]; sys.exit(0 if m["sim_seconds"] >= 240 and g["floor_speed_share"] == 0.6 and g["accelerate_cav_s"] > 0 else 1)' "$WORK/six/palcas/metrics.json"; then
  why="a short run, or metrics.json does not count the advice guard (on by default): $(head -c 300 "$WORK/six/palcas/metrics.json")"
elif [ "$(awk -F, 'NR > 1 && $4 > 0 { print $2 }' "$WORK/six/palcas/decisions.csv" | sort -u | tr '\n' ' ')" != "rsu_0 rsu_1 rsu_2 rsu_3 rsu_4 rsu_5 " ]; then
  why="not every RSU advised: $(awk -F, 'NR > 1 && $4 > 0 { print $2 }' "$WORK/six/palcas/decisions.csv" | sort | uniq -c | tr '\n' ' ')"
fi
result shipped_policy_serves_a_road_with_six_zones "$why"

# A corrupt checkpoint: --resume fails, naming the file and what is wrong with it (and the
# file is left as it was, for the user to look at).
status=0
PALCAS_NO_BUILD=1 timeout -k 10 300 "$ROOT/palcas" train --scenario tiny --episodes 1 --duration 30 \
  --learning "$ROOT/config/training/tiny_fast_learning.yaml" --out "$WORK/train_ckpt" >"$WORK/ckpt1.log" 2>&1 || status=$?
why=""
if [ "$status" -ne 0 ] || [ ! -f "$WORK/train_ckpt/checkpoints/rsu_0/agent.ckpt" ]; then
  why="the first training failed or wrote no checkpoint (exit $status): $(tail -2 "$WORK/ckpt1.log")"
else
  # First, as a policy: one whose folder carries bridge.yaml runs under it (what
  # tools/ship_policy.py --bridge-as-trained writes), and --bridge-params still goes over it.
  cp -r "$WORK/train_ckpt" "$WORK/policy_own_bridge"
  printf 'cav_lane_change_mode: 1792\nlane_change_duration_s: 3.0\n' >"$WORK/policy_own_bridge/bridge.yaml"
  printf 'lane_change_duration_s: 2.5\n' >"$WORK/user_bridge.yaml"
  status=0
  PALCAS_NO_BUILD=1 timeout -k 10 300 "$ROOT/palcas" run --policy "$WORK/policy_own_bridge" --no-compare \
    --duration 20 --bridge-params "$WORK/user_bridge.yaml" --out "$WORK/run_own_bridge" >"$WORK/own_bridge.log" 2>&1 || status=$?
  own="$(/usr/bin/python3 -c 'import json,sys; b=json.load(open(sys.argv[1]))["config"]["bridge"]; print(b["cav_lane_change_mode"], b["lane_change_duration_s"])' \
         "$WORK/run_own_bridge/palcas/manifest.json" 2>&1)"
  why=""
  if [ "$status" -ne 0 ]; then why="the run failed (exit $status): $(tail -3 "$WORK/own_bridge.log")"
  elif [ "$own" != "1792 2.5" ]; then why="the bridge ran with lane-change mode and duration '$own', expected '1792 2.5'"
  elif ! grep -q "under the policy's own bridge parameters .*policy_own_bridge/bridge.yaml" "$WORK/own_bridge.log"; then
    why="the run does not say it uses the policy's bridge.yaml"
  fi
  result run_uses_the_policys_own_bridge_parameters "$why"
  why=""
  printf 'not a checkpoint' >"$WORK/train_ckpt/checkpoints/rsu_0/agent.ckpt"
  status=0
  PALCAS_NO_BUILD=1 timeout -k 10 300 "$ROOT/palcas" train --resume --episodes 2 --out "$WORK/train_ckpt" \
    >"$WORK/ckpt2.log" 2>"$WORK/ckpt2_err.log" || status=$?
  if [ "$status" -eq 0 ]; then why="--resume over a corrupt checkpoint exited 0"
  elif ! grep -q "train_ckpt/checkpoints/rsu_0/agent.ckpt is not a PALCAS model file" "$WORK/ckpt2_err.log"; then
    why="the error does not name the file and the fault: $(cat "$WORK/ckpt2_err.log")"
  elif [ "$(cat "$WORK/train_ckpt/checkpoints/rsu_0/agent.ckpt")" != "not a checkpoint" ]; then
    why="the corrupt checkpoint was overwritten"
  fi
fi
result resume_refuses_a_corrupt_checkpoint "$why"

# --demand / --ramp-demand reach the bridge: the default run folder is named by them, and
# manifest.json, metrics.json and the generated routes file that SUMO ran show them; the
# manifest also says what the core was built for, and the guard's collision attribution
# counts every CAV collision. The same run asks for two of SUMO's own outputs, which land in
# the arm's folder.
status=0
PALCAS_NO_BUILD=1 PALCAS_RESULTS_DIR="$WORK/results" timeout -k 10 300 "$ROOT/palcas" run --arm keep --no-compare \
  --scenario tiny --duration 20 --pr 40 --seed 7 --demand 1850 --ramp-demand 420 \
  --sumo-output tripinfo --sumo-output summary >"$WORK/demand.log" 2>&1 || status=$?
run_dir="$(ls -d "$WORK"/results/run-*-pr40-d1850-r420-s7 2>/dev/null | head -1)"
why=""
if [ "$status" -ne 0 ]; then why="the run failed (exit $status): $(tail -3 "$WORK/demand.log")"
elif [ -z "$run_dir" ]; then why="no run folder named by the demand: $(ls "$WORK/results")"
else
  got="$(/usr/bin/python3 -c 'import json,sys
m = json.load(open(sys.argv[1] + "/keep/manifest.json"))
r = json.load(open(sys.argv[1] + "/keep/metrics.json"))
c = m["config"]["scenario"]
print(m["demand"]["mainline_flow_vphpl"], m["demand"]["onramp_flow_vphpl"], c["mainline_flow_vphpl"],
      r["mainline_flow_vphpl"], r["onramp_flow_vphpl"], r["throughput_vph"] is not None, "insertion_dropped" in r,
      m["build"]["core_arch"] in ("native", "portable") and bool(m["build"]["core_simd"]), r["guard"]["collided_cavs"] == r["cav_collisions"])' "$run_dir" 2>&1)"
  [ "$got" = "1850.0 420.0 1850.0 1850.0 420.0 True True True True" ] || why="manifest/metrics show '$got', expected '1850.0 420.0 1850.0 1850.0 420.0 True True True True'"
  [ -n "$why" ] || grep -q "mainline 1850 veh/h/lane, on-ramp 420 veh/h/lane" "$run_dir"/keep/scenario/*.rou.xml ||
    why="the routes file SUMO ran does not say 1850 / 420: $(grep -h -o 'mainline [^.]*' "$run_dir"/keep/scenario/*.rou.xml)"
  [ -n "$why" ] || grep -q "demand=1850 veh/h/lane (ramps 420 veh/h)" "$WORK/demand.log" || why="the run does not say its demand"
fi
result run_demand_reaches_the_bridge "$why"
why=""
if [ -z "$run_dir" ]; then why="no run folder"
else
  grep -q "<tripinfos" "$run_dir/keep/sumo_tripinfo.xml" 2>/dev/null || why+="no SUMO tripinfo in sumo_tripinfo.xml; "
  grep -q "<summary" "$run_dir/keep/sumo_summary.xml" 2>/dev/null || why+="no SUMO summary in sumo_summary.xml; "
  [ -e "$run_dir/keep/sumo_fcd.xml" ] && why+="an output nobody asked for (fcd); "
  grep -q '"sumo_outputs": \[' "$run_dir/keep/manifest.json" || why+="manifest.json does not record sumo_outputs"
fi
result run_sumo_outputs_land_in_the_run_folder "$why"

# SIGTERM of ./palcas train or ./palcas run (a scheduler, kill): the command stops every
# process it started and says so; a training's nodes checkpoint on the way out.
left_of() {  # DIR: processes whose command line names DIR
  local p out=""
  for p in $(pgrep -f "roslaunch|rsu_node|bridge_node|fedserver_node"); do
    tr '\0' ' ' <"/proc/$p/cmdline" 2>/dev/null | grep -q "$1" && out+="$p "
  done
  echo "$out"
}
sigterm_case() {  # NAME DIR EXPECTED_EXIT CHECK_CHECKPOINTS COMMAND...
  local name="$1" dir="$2" expect="$3" ckpt="$4"; shift 4
  PALCAS_NO_BUILD=1 "$@" >"$WORK/$name.log" 2>&1 &
  local pid=$! why="" status=0 waited=0
  # Stop it once its simulation is under way (the bridge announced SUMO), not before.
  until grep -aq "SUMO 1.15" "$dir"/console.log "$dir"/*/console.log 2>/dev/null || [ $waited -ge 120 ]; do
    sleep 1; waited=$((waited + 1))
  done
  sleep 3
  kill -TERM "$pid"
  wait "$pid" || status=$?
  sleep 1
  local left; left="$(left_of "$dir")"
  if [ "$status" -ne "$expect" ]; then why="exit $status, expected $expect: $(tail -2 "$WORK/$name.log")"
  elif [ -n "$left" ]; then why="processes left behind: $left"; kill -9 $left 2>/dev/null
  elif ! grep -q "interrupted (TERM)" "$WORK/$name.log"; then why="it did not say it was interrupted"
  elif [ "$ckpt" = yes ] && [ ! -f "$dir/checkpoints/rsu_0/controller.txt" ]; then why="no checkpoint written on the way out"
  fi
  result "$name" "$why"
}
sigterm_case train_sigterm_leaves_nothing "$WORK/t2" 143 yes \
  "$ROOT/palcas" train --scenario tiny --episodes 1 --duration 100000 \
  --learning "$ROOT/config/training/tiny_fast_learning.yaml" --out "$WORK/t2"
sigterm_case run_sigterm_leaves_nothing "$WORK/r2" 143 no \
  "$ROOT/palcas" run --arm keep --no-compare --scenario tiny --duration 100000 --out "$WORK/r2"

# An RSU started on its own in eval mode without policy_dir (rsu.launch, no bridge): it exits
# at once with a FATAL saying what to give, instead of waiting for a bridge (register_timeout_s
# 60 s) and then evaluating random weights.
port="$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
ROS_MASTER_URI="http://127.0.0.1:$port" ROS_LOG_DIR="$WORK/rsu_eval_log" timeout -k 5 30 \
  roslaunch -p "$port" palcas_launch rsu.launch index:=0 mode:=eval policy_dir:= >"$WORK/rsu_eval.log" 2>&1
why=""
if ! grep -aq "mode eval needs trained weights and policy_dir is not set: give policy_dir:=DIR" "$WORK/rsu_eval.log"; then
  why="no FATAL naming policy_dir within 30 s: $(grep -a -i "fatal\|error" "$WORK/rsu_eval.log" | head -3)"
elif ! grep -aq "\[rsu_0/rsu-[0-9]*\] process has died .*exit code 1" "$WORK/rsu_eval.log"; then
  why="the RSU did not exit with code 1: $(tail -3 "$WORK/rsu_eval.log")"
fi
result rsu_refuses_eval_without_weights "$why"

# Training through the V2X channel, two episodes in one launch: the RSUs' view of the road
# starts afresh with the second episode (its steps start again at 0) and both advise;
# train.json records the channel file (repository-relative: tools/repo_paths.py).
status=0
PALCAS_NO_BUILD=1 timeout -k 10 300 "$ROOT/palcas" train --scenario tiny --episodes 2 --duration 60 \
  --learning "$ROOT/config/training/tiny_fast_learning.yaml" --v2x "$ROOT/test/launch/v2x_impaired.yaml" \
  --out "$WORK/train_v2x" >"$WORK/train_v2x.log" 2>&1 || status=$?
why=""
if [ "$status" -ne 0 ]; then why="exit $status: $(tail -3 "$WORK/train_v2x.log")"
elif ! grep -q '"v2x_params": "test/launch/v2x_impaired.yaml"' "$WORK/train_v2x/train.json"; then
  why="train.json does not record the channel: $(cat "$WORK/train_v2x/train.json")"
else
  for e in 0 1; do
    if ! /usr/bin/python3 -c 'import json, sys; v = json.load(open(sys.argv[1]))["v2x"]; sys.exit(0 if v["enabled"] and v["advisories_delivered"] > 50 and v["advisories_lost"] > 0 else 1)' \
      "$WORK/train_v2x/episode_$e/metrics.json"; then
      why="episode $e advised too little through the channel: $(head -c 400 "$WORK/train_v2x/episode_$e/metrics.json")"
    fi
  done
fi
result train_through_the_v2x_channel_two_episodes "$why"
