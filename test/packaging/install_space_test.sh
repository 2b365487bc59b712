#!/usr/bin/env bash
# `catkin_make install` yields an install space that runs an episode by itself: with only
# install/setup.bash sourced (no devel space, not the source tree), roslaunch palcas_launch
# system.launch runs keep on the tiny road and the shipped palcas policy on the paper road,
# each writing its metrics.json. Reuses ./palcas build's build folder (only the install step
# runs); about a minute.
#
#   test/packaging/install_space_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
junit_script install_space "$@"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin"
INSTALL="$WORK/install"

why=""
(cd "$ROOT" && catkin_make --source "$ROOT" --build "$ROOT/build" -DCMAKE_BUILD_TYPE=Release \
   -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_INSTALL_PREFIX="$INSTALL" install) >"$WORK/install.log" 2>&1 ||
  why="catkin_make install failed: $(tail -5 "$WORK/install.log" | tr '\n' ' ')"
# Put the build folder's install prefix back to the default, for the next plain build.
(cd "$ROOT" && cmake -DCMAKE_INSTALL_PREFIX="$ROOT/install" "$ROOT/build") >/dev/null 2>&1
[ -n "$why" ] || [ -f "$INSTALL/setup.bash" ] || why="no $INSTALL/setup.bash"
for f in share/palcas_launch/system.launch share/palcas_config/bridge.yaml \
         share/palcas_policies/palcas/checkpoints/rsu_0/model.palcas lib/palcas_sumo_bridge/bridge_node \
         lib/palcas_rsu/rsu_node lib/palcas_fedserver/fedserver_node \
         include/palcas_core/rsu/rsu_controller.h include/palcas_core/learning/nn/network.h; do
  [ -n "$why" ] || [ -e "$INSTALL/$f" ] || why="the install space lacks $f"
done
result install_space_complete "$why"

# An episode from the install space alone: a clean environment, no devel space on any path.
episode() {  # NAME ARGS...: runs system.launch from the install space into $WORK/<NAME>
  local name="$1"; shift
  local port=$((20000 + RANDOM % 20000))
  env -i HOME="$HOME" PATH="$PATH" SUMO_HOME=/usr/share/sumo bash -c \
    "source '$INSTALL/setup.bash' && cd '$WORK' && exec timeout -k 10 240 roslaunch -p $port palcas_launch system.launch \
       out_dir:='$WORK/$name' respawn:=false $*" >"$WORK/$name.log" 2>&1
}
why=""
episode keep arm:=keep scenario:=tiny duration:=30 || true
if [ ! -f "$WORK/keep/metrics.json" ]; then why="keep wrote no metrics.json: $(grep -m3 -i 'error\|fatal' "$WORK/keep.log" | tr '\n' ' ')"
elif grep -q "$ROOT/devel\|$ROOT/config\|$ROOT/launch" "$WORK/keep/manifest.json"; then why="the run used the source or devel tree: $(grep -o "$ROOT/[a-z]*" "$WORK/keep/manifest.json" | sort -u | tr '\n' ' ')"
fi
result keep_runs_from_the_install_space "$why"

why=""
episode palcas duration:=30 || true
if [ ! -f "$WORK/palcas/metrics.json" ]; then why="the shipped policy wrote no metrics.json: $(grep -m3 -i 'error\|fatal' "$WORK/palcas.log" | tr '\n' ' ')"
elif ! grep -q "evaluating policy $INSTALL/share/palcas_policies/palcas/checkpoints" "$WORK/palcas.log"; then
  why="the RSUs did not load the installed shipped policy: $(grep -m2 'evaluating policy' "$WORK/palcas.log" | tr '\n' ' ')"
fi
result shipped_policy_runs_from_the_install_space "$why"
