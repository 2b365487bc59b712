#!/usr/bin/env bash
# Times the bare `sumo` binary on the paper scenario (default PR 0.6, 1 h simulated, no output
# files), the reference for the bridge's overhead. Generates the scenario with palcas_sim's
# own writer (compiled here from the sources: no catkin build needed), then runs
#   sumo -c scenario.sumocfg --duration-log.statistics --no-warnings
# and prints wall seconds, real-time factor and SUMO's vehicle statistics.
# Usage: tools/bare_sumo_timing.sh            (env: PR=0.6 DURATION_S=3600 SEED=42 KEEP=0)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SIM="$ROOT/palcas_sumo_bridge/sim"
PR="${PR:-0.6}"
DURATION_S="${DURATION_S:-3600}"
SEED="${SEED:-42}"
WORK="$(mktemp -d /tmp/palcas_bare_sumo.XXXXXX)"
[[ "${KEEP:-0}" == 1 ]] || trap 'rm -rf "$WORK"' EXIT

for tool in g++ sumo netconvert; do
  command -v "$tool" > /dev/null || { echo "error: '$tool' not found on PATH" >&2; exit 1; }
done

cat > "$WORK/write_scenario.cpp" <<'CPP'
#include <iostream>
#include <string>
#include "palcas_sim/scenario.h"
int main(int argc, char** argv) {
  if (argc != 6) { std::cerr << "usage: scenario_dir out_dir pr duration_s seed\n"; return 2; }
  try {
    palcas::sim::ScenarioConfig c;  // the paper's defaults (scenario.h)
    c.scenario_dir = argv[1];
    c.penetration_rate = std::stod(argv[3]);
    c.duration_s = std::stod(argv[4]);
    c.seed = static_cast<unsigned int>(std::stoul(argv[5]));
    std::cout << palcas::sim::writeScenario(c, argv[2]).sumocfg_file << "\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
CPP
g++ -std=c++17 -O2 -I"$SIM/include" -I"$SIM/lib" "$WORK/write_scenario.cpp" \
  "$SIM/lib/scenario_xml.cpp" "$SIM/lib/scenario_network.cpp" "$SIM/lib/scenario_config.cpp" \
  "$SIM/lib/scenario_writer.cpp" "$SIM/lib/road_layout.cpp" "$SIM/lib/road_spec.cpp" -o "$WORK/write_scenario"
CFG="$("$WORK/write_scenario" "$ROOT/config/scenarios/paper" "$WORK/scenario" "$PR" "$DURATION_S" "$SEED")"

echo "scenario: paper, PR $PR, ${DURATION_S} s simulated, seed $SEED, step 0.1 s ($CFG)"
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg), $(sumo --version | head -1)"
START_NS=$(date +%s%N)
sumo -c "$CFG" --duration-log.statistics --no-warnings > "$WORK/sumo.log" 2>&1
END_NS=$(date +%s%N)
WALL_S=$(awk -v a="$START_NS" -v b="$END_NS" 'BEGIN { printf "%.2f", (b - a) / 1e9 }')
RTF=$(awk -v d="$DURATION_S" -v w="$WALL_S" 'BEGIN { printf "%.2f", d / w }')
echo "wall (process, including network load): ${WALL_S} s"
echo "real-time factor (simulated / wall): ${RTF}"
echo "--- SUMO's own summary ---"
sed -n '/^Performance:/,$p' "$WORK/sumo.log"
