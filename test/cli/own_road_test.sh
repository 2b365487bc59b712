#!/usr/bin/env bash
# A road its user brought (config/scenarios/curved: netconvert sources with edge names of
# their own, a curved mainline, an on-ramp with an acceleration lane, an off-ramp about 760 m after
# it, a lane drop 5 -> 4; config/scenarios/README.md, "Bring your own road"): ./palcas run
# builds it with netconvert, finds its mainline, ramps and two zones, and runs the keep arm
# and the shipped palcas policy (5 lanes: its state size 45) on it, 90 s each. Needs a built
# workspace (./palcas test builds first); about two minutes.
#
#   test/cli/own_road_test.sh [--xml FILE]
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
junit_script own_road "$@"

for arm in keep palcas; do
  status=0
  PALCAS_NO_BUILD=1 timeout -k 10 600 "$ROOT/palcas" run --scenario curved --arm "$arm" --no-compare \
    --duration 90 --seed 7 --out "$WORK/$arm" >"$WORK/$arm.log" 2>&1 || status=$?
  metrics="$WORK/$arm/$arm/metrics.json"
  why=""
  if [ "$status" -ne 0 ]; then why="exit $status: $(tail -5 "$WORK/$arm.log")"
  elif [ ! -f "$metrics" ]; then why="no metrics.json: $(tail -5 "$WORK/$arm.log")"
  elif ! check="$(/usr/bin/python3 - "$metrics" "$WORK/$arm/$arm/manifest.json" <<'PY' 2>&1
import json, sys
m = json.load(open(sys.argv[1]))
manifest = json.load(open(sys.argv[2]))
problems = []
if m["sim_seconds"] < 90: problems.append("ran %s s" % m["sim_seconds"])
if m["cavs_seen"] < 50: problems.append("saw %s CAVs" % m["cavs_seen"])
if m["arrived"] < 20: problems.append("%s vehicles arrived" % m["arrived"])
if m["exiting_cavs"] < 1 or m["exits_ok"] < 1: problems.append("no CAV took the off-ramp (%s exiting, %s ok)" % (m["exiting_cavs"], m["exits_ok"]))
if m["merging_cavs"] < 1: problems.append("no CAV came from the on-ramp")
if manifest["config"]["scenario"]["network_file"] != "curved.netccfg": problems.append("manifest: network_file %r" % manifest["config"]["scenario"]["network_file"])
print("; ".join(problems))
sys.exit(1 if problems else 0)
PY
)"; then why="$check"
  fi
  result "${arm}_runs_on_the_curved_road" "$why"
done

# The shipped policy's RSUs ran on the road's two zones and advised.
why=""
console="$WORK/palcas/palcas/console.log"
if [ ! -f "$console" ]; then why="no console.log"
elif ! grep -aq "rsu_1: evaluating policy" "$console"; then why="rsu_1 did not evaluate the shipped policy: $(grep -a 'rsu_' "$console" | head -3)"
elif [ "$(awk -F, 'NR > 1 && $4 > 0 { print $2 }' "$WORK/palcas/palcas/decisions.csv" | sort -u | tr '\n' ' ')" != "rsu_0 rsu_1 " ]; then
  why="not both RSUs advised: $(awk -F, 'NR > 1 && $4 > 0 { print $2 }' "$WORK/palcas/palcas/decisions.csv" | sort | uniq -c | tr '\n' ' ')"
fi
result shipped_policy_advises_in_both_zones "$why"
