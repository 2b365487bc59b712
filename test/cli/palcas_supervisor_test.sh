#!/usr/bin/env bash
# ./palcas train must not report success when an RSU dies: a tiny training whose RSUs die
# at start (an out-of-range parameter) exits non-zero with one line naming the node and its
# error. Needs a built workspace (./palcas test builds first); about a minute.
#
#   test/cli/palcas_supervisor_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
XML=""
[ "${1:-}" != --xml ] || XML="${2:?--xml needs a file}"
WORK="$(mktemp -d)"
names=() failures=()
trap 'failed="$(write_junit palcas_supervisor "$XML")"; rm -rf "$WORK";
      echo "palcas_supervisor: $((${#names[@]} - failed)) passed, $failed failed"; [ "$failed" -eq 0 ]' EXIT

printf 'rsu:\n  gradient_steps_per_decision: -1.0\n' >"$WORK/bad_rsu.yaml"
status=0
PALCAS_NO_BUILD=1 timeout -k 10 300 "$ROOT/palcas" train --scenario tiny --episodes 1 --duration 20 \
  --rsu-params "$WORK/bad_rsu.yaml" --out "$WORK/train" >"$WORK/out.log" 2>"$WORK/err.log" || status=$?
why=""
if [ "$status" -eq 0 ]; then why="exit 0 although every RSU died"
elif ! grep -q "error: training lost node(s) rsu_0" "$WORK/err.log"; then why="no line naming rsu_0: $(cat "$WORK/err.log")"
elif ! grep -q "gradient_steps_per_decision" "$WORK/err.log"; then why="the node's error is not named: $(cat "$WORK/err.log")"
elif ! grep -q "run without it" "$WORK/train/aborted_episodes.txt" 2>/dev/null; then why="aborted_episodes.txt does not record the lost episodes"
fi
names+=(train_fails_when_an_rsu_dies); failures+=("$why")
if [ -z "$why" ]; then echo "ok   train_fails_when_an_rsu_dies"; else echo "FAIL train_fails_when_an_rsu_dies: $why"; fi
