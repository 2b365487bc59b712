#!/usr/bin/env bash
# rviz shows the system: the tiny road in training (its exploring RSUs advise every kind of
# action) with rviz:=true at real time, on a virtual X display (xvfb-run). Screenshots of
# the display until one shows advisory arrows and the whole road across the window
# (test/rviz/screenshot_check.py), within 45 s of wall time. Needs a built workspace
# (./palcas test builds first).
#
#   test/rviz/rviz_screenshot_test.sh [--xml FILE] [--arm ARM] [--screenshot FILE] [--wait S]
#
# --arm keep (no RSUs, no advisories) must fail: the check can tell arrows from none.
# --screenshot keeps the last screenshot; --wait S takes the first one after S s of wall
# time, on a fuller road (config/rviz/palcas_rviz.png: --wait 40).
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"  # ROS runs on the system Python
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
xml_args=()
arm=palcas shot="" wait_s=0
while [ $# -gt 0 ]; do
  case "$1" in
    --xml) xml_args=(--xml "$2"); shift 2 ;;
    --arm) arm="$2"; shift 2 ;;
    --screenshot) shot="$2"; shift 2 ;;
    --wait) wait_s="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
junit_script rviz_screenshot "${xml_args[@]+"${xml_args[@]}"}"
[ -n "$shot" ] || shot="$WORK/screenshot.png"

# Inside the virtual display: the launch in the background, screenshots every 2 s.
cat >"$WORK/inside.sh" <<'INSIDE'
set -u
ROOT="$1" WORK="$2" ARM="$3" SHOT="$4" WAIT_S="$5"
set +u; source "$ROOT/devel/setup.bash"; set -u
port="$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')"
ROS_MASTER_URI="http://127.0.0.1:$port" ROS_HOSTNAME=127.0.0.1 ROS_LOG_DIR="$WORK/ros_log" \
  setpriv --pdeathsig INT roslaunch -p "$port" palcas_launch system.launch arm:="$ARM" mode:=train \
  scenario:=tiny clusters:=2 pr:=60 seed:=5 duration:=120 rviz:=true real_time_factor:=1 \
  out_dir:="$WORK/run" >"$WORK/console.log" 2>&1 &
launch=$!
status=1
sleep "$WAIT_S"
for _ in $(seq 22); do
  sleep 2
  kill -0 "$launch" 2>/dev/null || { echo "the launch ended early"; break; }
  /usr/bin/python3 "$ROOT/test/rviz/screenshot_check.py" --save "$SHOT" >"$WORK/check.txt" 2>&1
  status=$?
  [ "$status" -ne 0 ] || break
done
cat "$WORK/check.txt"
kill -INT "$launch" 2>/dev/null
wait "$launch"
exit "$status"
INSIDE
# 1400x900: the shipped window (1400x860) and a margin; rviz draws with Mesa's software GL.
xvfb-run -a -s "-screen 0 1400x900x24" bash "$WORK/inside.sh" "$ROOT" "$WORK" "$arm" "$shot" "$wait_s" >"$WORK/inside.log" 2>&1
status=$?
why=""
if [ ! -s "$WORK/run/palcas.rviz" ]; then
  why="the bridge wrote no palcas.rviz: $(grep -a -E 'FATAL|ERROR' "$WORK/console.log" | tail -2)"
elif [ "$status" -ne 0 ]; then
  why="$(tail -1 "$WORK/inside.log") (screenshot: $shot)"
fi
result advisory_arrows_on_a_framed_road "$why"
