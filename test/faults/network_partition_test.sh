#!/usr/bin/env bash
# An RSU on a second host: a network namespace joined to this one by a veth link, both made
# and removed by this test, addresses inside them only (10.231.<n>.1 here, .2 there). The
# bridge (tiny road, lockstep with rsu_0, paced at 5x real time) runs here, rsu_0 there.
#   1. rsu_0 registers across the link and is answered in lockstep;
#   2. the link goes down -> the bridge marks rsu_0 lost and goes on simulating;
#   3. the link comes back -> rsu_0's answers arrive again and the bridge takes it back;
#   4. the episode finishes with its metrics.json.
# Asserts on what the bridge logged and wrote (simulation time, counts), not on timing.
# Needs root (ip netns); about two minutes.
#
#   test/faults/network_partition_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
junit_script network_partition "$@"

NET=$((200 + $$ % 50))
NS="palcas_rsu_host_$$"
VETH_HERE="pcs$$h" VETH_THERE="pcs$$r"
HERE_IP="10.231.$NET.1" THERE_IP="10.231.$NET.2"
bridge_pid="" rsu_pid=""
JUNIT_ON_EXIT='cleanup'
cleanup() {
  for p in $rsu_pid $bridge_pid; do kill -INT "$p" 2>/dev/null; done
  sleep 2
  for p in $rsu_pid $bridge_pid; do kill -9 "$p" 2>/dev/null; done
  ip link del "$VETH_HERE" 2>/dev/null
  ip netns del "$NS" 2>/dev/null
}
wait_for() {  # SECONDS COMMAND...: poll until the command succeeds
  local end=$((SECONDS + $1)); shift
  until "$@"; do [ $SECONDS -lt $end ] || return 1; sleep 0.5; done
}
# The bridge's log without its colour codes.
bridge_log() { sed 's/\x1b\[[0-9;]*m//g' "$WORK/bridge.log"; }
logged() { bridge_log | grep -a -- "$1" >/dev/null; }
# The simulated second of the bridge's last progress line (0 before the first).
progress() {
  local t
  t="$(bridge_log | grep -aoE 't= *[0-9]+/600' | tail -1 | grep -oE '[0-9]+/' | tr -d /)"
  echo "${t:-0}"
}
moved_past() { [ "$(progress)" -gt "$1" ]; }

if [ "$(id -u)" != 0 ]; then
  # Network namespaces need root; a developer's user account cannot run this test.
  result netns_available "not root: network namespaces need root (run ./palcas test as root)"
  exit
fi
why=""
ip netns add "$NS" && ip link add "$VETH_HERE" type veth peer name "$VETH_THERE" &&
  ip link set "$VETH_THERE" netns "$NS" &&
  ip addr add "$HERE_IP/24" dev "$VETH_HERE" && ip link set "$VETH_HERE" up &&
  ip netns exec "$NS" ip addr add "$THERE_IP/24" dev "$VETH_THERE" &&
  ip netns exec "$NS" ip link set "$VETH_THERE" up && ip netns exec "$NS" ip link set lo up ||
  why="could not make the namespace and veth link"
result link_made "$why"
[ -z "$why" ] || exit

export PATH="/usr/bin:$PATH"
port="$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("0.0.0.0",0)); print(s.getsockname()[1])')"
export ROS_MASTER_URI="http://$HERE_IP:$port" ROS_LOG_DIR="$WORK/ros_log"
printf 'lockstep_deadline_s: 0.2\nlost_after_missed_steps: 20\nstartup_timeout_s: 60.0\nmetrics_period_s: 1.0\n' >"$WORK/bridge.yaml"
ROS_IP="$HERE_IP" roslaunch -p "$port" palcas_launch bridge.launch scenario:=tiny duration:=600 \
  out_dir:="$WORK/run" advisory_control:=true expected_rsus:="[rsu_0]" real_time_factor:=5 \
  extra_params:="$WORK/bridge.yaml" >"$WORK/bridge.log" 2>&1 &
bridge_pid=$!
wait_for 60 logged "SUMO 1.15" || true
ip netns exec "$NS" env ROS_IP="$THERE_IP" ROS_MASTER_URI="$ROS_MASTER_URI" ROS_LOG_DIR="$WORK/ros_log_rsu" \
  PATH="$PATH" roslaunch palcas_launch rsu.launch index:=0 scenario:=tiny mode:=eval policy_dir:=random federation:=false \
  i2i:=false >"$WORK/rsu.log" 2>&1 &
rsu_pid=$!

# 1. Registered across the link and answering.
why=""
wait_for 90 logged "RSU 'rsu_0' registered" || why="rsu_0 did not register across the link"
result registered_across_link "$why"

# 2. Link down: lost, and the simulation goes on.
why=""
sleep 3
ip link set "$VETH_HERE" down || why="could not take the link down"
wait_for 60 logged "RSU 'rsu_0' lost" || why="the bridge did not mark rsu_0 lost"
progress_at_loss="$(progress)"
# Simulated time must pass with the link still down. A fixed 4 s of wall time was too short
# on a loaded machine (no new progress line yet); 60 s is an upper bound, not a rate.
[ -n "$why" ] || wait_for 60 moved_past "$progress_at_loss" ||
  why="the simulation stopped while rsu_0 was away (t=$progress_at_loss, still $(progress) 60 s later)"
result link_down_rsu_lost_bridge_goes_on "$why"

# 3. Link back: rsu_0 answers again and is waited for.
why=""
ip link set "$VETH_HERE" up || why="could not bring the link back"
wait_for 90 logged "RSU 'rsu_0' answers again" || why="rsu_0 did not rejoin after the link came back"
result link_up_rsu_rejoins "$why"

# 4. The episode ends with its metrics; the bridge never died.
why=""
wait_for 180 test -f "$WORK/run/metrics.json" || why="no metrics.json"
[ -n "$why" ] || /usr/bin/python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))
sys.exit(0 if m["sim_seconds"] >= 599 and m["advisories"] > 0 else 1)' "$WORK/run/metrics.json" ||
  why="metrics.json does not cover the episode with advisories applied"
result episode_finished "$why"
