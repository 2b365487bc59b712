#!/usr/bin/env bash
# launch/system.launch runs every arm with the right nodes (roslaunch --nodes, nothing
# started), refuses an unknown arm naming it, and documents every argument (--ros-args: no
# "undocumented", no required argument). Needs the workspace built (./palcas test builds).
#
#   test/launch/system_launch_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
XML=""
[ "${1:-}" != --xml ] || XML="${2:?--xml needs a file}"
names=() failures=()
trap 'failed="$(write_junit system_launch "$XML")";
      echo "system_launch: $((${#names[@]} - failed)) passed, $failed failed"; [ "$failed" -eq 0 ]' EXIT
export PATH="/usr/bin:$PATH"
# shellcheck disable=SC1091
set +u; source "$ROOT/devel/setup.bash"; set -u

expect_nodes() {  # ARM "NODES"
  local got why=""
  got="$(roslaunch --nodes palcas_launch system.launch arm:="$1" out_dir:=/tmp/unused 2>&1 | sort | tr '\n' ' ')"
  [ "$got" = "$2 " ] || why="nodes '$got', expected '$2 '"
  names+=("arm_$1"); failures+=("$why")
  if [ -z "$why" ]; then echo "ok   arm_$1"; else echo "FAIL arm_$1: $why"; fi
}
expect_nodes palcas "/fedserver/palcas_fedserver /palcas_sumo_bridge /rsu_0/rsu /rsu_1/rsu /rsu_2/rsu"
expect_nodes palcas_assist "/fedserver/palcas_fedserver /palcas_sumo_bridge /rsu_0/rsu /rsu_1/rsu /rsu_2/rsu"
expect_nodes no_priority "/fedserver/palcas_fedserver /palcas_sumo_bridge /rsu_0/rsu /rsu_1/rsu /rsu_2/rsu"
expect_nodes independent "/palcas_sumo_bridge /rsu_0/rsu /rsu_1/rsu /rsu_2/rsu"
expect_nodes centralized "/central/rsu /palcas_sumo_bridge"
expect_nodes keep "/palcas_sumo_bridge"
expect_nodes sumo_native "/palcas_sumo_bridge"

why=""
params="$(roslaunch --dump-params palcas_launch system.launch arm:=no_priority out_dir:=/tmp/unused 2>&1)"
grep -q '^/rsu_0/rsu/reward/lambda: 0.0' <<<"$params" || why="no_priority does not set lambda 0"
params="$(roslaunch --dump-params palcas_launch system.launch arm:=keep out_dir:=/tmp/unused 2>&1)"
[ -n "$why" ] || grep -q '^/palcas_sumo_bridge/advisory_control: true' <<<"$params" || why="keep without advisory control"
[ -n "$why" ] || grep -q '^/palcas_sumo_bridge/assist_mode: false' <<<"$params" || why="keep in assist mode"
params="$(roslaunch --dump-params palcas_launch system.launch arm:=palcas_assist out_dir:=/tmp/unused 2>&1)"
[ -n "$why" ] || grep -q '^/palcas_sumo_bridge/assist_mode: true' <<<"$params" || why="palcas_assist not in assist mode"
[ -n "$why" ] || grep -q '^/rsu_0/rsu/federation: true' <<<"$params" || why="palcas_assist without federation"
# Recording: the bridge waits for both recorders (states and the view's markers) before step 0.
[ -n "$why" ] || grep -q '^/palcas_sumo_bridge/min_marker_subscribers: 0$' <<<"$params" || why="a markers subscriber awaited without recording"
params="$(roslaunch --dump-params palcas_launch system.launch arm:=keep record:=true out_dir:=/tmp/unused 2>&1)"
for expected in 'min_subscribers: 1' 'min_marker_subscribers: 1'; do
  [ -n "$why" ] || grep -q "^/palcas_sumo_bridge/$expected\$" <<<"$params" || why="record:=true lacks '$expected'"
done
names+=(arm_parameters); failures+=("$why")
if [ -z "$why" ]; then echo "ok   arm_parameters"; else echo "FAIL arm_parameters: $why"; fi

# paper_printed:=true gives the bridge the paper's literal actuation: none of the comfort
# bounds, no advice guard, advised changes that avoid only immediate collisions. And a policy's own
# bridge.yaml (policy_bridge_params) is loaded over config, under bridge_params.
why=""
params="$(roslaunch --dump-params palcas_launch system.launch arm:=palcas paper_printed:=true out_dir:=/tmp/unused 2>&1)"
for expected in 'own_car_following: false' 'own_merge: false' 'max_advised_accel_mps2: 0.0' \
                'lane_change_max_accel_mps2: 0.0' 'cav_lane_change_mode: 256' 'guard_enabled: false'; do
  grep -q "^/palcas_sumo_bridge/$expected\$" <<<"$params" || why="$why paper_printed lacks '$expected';"
done
params="$(roslaunch --dump-params palcas_launch system.launch arm:=palcas policy_bridge_params:=none out_dir:=/tmp/unused 2>&1)"
grep -q '^/palcas_sumo_bridge/lane_change_max_accel_mps2: 0.0$' <<<"$params" || why="$why the default is not config/bridge.yaml's 0.0;"
grep -q '^/palcas_sumo_bridge/guard_floor_speed_share: 0.6$' <<<"$params" || why="$why the advice guard is not on by default (0.6);"
grep -q '^/palcas_sumo_bridge/guard_enabled: true$' <<<"$params" || why="$why the advice guard is not enabled by default;"
printf 'lane_change_max_accel_mps2: 2.0\nlane_change_duration_s: 3.0\n' >/tmp/palcas_policy_bridge_$$.yaml
printf 'lane_change_duration_s: 2.5\n' >/tmp/palcas_user_bridge_$$.yaml
params="$(roslaunch --dump-params palcas_launch system.launch arm:=palcas out_dir:=/tmp/unused \
          policy_bridge_params:=/tmp/palcas_policy_bridge_$$.yaml bridge_params:=/tmp/palcas_user_bridge_$$.yaml 2>&1)"
rm -f /tmp/palcas_policy_bridge_$$.yaml /tmp/palcas_user_bridge_$$.yaml
grep -q '^/palcas_sumo_bridge/lane_change_max_accel_mps2: 2.0$' <<<"$params" || why="$why the policy's bridge.yaml is not loaded;"
grep -q '^/palcas_sumo_bridge/lane_change_duration_s: 2.5$' <<<"$params" || why="$why bridge_params does not go over the policy's;"
names+=(bridge_parameter_layers); failures+=("$why")
if [ -z "$why" ]; then echo "ok   bridge_parameter_layers"; else echo "FAIL bridge_parameter_layers: $why"; fi

# A policy's own rsu.yaml (policy_rsu_params) is loaded over config/departures.yaml, under
# rsu_params, on every RSU (zones and central) and not with paper_printed; the shipped policy's
# when the registry says it carries one.
why=""
printf 'rsu:\n  no_left_for_exit_within_m: 500.0\n  lane_change_dwell_s: 7.0\n' >/tmp/palcas_policy_rsu_$$.yaml
printf 'rsu:\n  lane_change_dwell_s: 3.0\n' >/tmp/palcas_user_rsu_$$.yaml
for arm in palcas centralized; do
  rsu=rsu_0; [ "$arm" = centralized ] && rsu=central
  params="$(roslaunch --dump-params palcas_launch system.launch arm:=$arm out_dir:=/tmp/unused \
            policy_rsu_params:=/tmp/palcas_policy_rsu_$$.yaml rsu_params:=/tmp/palcas_user_rsu_$$.yaml 2>&1)"
  grep -q "^/$rsu/rsu/rsu/no_left_for_exit_within_m: 500.0\$" <<<"$params" || why="$why $arm: the policy's rsu.yaml is not loaded;"
  grep -q "^/$rsu/rsu/rsu/lane_change_dwell_s: 3.0\$" <<<"$params" || why="$why $arm: rsu_params does not go over the policy's;"
  grep -q "^/$rsu/rsu/rsu/policy_model: folder_order\$" <<<"$params" || why="$why $arm: departures.yaml is lost;"
done
params="$(roslaunch --dump-params palcas_launch system.launch arm:=palcas out_dir:=/tmp/unused paper_printed:=true \
          policy_rsu_params:=/tmp/palcas_policy_rsu_$$.yaml 2>&1)"
grep -q '^/rsu_0/rsu/rsu/no_left_for_exit_within_m: 0.0$' <<<"$params" || why="$why paper_printed loads the policy's rsu.yaml;"
rm -f /tmp/palcas_policy_rsu_$$.yaml /tmp/palcas_user_rsu_$$.yaml
shipped_rsu="$(/usr/bin/python3 -c 'import sys; sys.path.insert(0, "'"$ROOT"'/tools"); import palcas_arms; print(" ".join(a for a, e in palcas_arms.ARMS.items() if e.get("shipped_rsu_params")))')"
for arm in $shipped_rsu; do
  params="$(roslaunch --dump-params palcas_launch system.launch arm:=$arm out_dir:=/tmp/unused 2>&1)"
  key="$(sed -n 's/^  \([a-z_]*\): .*/\1/p' "$ROOT/policies/$arm/rsu.yaml" | head -n 1)"
  value="$(sed -n "s/^  $key: \(.*\)/\1/p" "$ROOT/policies/$arm/rsu.yaml" | head -n 1)"
  grep -q "^/rsu_0/rsu/rsu/$key: $value\$" <<<"$params" || why="$why $arm: its shipped rsu.yaml ($key: $value) is not loaded;"
done
names+=(rsu_parameter_layers); failures+=("$why")
if [ -z "$why" ]; then echo "ok   rsu_parameter_layers"; else echo "FAIL rsu_parameter_layers: $why"; fi

# demand / ramp_demand go over the scenario's flows on the bridge; left out, the scenario's own.
why=""
params="$(roslaunch --dump-params palcas_launch system.launch arm:=keep scenario:=tiny demand:=1850 ramp_demand:=420 out_dir:=/tmp/unused 2>&1)"
grep -q '^/palcas_sumo_bridge/scenario/mainline_flow_vphpl: 1850.0$' <<<"$params" || why="$why demand:=1850 did not reach the bridge;"
grep -q '^/palcas_sumo_bridge/scenario/onramp_flow_vphpl: 420.0$' <<<"$params" || why="$why ramp_demand:=420 did not reach the bridge;"
params="$(roslaunch --dump-params palcas_launch system.launch arm:=keep scenario:=tiny out_dir:=/tmp/unused 2>&1)"
grep -q '^/palcas_sumo_bridge/scenario/mainline_flow_vphpl: 1000.0$' <<<"$params" || why="$why without demand the bridge lacks tiny's 1000;"
grep -q '^/palcas_sumo_bridge/scenario/onramp_flow_vphpl: 300.0$' <<<"$params" || why="$why without ramp_demand the bridge lacks tiny's 300;"
names+=(demand_reaches_the_bridge); failures+=("$why")
if [ -z "$why" ]; then echo "ok   demand_reaches_the_bridge"; else echo "FAIL demand_reaches_the_bridge: $why"; fi

# No arguments evaluates the shipped policy, under its own bridge.yaml; so does every learning
# arm of the registry that ships one (tools/arm_registry_test.py checks its shipped_policy
# against policies/). An evaluation with no weights is refused; training starts from random weights.
why=""
for arm in $(/usr/bin/python3 "$ROOT/tools/palcas_arms.py" --list learning); do
  rsu="$(/usr/bin/python3 -c 'import sys; sys.path.insert(0, sys.argv[1]); import palcas_arms; print(palcas_arms.rsu_ids(sys.argv[2], 1)[0])' "$ROOT/tools" "$arm")"
  params="$(roslaunch --dump-params palcas_launch system.launch arm:="$arm" out_dir:=/tmp/unused 2>&1)"
  grep -q "^/$rsu/rsu/policy_dir: $ROOT/policies/$arm/checkpoints\$" <<<"$params" ||
    why="$why $arm does not evaluate policies/$arm/checkpoints;"
  expected=0.0; [ ! -f "$ROOT/policies/$arm/bridge.yaml" ] ||
    expected="$(sed -n 's/^lane_change_max_accel_mps2: *//p' "$ROOT/policies/$arm/bridge.yaml")"
  grep -q "^/palcas_sumo_bridge/lane_change_max_accel_mps2: ${expected}\$" <<<"$params" ||
    why="$why $arm does not run under its shipped bridge.yaml (lane_change_max_accel_mps2 $expected);"
done
out="$(roslaunch --nodes palcas_launch system.launch policy_dir:=none out_dir:=/tmp/unused 2>&1)" &&
  why="$why eval with policy_dir:=none was accepted;"
[[ "$out" == *mode_eval_needs_trained_weights* ]] || why="$why the refusal does not say what eval needs: $out;"
params="$(roslaunch --dump-params palcas_launch system.launch mode:=train out_dir:=/tmp/unused 2>&1)"
grep -q "^/rsu_0/rsu/policy_dir: ''\$" <<<"$params" || why="$why training is handed a policy_dir;"
grep -q '^/palcas_sumo_bridge/lane_change_max_accel_mps2: 0.0$' <<<"$params" || why="$why training runs under a shipped bridge.yaml;"
names+=(default_runs_the_shipped_policy); failures+=("$why")
if [ -z "$why" ]; then echo "ok   default_runs_the_shipped_policy"; else echo "FAIL default_runs_the_shipped_policy: $why"; fi

why=""
out="$(roslaunch --nodes palcas_launch system.launch arm:=bogus out_dir:=/tmp/unused 2>&1)" && why="an unknown arm was accepted"
[ -n "$why" ] || [[ "$out" == *unknown_arm_bogus* ]] || why="the error does not name the arm: $out"
names+=(unknown_arm_refused); failures+=("$why")
if [ -z "$why" ]; then echo "ok   unknown_arm_refused"; else echo "FAIL unknown_arm_refused: $why"; fi

why=""
doc="$(roslaunch --ros-args palcas_launch system.launch 2>&1)"
grep -q undocumented <<<"$doc" && why="undocumented arguments: $(grep undocumented <<<"$doc" | tr '\n' ' ')"
[ -n "$why" ] || ! grep -q 'Required Arguments' <<<"$doc" || why="arguments listed as required: $doc"
# The building blocks too: every argument of every launch file says what it is.
for f in "$ROOT"/launch/*.launch; do
  [ "$(basename "$f")" != system.launch ] || continue
  doc="$(roslaunch --ros-args "$f" 2>&1)"
  ! grep -q undocumented <<<"$doc" || why="$why $(basename "$f"): undocumented $(grep undocumented <<<"$doc" | tr -s ' \n' ' ');"
done
names+=(every_argument_documented); failures+=("$why")
if [ -z "$why" ]; then echo "ok   every_argument_documented"; else echo "FAIL every_argument_documented: $why"; fi
