#pragma once
// Helpers shared by the scenario tests: a fresh temporary folder per test, the scenario and
// test-data folders, the tiny road and file reading.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "palcas_sim/road_spec.h"
#include "palcas_sim/scenario.h"
#include "palcas_sim/sumo_session.h"

namespace palcas::sim::test {

/// A new empty folder under the system temp dir, unique per process and name.
inline std::string freshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("palcas_scenario_" + std::to_string(getpid()) + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

/// config/scenarios/<name>: the tests read only its vtypes.xml.
inline std::string scenarioDir(const std::string& name) {
  return std::string(PALCAS_CONFIG_DIR) + "/scenarios/" + name;
}

/// sim/test/data/hand_written_<name>: the former hand-written network sources (paper, tiny).
inline std::string handWrittenDir(const std::string& name) {
  return std::string(PALCAS_SIM_TEST_DATA_DIR) + "/hand_written_" + name;
}

/// The tiny road (config/scenarios/README.md): 2 clusters x 300 m, 3 lanes; warm-up 40 m, on-ramp
/// joins at +60, 100 m acceleration lane, exit at +240; widths and speeds as the paper's.
inline RoadSpec tinyRoad() {
  RoadSpec r;
  r.clusters = 2;
  r.num_lanes = 3;
  r.cluster_length_m = 300.0;
  r.warmup_length_m = 40.0;
  r.merge_start_m = 60.0;
  r.acceleration_lane_m = 100.0;
  r.exit_m = 240.0;
  return r;
}

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

// In-process session options on the tiny road with every vehicle a CAV (plenty of
// candidates), advisory control and the actuation config/bridge.yaml ships; mainline_vphpl > 0
// sets the mainline demand [veh/h/lane] (else ScenarioConfig's default).
inline SessionOptions sessionOnTiny(const std::string& dir_name, unsigned seed = 3, double mainline_vphpl = 0.0) {
  ScenarioConfig c;
  if (mainline_vphpl > 0.0) c.mainline_flow_vphpl = mainline_vphpl;
  c.scenario_dir = scenarioDir("tiny");
  c.road = tinyRoad();  // default route shares for its two clusters
  c.penetration_rate = 1.0;
  c.duration_s = 400.0;
  c.seed = seed;
  const auto files = writeScenario(c, freshDir(dir_name));
  SessionOptions o;
  o.sumo_args = {"-c", files.sumocfg_file, "--no-warnings", "true", "--no-step-log", "true",
                 "--time-to-teleport.remove", "true"};
  o.cluster_length_m = 300.0;
  o.advisory_control = true;
  o.own_car_following = true;
  o.own_merge = true;
  o.cav_lane_change_mode = 1536;
  return o;
}

/// sessionOnTiny with every zone busy from its first window (no zone's speed share reaches
/// 1.5 of its top speeds), its CAVs handed back to SUMO's own lane changing (1621, default gap
/// acceptance), and the busy zones' change bound at `bound_mps2` for `hold_s` after a change,
/// not below `floor_share` of a CAV's allowed speed.
inline SessionOptions sessionOnTinyEveryZoneBusy(const std::string& dir_name, unsigned seed, double bound_mps2,
                                                 double hold_s, double floor_share) {
  SessionOptions o = sessionOnTiny(dir_name, seed);
  o.guard.busy_speed_share = 1.5;
  o.guard.busy_leave_share = 1.6;
  o.guard.busy_window_s = 1.0;
  o.guard.busy_handback = true;
  o.assist_lane_change_mode = 1621;
  o.guard.busy_lc_assertive = 0.0;
  o.guard.floor_speed_share = floor_share;
  o.guard.busy_change_max_accel_mps2 = bound_mps2;
  o.guard.busy_change_hold_s = hold_s;
  o.guard.insertion_edge = false;
  return o;
}

}  // namespace palcas::sim::test
