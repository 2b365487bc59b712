#!/usr/bin/env bash
# Counts simulations that die in early training: N one-episode trainings from scratch
# (epsilon 1: random advisories, the most lane changes) on a road, each its own launch and
# seed, with an optional bridge parameter file. Prints one line per episode and a total.
#
#   tools/crash_count.sh [--episodes N] [--duration S] [--scenario NAME] [--first-seed K]
#                        [--bridge-params FILE] --out DIR
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
N=20 DURATION=90 SCENARIO=paper FIRST=1 BRIDGE="" OUT=""
while [ $# -gt 0 ]; do
  case "$1" in
    --episodes) N="$2"; shift 2 ;;
    --duration) DURATION="$2"; shift 2 ;;
    --scenario) SCENARIO="$2"; shift 2 ;;
    --first-seed) FIRST="$2"; shift 2 ;;
    --bridge-params) BRIDGE="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    *) echo "crash_count: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -n "$OUT" ] || { echo "crash_count: --out DIR is required" >&2; exit 2; }
export PATH="/usr/bin:/bin:$PATH"
set +u; source "$ROOT/devel/setup.bash"; set -u
mkdir -p "$OUT"
died=0
for ((k = FIRST; k < FIRST + N; k++)); do
  dir="$OUT/seed$k"
  mkdir -p "$dir"
  port="$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')"
  ROS_MASTER_URI="http://127.0.0.1:$port" ROS_HOSTNAME=127.0.0.1 ROS_LOG_DIR="$dir/ros_log" \
    timeout -k 10 900 roslaunch -p "$port" palcas_launch system.launch arm:=palcas mode:=train scenario:="$SCENARIO" \
    seed:="$k" duration:="$DURATION" out_dir:="$dir" \
    checkpoint_dir:="$dir/checkpoints" bridge_params:="$BRIDGE" >"$dir/console.log" 2>&1
  if [ -f "$dir/metrics.json" ]; then
    echo "seed $k: completed ${DURATION} s"
  else
    died=$((died + 1))
    why="$(grep -a -m1 -o -E "Assertion.*|Segmentation fault.*|\[FATAL\].*|process has died.*" "$dir/console.log" | cut -c1-160)"
    echo "seed $k: DIED: ${why:-no reason in the log}"
  fi
done
echo "$died of $N episodes died (scenario $SCENARIO, ${DURATION} s each, bridge params: ${BRIDGE:-defaults})"
