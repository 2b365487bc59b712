#!/usr/bin/env bash
# Learning regression test: a seeded ./palcas train on the tiny road (16 episodes x 300 s,
# a small network, about 4 minutes) must beat the keep arm (advisories on, all KEEP) on an
# evaluation seed it never trained on: DSR at least MARGIN points above keep's while the
# traffic keeps at least SPEED_SHARE of keep's average speed (a policy that gets CAVs out
# by jamming the road does not count). The same training with learning switched off
# (learning rate 0: config/training/no_learning.yaml) must not. And the learnt policy must
# not jam the road on traffic it never trained on: on two held-out seeds x two demands
# (the tiny road's own 1000 veh/h/lane and JAM_DEMAND) its speed stays at least JAM_SHARE
# of keep's on the same traffic (about 2 more minutes). Asserts on simulated outcomes only,
# never on wall-clock time.
#
#   test/learning/learning_regression_test.sh [--xml FILE] [--keep-work]
set -uo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
XML="" KEEP_WORK=false
while [ $# -gt 0 ]; do
  case "$1" in
    --xml) XML="$2"; shift 2 ;;
    --keep-work) KEEP_WORK=true; shift ;;
    *) echo "learning_regression_test: unknown option $1" >&2; exit 2 ;;
  esac
done
MARGIN=15          # DSR points above keep a learnt policy must reach
SPEED_SHARE=0.9    # of keep's average speed (all vehicles) it must keep
TRAIN_SEED=1       # episodes use seeds 1..16 (a second attempt: 17..32)
EVAL_SEED=101      # never used in training
# The advice guard's busy zones off: they would filter even a random policy's advice into
# DSR on this road (config/training/learning_only.yaml says why).
BRIDGE="$ROOT/config/training/learning_only.yaml"
JAM_SEEDS="101 102"     # held-out seeds of the jam check (training: 1..32)
JAM_DEMANDS="1000 1600" # veh/h/lane: the tiny road's own (config/scenarios/tiny) and a busier one
JAM_SHARE=0.5           # of keep's speed on the same traffic: below it, the policy jammed the road
JAM_DURATION=300        # simulated seconds per extra evaluation
WORK="$(mktemp -d)"
export PALCAS_NO_BUILD=1  # ./palcas test built the workspace already
names=() failures=()

# "DSR SPEED" of a run folder's metrics.json.
outcome() {
  /usr/bin/python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); print(m["dsr_pct"], m["efficiency_all_mps"])' "$1"
}

# train_and_compare NAME LEARNING_FILE [TRAIN_SEED]: trains, evaluates beside keep, prints
# "policy_dsr policy_speed keep_dsr keep_speed".
train_and_compare() {
  local name="$1" learning="$2"
  "$ROOT/palcas" train --scenario tiny --episodes 16 --duration 300 --seed "${3:-$TRAIN_SEED}" \
    --learning "$learning" --rsu-params "$ROOT/config/training/short_rsu.yaml" --bridge-params "$BRIDGE" \
    --out "$WORK/$name/train" >"$WORK/$name.train.log" 2>&1 || return 1
  "$ROOT/palcas" run --policy "$WORK/$name/train" --scenario tiny --duration 600 --seed "$EVAL_SEED" \
    --bridge-params "$BRIDGE" --out "$WORK/$name/eval" >"$WORK/$name.eval.log" 2>&1 || return 1
  echo "$(outcome "$WORK/$name/eval/palcas/metrics.json") $(outcome "$WORK/$name/eval/keep/metrics.json")"
}

is_number() { [[ "$1" =~ ^[0-9]+(\.[0-9]+)?$ ]]; }

record() {  # NAME FAILURE("" = passed)
  names+=("$1"); failures+=("$2")
  if [ -z "$2" ]; then echo "ok   $1"; else echo "FAIL $1: $2"; fi
}
fail_keeping_work() {  # NAME FAILURE: a failed check; the work folder stays for its logs
  record "$1" "$2"
  KEEP_WORK=true
}

# beats POLICY_DSR POLICY_SPEED KEEP_DSR KEEP_SPEED: the policy beats keep as defined above.
beats() {
  for v in "$@"; do is_number "$v" || return 2; done
  awk -v p="$1" -v ps="$2" -v k="$3" -v ks="$4" -v m="$MARGIN" -v share="$SPEED_SHARE" \
    'BEGIN { exit !(p >= k + m && ps >= share * ks) }'
}

read -r dsr speed keep_dsr keep_speed < <(train_and_compare learning "$ROOT/config/training/tiny_fast_learning.yaml" || echo "nan nan nan nan")
echo "learning on:  policy DSR $dsr % at $speed m/s; keep DSR $keep_dsr % at $keep_speed m/s (eval seed $EVAL_SEED)"
# Trainings are not repeatable to the bit (ROS timing), and about one in five of these short
# ones ends in a policy that brakes the tiny road into a jam: a second training on other
# seeds decides then. Learning switched off never came close (1.9–5.2 m/s in four runs).
if ! beats "$dsr" "$speed" "$keep_dsr" "$keep_speed"; then
  read -r dsr speed keep_dsr keep_speed < <(train_and_compare learning_again "$ROOT/config/training/tiny_fast_learning.yaml" 17 || echo "nan nan nan nan")
  echo "learning on, second training (seeds 17..32): policy DSR $dsr % at $speed m/s; keep DSR $keep_dsr % at $keep_speed m/s"
fi
if beats "$dsr" "$speed" "$keep_dsr" "$keep_speed"; then
  record trained_policy_beats_keep ""
else
  fail_keeping_work trained_policy_beats_keep "DSR $dsr % at $speed m/s vs keep $keep_dsr % at $keep_speed m/s: needs keep + $MARGIN points at >= $SPEED_SHARE x its speed (logs: $WORK)"
fi

read -r dsr0 speed0 keep_dsr0 keep_speed0 < <(train_and_compare no_learning "$ROOT/config/training/no_learning.yaml" || echo "nan nan nan nan")
echo "learning off: policy DSR $dsr0 % at $speed0 m/s; keep DSR $keep_dsr0 % at $keep_speed0 m/s"
beats "$dsr0" "$speed0" "$keep_dsr0" "$keep_speed0"; verdict=$?
if [ "$verdict" -eq 1 ]; then
  record untrained_policy_does_not ""
elif [ "$verdict" -eq 2 ]; then
  fail_keeping_work untrained_policy_does_not "the learning-off run failed (logs: $WORK)"
else
  fail_keeping_work untrained_policy_does_not "learning rate 0 gave DSR $dsr0 % at $speed0 m/s vs keep $keep_dsr0 % at $keep_speed0 m/s: the test does not measure learning"
fi

# no_jams POLICY_DIR MAIN_EVAL_DIR: the policy against keep on every (seed, demand) of the
# jam check; the (EVAL_SEED, tiny's own demand) pair is the main evaluation above. Prints
# one line per evaluation; returns 1 if one jammed, 2 if one failed to run.
no_jams() {
  local policy="$1" main_eval="$2" seed demand dir verdict=0
  for seed in $JAM_SEEDS; do
    for demand in $JAM_DEMANDS; do
      dir="$WORK/jam/s$seed-d$demand"
      if [ "$seed" = "$EVAL_SEED" ] && [ "$demand" = 1000 ]; then
        dir="$main_eval"
      else
        "$ROOT/palcas" run --policy "$policy" --no-compare --scenario tiny --duration "$JAM_DURATION" --seed "$seed" \
          --demand "$demand" --bridge-params "$BRIDGE" --out "$dir" >"$WORK/jam-s$seed-d$demand.log" 2>&1 &&
        "$ROOT/palcas" run --arm keep --no-compare --scenario tiny --duration "$JAM_DURATION" --seed "$seed" \
          --demand "$demand" --bridge-params "$BRIDGE" --out "$dir" >>"$WORK/jam-s$seed-d$demand.log" 2>&1 || { verdict=2; echo "learning jam check seed $seed demand $demand: the run failed ($WORK/jam-s$seed-d$demand.log)"; continue; }
      fi
      local p k
      read -r _ p < <(outcome "$dir/palcas/metrics.json" 2>/dev/null || echo "nan nan")
      read -r _ k < <(outcome "$dir/keep/metrics.json" 2>/dev/null || echo "nan nan")
      if ! is_number "$p" || ! is_number "$k"; then
        verdict=2; echo "learning jam check seed $seed demand $demand: no metrics (policy '$p', keep '$k')"; continue
      fi
      if awk -v p="$p" -v k="$k" -v share="$JAM_SHARE" 'BEGIN { exit !(p < share * k) }'; then
        [ "$verdict" -eq 2 ] || verdict=1
        echo "learning jam check seed $seed demand $demand: policy $p m/s < $JAM_SHARE x keep's $k m/s: JAM"
      else
        echo "learning jam check seed $seed demand $demand: policy $p m/s, keep $k m/s"
      fi
    done
  done
  return "$verdict"
}

# The learnt policy that was judged above (the second training's, if there was one).
learnt="$WORK/learning"
[ ! -d "$WORK/learning_again" ] || learnt="$WORK/learning_again"
if [ -d "$learnt/train/checkpoints" ] && [ -f "$learnt/eval/palcas/metrics.json" ]; then
  no_jams "$learnt/train" "$learnt/eval"; verdict=$?
  if [ "$verdict" -eq 0 ]; then
    record trained_policy_does_not_jam ""
  elif [ "$verdict" -eq 1 ]; then
    fail_keeping_work trained_policy_does_not_jam "the policy jammed the road (speed < $JAM_SHARE x keep's on the same seed and demand; lines above; logs: $WORK)"
  else
    fail_keeping_work trained_policy_does_not_jam "an evaluation of the jam check failed (logs: $WORK)"
  fi
else
  fail_keeping_work trained_policy_does_not_jam "no trained policy to check (the training failed; logs: $WORK)"
fi

failed="$(write_junit palcas_learning "$XML")"
[ "$KEEP_WORK" = true ] && echo "work folder kept: $WORK" || rm -rf "$WORK"
echo "palcas_learning: $((${#names[@]} - failed)) passed, $failed failed"
[ "$failed" -eq 0 ]
