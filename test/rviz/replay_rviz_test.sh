#!/usr/bin/env bash
# ./palcas replay BAG --rviz shows a recorded episode from its bags alone: a 60 s evaluation
# of the tiny road (an untrained network, so every kind of advice shows) recorded with
# record:=true, then played into rviz on a virtual X display (xvfb-run); screenshots until
# one shows advisory arrows (test/rviz/screenshot_check.py) and the road's asphalt, within
# 45 s of wall time. Needs a built workspace (./palcas test builds first).
#
#   test/rviz/replay_rviz_test.sh [--xml FILE] [--screenshot FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"  # ROS runs on the system Python
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
xml_args=() shot=""
while [ $# -gt 0 ]; do
  case "$1" in
    --xml) xml_args=(--xml "$2"); shift 2 ;;
    --screenshot) shot="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
junit_script replay_rviz "${xml_args[@]+"${xml_args[@]}"}"
[ -n "$shot" ] || shot="$WORK/screenshot.png"
set +u; source "$ROOT/devel/setup.bash"; set -u

# The recording: its own master on a free port; at 10x real time, not the recording default
# of 50x, as the other tests that read a bag do (a loaded machine's rosbag record loses messages).
port="$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')"
ROS_MASTER_URI="http://127.0.0.1:$port" ROS_HOSTNAME=127.0.0.1 ROS_LOG_DIR="$WORK/ros_log" \
  timeout -k 10 300 setpriv --pdeathsig INT roslaunch -p "$port" palcas_launch system.launch arm:=palcas \
  scenario:=tiny mode:=eval policy_dir:=random seed:=5 duration:=60 record:=true real_time_factor:=10 out_dir:="$WORK/run" \
  learning_params:="$ROOT/test/launch/small_learning.yaml" >"$WORK/console.log" 2>&1
why=""
for f in episode.bag episode_view.bag palcas.rviz; do
  [ -s "$WORK/run/$f" ] || why="$why the recording wrote no $f;"
done
result recording_has_bags_and_view "$why"

cat >"$WORK/inside.sh" <<'INSIDE'
set -u
ROOT="$1" WORK="$2" SHOT="$3"
# rviz under a bare X server (no window manager) once drew the road at half its framed width,
# centred on column 345 as if its drawing area were 690 px wide, in every screenshot of that
# start (a loaded CI box; not reproduced since): a second start of the replay gets one more
# chance, and the log says so.
status=1
for attempt in 1 2; do
[ "$attempt" -eq 1 ] || { echo "attempt 1 failed: $(cat "$WORK/check.txt")"; cp "$SHOT" "$SHOT.attempt1.png"; }
PALCAS_NO_BUILD=1 "$ROOT/palcas" replay "$WORK/run/episode.bag" --rviz --rate 1 >"$WORK/replay.log" 2>&1 &
replay=$!
status=1
for _ in $(seq 15); do
  sleep 3
  kill -0 "$replay" 2>/dev/null || { echo "the replay ended early"; break; }
  /usr/bin/python3 "$ROOT/test/rviz/screenshot_check.py" --save "$SHOT" >"$WORK/check.txt" 2>&1
  status=$?
  # The road itself (the lane bands' asphalt), not only vehicles: its markers come once.
  [ "$status" -ne 0 ] || /usr/bin/python3 - "$SHOT" <<'PY' >>"$WORK/check.txt" 2>&1 || status=1
import sys
import numpy as np
from PIL import Image
rgb = np.asarray(Image.open(sys.argv[1]).convert("RGB")).astype(np.int16)
asphalt = int((np.abs(rgb - np.array([77, 77, 84])) <= 10).all(axis=2).sum())
print("asphalt px %d" % asphalt)
sys.exit(0 if asphalt >= 20000 else 1)
PY
  [ "$status" -ne 0 ] || break
done
kill -INT "$replay" 2>/dev/null
wait "$replay"
[ "$status" -ne 0 ] || break
done
cat "$WORK/check.txt"
exit "$status"
INSIDE
xvfb-run -a -s "-screen 0 1400x900x24" bash "$WORK/inside.sh" "$ROOT" "$WORK" "$shot" >"$WORK/inside.log" 2>&1
status=$?
why=""
[ "$status" -eq 0 ] || why="$(tail -2 "$WORK/inside.log" | tr '\n' ' ') (screenshot: $shot; $WORK/replay.log)"
result replay_shows_road_vehicles_and_arrows "$why"
