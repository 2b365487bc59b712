#!/usr/bin/env bash
# What each departure from the printed paper buys, measured the way the learning regression
# test measures learning: for every file of config/training/ablations/ (one departure set
# back to the paper's value) plus "ours" (none) and "paper_printed" (all of them, bridge
# included), a seeded training on the tiny road (16 x 300 s, small network) and a greedy
# 600 s evaluation on an unseen seed (101), beside keep. Prints a Markdown table; folders stay in OUT.
#
#   tools/ablation_tiny.sh OUT [NAME ...]     (default: every ablation)
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:?usage: tools/ablation_tiny.sh OUT [NAME ...]}"; shift
mkdir -p "$OUT"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  names=(ours paper_printed)
  for f in "$ROOT"/config/training/ablations/*.yaml; do names+=("$(basename "$f" .yaml)"); done
fi
for name in "${names[@]}"; do
  [ -f "$OUT/$name/eval/palcas/metrics.json" ] && continue  # done before
  extra=()
  case "$name" in
    ours) ;;
    paper_printed) extra=(--paper-printed) ;;
    *) # the departure file merged over the federation interval of short_rsu.yaml
       /usr/bin/python3 - "$ROOT/config/training/short_rsu.yaml" "$ROOT/config/training/ablations/$name.yaml" \
         "$OUT/$name.rsu.yaml" <<'PY'
import sys, yaml
doc = yaml.safe_load(open(sys.argv[1])) or {}
for k, v in (yaml.safe_load(open(sys.argv[2])) or {}).items():
    doc.setdefault(k, {}).update(v)
yaml.safe_dump(doc, open(sys.argv[3], "w"))
PY
       extra=(--rsu-params "$OUT/$name.rsu.yaml") ;;
  esac
  rsu=(--rsu-params "$ROOT/config/training/short_rsu.yaml")
  [[ " ${extra[*]:-} " == *" --rsu-params "* ]] && rsu=()
  rm -rf "$OUT/$name"
  "$ROOT/palcas" train --scenario tiny --episodes 16 --duration 300 --seed 1 \
    --learning "$ROOT/config/training/tiny_fast_learning.yaml" "${rsu[@]}" "${extra[@]}" \
    --out "$OUT/$name/train" >"$OUT/$name.log" 2>&1
  "$ROOT/palcas" run --policy "$OUT/$name/train" --scenario tiny --duration 600 --seed 101 \
    --out "$OUT/$name/eval" >>"$OUT/$name.log" 2>&1
done
/usr/bin/python3 - "$OUT" "${names[@]}" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
print("| variant | DSR % | keep DSR % | speed m/s | keep speed m/s | MSR % | CR % | comfort % |")
print("|---|---|---|---|---|---|---|---|")
for name in sys.argv[2:]:
    try:
        p = json.loads((out / name / "eval/palcas/metrics.json").read_text())
        k = json.loads((out / name / "eval/keep/metrics.json").read_text())
    except (OSError, ValueError):
        print(f"| {name} | failed | | | | | | |")
        continue
    print(f"| {name} | {p['dsr_pct']:.1f} | {k['dsr_pct']:.1f} | {p['efficiency_all_mps']:.2f} | "
          f"{k['efficiency_all_mps']:.2f} | {p['msr_pct']:.1f} | {p['collision_rate_pct']:.2f} | "
          f"{p['comfort_share_pct']:.1f} |")
PY
