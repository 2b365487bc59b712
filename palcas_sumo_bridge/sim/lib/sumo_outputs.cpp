#include "palcas_sim/sumo_outputs.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace palcas::sim {

const std::vector<SumoOutputKind>& sumoOutputKinds() {
  static const std::vector<SumoOutputKind> kinds{
      {"fcd", "sumo_fcd.xml", "every vehicle's position, speed, acceleration and lane (--fcd-output)"},
      {"tripinfo", "sumo_tripinfo.xml", "one line per finished trip: depart, arrival, duration, waiting time (--tripinfo-output)"},
      {"ssm", "sumo_ssm.xml", "surrogate safety measures per encounter: TTC, DRAC, PET (--device.ssm.*)"},
      {"lanechange", "sumo_lanechange.xml", "every lane change: who, where, why (--lanechange-output)"},
      {"collision", "sumo_collision.xml", "every collision: who, where, lateral and longitudinal gap (--collision-output)"},
      {"summary", "sumo_summary.xml", "per step: vehicles loaded, running, waiting, arrived, mean speed (--summary-output)"},
      {"statistic", "sumo_statistic.xml", "the run's totals: teleports, collisions, trip statistics (--statistic-output)"},
  };
  return kinds;
}

namespace {

std::string knownNames() {
  std::string out;
  for (const SumoOutputKind& k : sumoOutputKinds()) out += (out.empty() ? "" : ", ") + std::string(k.name);
  return out;
}

}  // namespace

std::vector<std::string> sumoOutputArgs(const std::vector<std::string>& names, const std::string& dir,
                                        double fcd_period_s) {
  if (!std::isfinite(fcd_period_s) || fcd_period_s < 0.0)
    throw std::invalid_argument("sumo_fcd_period_s must be >= 0, got " + std::to_string(fcd_period_s));
  std::vector<std::string> args;
  std::vector<std::string> seen;
  for (const std::string& name : names) {
    const auto& kinds = sumoOutputKinds();
    auto kind = std::find_if(kinds.begin(), kinds.end(), [&](const SumoOutputKind& k) { return name == k.name; });
    if (kind == kinds.end())
      throw std::invalid_argument("unknown SUMO output '" + name + "' (known: " + knownNames() + ")");
    if (std::find(seen.begin(), seen.end(), name) != seen.end())
      throw std::invalid_argument("SUMO output '" + name + "' named twice");
    seen.push_back(name);
    const std::string file = dir + "/" + kind->file_name;
    if (name == "fcd") {
      args.insert(args.end(), {"--fcd-output", file, "--fcd-output.acceleration", "true"});
      if (fcd_period_s > 0.0) args.insert(args.end(), {"--device.fcd.period", std::to_string(fcd_period_s)});
    } else if (name == "tripinfo") {
      args.insert(args.end(), {"--tripinfo-output", file});
    } else if (name == "ssm") {
      // Every vehicle carries the device; "deterministic" assigns it without a random draw.
      args.insert(args.end(), {"--device.ssm.probability", "1", "--device.ssm.deterministic", "true",
                               "--device.ssm.file", file, "--device.ssm.measures", "TTC DRAC PET"});
    } else if (name == "lanechange") {
      args.insert(args.end(), {"--lanechange-output", file});
    } else if (name == "collision") {
      args.insert(args.end(), {"--collision-output", file});
    } else if (name == "summary") {
      args.insert(args.end(), {"--summary-output", file});
    } else {
      args.insert(args.end(), {"--statistic-output", file});
    }
  }
  return args;
}

}  // namespace palcas::sim
