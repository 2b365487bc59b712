#!/usr/bin/env bash
# Command-line checks of ./palcas: a bad option of `run`, `train`, `experiment` or `replay`
# (--x y or --x=y) is refused with exit status 2 and a message naming the option, and --help
# exits 0, before anything is installed, built or created.
# Needs no build. `./palcas test` runs it and counts its JUnit file with the other tests.
#
#   test/cli/palcas_cli_test.sh [--xml FILE]
set -uo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck source=../junit.sh
source "$ROOT/test/junit.sh"
XML=""
if [ "${1:-}" = --xml ]; then
  [ $# -ge 2 ] || { echo "palcas_cli_test: --xml needs a file" >&2; exit 2; }
  XML="$2"
fi
WORK="$(mktemp -d)"
export PALCAS_RESULTS_DIR="$WORK/results"  # where a default run or training folder would go
OUT="$WORK/out"                            # the --out of every check

names=() failures=()

finish() {
  [ ${#names[@]} -gt 0 ] || { names+=(no_check_ran); failures+=("the script stopped before its first check"); }
  local failed
  failed="$(write_junit palcas_cli "$XML")"
  rm -rf "$WORK"
  echo "palcas_cli: $((${#names[@]} - failed)) passed, $failed failed"
  [ "$failed" -eq 0 ] && exit 0 || exit 1
}
trap 'finish' EXIT

# check NAME EXPECTED_TEXT ARGS...: ./palcas ARGS exits 2, names EXPECTED_TEXT on stderr,
# and creates neither a results folder nor --out.
check() {
  local name="$1" expect="$2"; shift 2
  local err status=0 why=""
  # A time limit: if the check regressed, ./palcas would go on to build and run.
  err="$(cd "$WORK" && timeout -k 5 60 "$ROOT/palcas" "$@" 2>&1 >/dev/null)" || status=$?
  if [ "$status" -eq 124 ] || [ "$status" -eq 137 ]; then
    why="did not stop within 60 s (it went past the checks)"
  elif [ "$status" -ne 2 ]; then
    why="exit status $status, expected 2; stderr: $err"
  elif [[ "$err" != *"$expect"* ]]; then
    why="stderr does not contain \"$expect\": $err"
  elif [[ "$err" == *"building the workspace"* ]]; then
    why="started a build: $err"
  elif [ -e "$PALCAS_RESULTS_DIR" ] || [ -e "$OUT" ]; then
    why="created a results folder"
  fi
  rm -rf "$PALCAS_RESULTS_DIR" "$OUT"
  names+=("$name"); failures+=("$why")
  if [ -z "$why" ]; then echo "ok   $name"; else echo "FAIL $name: $why"; fi
}

check run_pr_out_of_range      "--pr '150'"                 run --out "$OUT" --pr 150
check run_pr_after_equals_sign "--pr '150'"                 run --out="$OUT" --pr=150
check run_unknown_option       "run: unknown option '--bogus'" run --out "$OUT" --bogus
check train_unknown_option     "train: unknown option '--bogus'" train --out "$OUT" --bogus
check experiment_seeds_text    "experiment: argument --seeds: invalid int value: 'many'" experiment --out="$OUT" --seeds=many
check run_seed_not_an_integer  "--seed 'x'"                 run --out "$OUT" --seed x
check run_duration_not_positive "--duration '0'"            run --out "$OUT" --duration 0
check run_scenario_unknown     "--scenario 'nope'"          run --out "$OUT" --scenario nope
check run_policy_missing       "--policy '/nonexistent'"    run --out "$OUT" --policy /nonexistent
check run_arm_unknown          "--arm 'bogus'"              run --out "$OUT" --arm bogus
check run_pr_without_value     "option --pr needs a value"  run --out "$OUT" --pr
check run_real_time_factor_zero "--real-time-factor '0'"   run --out "$OUT" --rviz --real-time-factor 0
check run_real_time_factor_text "--real-time-factor 'fast'" run --out "$OUT" --real-time-factor fast
check run_real_time_factor_without_value "option --real-time-factor needs a value" run --out "$OUT" --real-time-factor
check run_demand_negative      "--demand '-5'"              run --out "$OUT" --demand -5
check run_demand_not_a_number  "--demand 'lots'"            run --out "$OUT" --demand lots
check run_demand_too_high      "--demand '200000': expected a number in [0, 100000]" run --out "$OUT" --demand 200000
check run_demand_without_value "option --demand needs a value" run --out "$OUT" --demand
check run_ramp_demand_not_a_number "--ramp-demand '5x'"     run --out "$OUT" --ramp-demand 5x
check run_sumo_output_unknown  "--sumo-output 'trips': unknown SUMO output (known: fcd tripinfo" run --out "$OUT" --sumo-output fcd,trips
check run_sumo_output_twice    "--sumo-output 'ssm': named twice" run --out "$OUT" --sumo-output ssm --sumo-output ssm
check run_sumo_output_without_value "option --sumo-output needs a value" run --out "$OUT" --sumo-output
check train_demand_negative    "--demand '-1'"              train --out "$OUT" --demand -1
check train_ramp_demand_too_high "--ramp-demand '1e9'"      train --out "$OUT" --ramp-demand 1e9
check train_demand_range_reversed "--demand-range '2000,1000': MIN 2000 is greater than MAX 1000" train --out "$OUT" --demand-range 2000,1000
check train_demand_range_one_number "--demand-range '1000': expected MIN,MAX" train --out "$OUT" --demand-range 1000
check train_pr_range_out_of_range "--pr-range '10,200': MAX '200'" train --out "$OUT" --pr-range 10,200
check train_demand_and_range   "--demand and --demand-range" train --out "$OUT" --demand 1000 --demand-range 1000,2000
check train_pr_and_range       "--pr and --pr-range"        train --out "$OUT" --pr 40 --pr-range 10,60
check train_arm_keep           "--arm keep"                 train --out "$OUT" --arm keep
check train_episodes_zero      "--episodes '0'"             train --out "$OUT" --episodes 0
check train_seed_without_value "option --seed needs a value" train --out "$OUT" --seed
check train_explore_fraction_zero "--explore-fraction '0'" train --out "$OUT" --explore-fraction 0
check run_scenario_wrong_state "its state has 43 features"  run --out "$OUT" --scenario tiny
# A policy folder whose bridge.yaml is not a mapping of bridge parameters.
BAD_BRIDGE="$WORK/bad_bridge_policy"
mkdir -p "$BAD_BRIDGE"
cp -r "$ROOT/policies/palcas/checkpoints" "$ROOT/policies/palcas/train.json" \
  "$ROOT/policies/palcas/learning_schedule.yaml" "$BAD_BRIDGE/"
printf -- '- not a mapping\n' >"$BAD_BRIDGE/bridge.yaml"
check run_policy_bridge_not_a_mapping "its bridge.yaml is not a YAML mapping" run --out "$OUT" --policy "$BAD_BRIDGE"
rm "$BAD_BRIDGE/bridge.yaml"
printf 'rsu: [1, 2\n' >"$BAD_BRIDGE/rsu.yaml"  # not YAML at all
check run_policy_rsu_not_a_mapping "its rsu.yaml is not a YAML mapping of RSU parameters" run --out "$OUT" --policy "$BAD_BRIDGE"
check train_bridge_params_missing "--bridge-params '/nonexistent'" train --out "$OUT" --bridge-params /nonexistent
check experiment_arm_unknown   "--arms: unknown arm 'bogus'" experiment --out "$OUT" --arms keep,bogus
check experiment_pr_out_of_range "--prs: 150 is outside"    experiment --out "$OUT" --arms keep --prs 5,150
check experiment_seeds_zero    "--seeds: 0 must be >= 1"     experiment --out "$OUT" --arms keep --seeds 0
check experiment_policy_wrong_road "trained on road paper"  experiment --out "$OUT" --arms palcas --scenario tiny
check experiment_without_out   "--out"                       experiment --arms keep
check experiment_demand_zero   "--demands: 0 is outside"     experiment --out "$OUT" --arms keep --demands 1000,0
check experiment_demand_text   "--demands: 'many' is not valid" experiment --out "$OUT" --arms keep --demands many
# replay: a missing bag or policy, a bad value, --rate without --rviz (the bag's content is
# checked by replay_policy itself: test/launch/policy_replay.test).
ANY_FILE="$ROOT/README.md"
check replay_without_bag       "no bag given"                replay --policy "$ROOT/policies/palcas"
check replay_bag_missing       "bag '/nonexistent.bag': no such file" replay /nonexistent.bag --policy "$ROOT/policies/palcas"
check replay_without_policy    "--policy DIR is required"    replay "$ANY_FILE"
check replay_policy_missing    "--policy '/nonexistent'"     replay "$ANY_FILE" --policy /nonexistent
check replay_tolerance_text    "--accel-tolerance 'tight'"   replay "$ANY_FILE" --policy "$ROOT/policies/palcas" --accel-tolerance tight
check replay_learning_missing  "--learning '/nonexistent'"   replay "$ANY_FILE" --policy "$ROOT/policies/palcas" --learning /nonexistent
check replay_unknown_option    "replay: unknown option '--bogus'" replay "$ANY_FILE" --bogus
check replay_rate_zero         "--rate '0'"                  replay "$ANY_FILE" --rviz --rate 0
check replay_rate_without_rviz "--rate goes with --rviz"     replay "$ANY_FILE" --policy "$ROOT/policies/palcas" --rate 2
check replay_rviz_with_policy  "it takes only --rate"        replay "$ANY_FILE" --rviz --policy "$ROOT/policies/palcas"

# --help of every command: exit 0, every option with its default, nothing built or created.
check_help() {  # COMMAND
  local out status=0 why=""
  out="$(cd "$WORK" && timeout -k 5 60 "$ROOT/palcas" "$1" --help 2>&1)" || status=$?
  if [ "$status" -ne 0 ]; then why="exit status $status, expected 0: $out"
  elif [[ "$out" != *"(default: "* ]]; then why="no defaults listed: $out"
  elif [[ "$out" == *"building the workspace"* ]]; then why="started a build: $out"
  elif [ -e "$PALCAS_RESULTS_DIR" ]; then why="created a results folder"
  fi
  names+=("$1_help"); failures+=("$why")
  if [ -z "$why" ]; then echo "ok   $1_help"; else echo "FAIL $1_help: $why"; fi
}
for command in run train experiment replay; do check_help "$command"; done

# --resume takes road, PR, seed and duration from the training record and refuses a flag
# that contradicts it (a fake record: these checks stop before anything is built or run).
RESUME="$WORK/resume_me"
mkdir -p "$RESUME/checkpoints"
printf '{"arm": "palcas", "scenario": "tiny", "pr": 40, "seed": 3, "episodes": 4, "duration_s": 300, "learning": "", "rsu_params": "", "bridge_params": "", "paper_printed": false, "explore_fraction": 0.5, "git_commit": "x"}\n' >"$RESUME/train.json"
check_resume() {  # NAME EXPECTED_TEXT ARGS...: like check, but the record must stay untouched
  local name="$1" expect="$2"; shift 2
  local err status=0 why="" before; before="$(cat "$RESUME/train.json")"
  err="$(cd "$WORK" && timeout -k 5 60 "$ROOT/palcas" train --resume --out "$RESUME" "$@" 2>&1 >/dev/null)" || status=$?
  if [ "$status" -ne 2 ]; then why="exit status $status, expected 2; stderr: $err"
  elif [[ "$err" != *"$expect"* ]]; then why="stderr does not contain \"$expect\": $err"
  elif [ "$(cat "$RESUME/train.json")" != "$before" ]; then why="train.json was rewritten"
  fi
  names+=("$name"); failures+=("$why")
  if [ -z "$why" ]; then echo "ok   $name"; else echo "FAIL $name: $why"; fi
}
check_resume resume_other_pr       "trained with --pr 40, not --pr 60"           --pr 60
check_resume resume_other_duration "trained with --duration 300, not --duration 3600" --duration 3600
check_resume resume_other_scenario "trained with --scenario tiny, not --scenario paper" --scenario paper
check_resume resume_other_explore  "leave --explore-fraction out"                --explore-fraction 0.3
check_resume resume_other_demand   "trained with --demand (the scenario's), not --demand 1400" --demand 1400
