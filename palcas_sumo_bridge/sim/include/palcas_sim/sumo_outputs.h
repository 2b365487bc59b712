#pragma once
// SUMO's own output files (FCD, trip info, SSM, lane changes, collisions, summary,
// statistics), switched on by name for a run: `sumo_outputs` in config/bridge.yaml or
// `./palcas run --sumo-output NAME`. They are written beside the run's metrics.json.

#include <string>
#include <vector>

namespace palcas::sim {

/// One output SUMO can write: its name here, its file name in the run folder, what it holds.
struct SumoOutputKind {
  const char* name;
  const char* file_name;
  const char* content;
};

/// Every output known by name, in a fixed order (documentation and error messages list them).
const std::vector<SumoOutputKind>& sumoOutputKinds();

/// The SUMO command-line arguments that write the named outputs into `dir`.
/// `fcd_period_s` is the FCD sampling period (0 = every step: large files).
/// SSM devices are assigned deterministically (no draw from SUMO's random stream, so the
/// traffic is the same with and without the output). @throws std::invalid_argument naming an
/// unknown or repeated output, or a negative period.
std::vector<std::string> sumoOutputArgs(const std::vector<std::string>& names, const std::string& dir,
                                        double fcd_period_s);

}  // namespace palcas::sim
