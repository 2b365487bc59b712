// metrics_from_bag: recomputes an episode's metrics from its bag with the same code the
// bridge runs live (EpisodeMeasure), and optionally compares them with the live
// metrics.json.
//
//   metrics_from_bag BAG [--manifest manifest.json] [--compare metrics.json]
//
// Prints the recomputed metrics as JSON. With --compare, exits 2 when a metric differs.
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "palcas_sumo_bridge/episode_measure.h"
#include "palcas_sumo_bridge/run_files.h"

namespace {

using nlohmann::json;
using palcas::bridge::EpisodeMeasure;

json value(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json toJson(const palcas::metrics::EpisodeMetrics& m) {
  return {{"efficiency_all_mps", value(m.efficiency_all_mps)},
          {"efficiency_cav_mps", value(m.efficiency_cav_mps)},
          {"collision_rate_pct", value(m.collision_rate_pct)},
          {"dsr_pct", value(m.dsr_pct)},
          {"msr_pct", value(m.msr_pct)},
          {"comfort_share_pct", value(m.comfort_share_pct)},
          {"throughput_vph", value(m.throughput_vph)},
          {"mean_travel_time_s", value(m.mean_travel_time_s)},
          {"lane_changes_per_cav", value(m.lane_changes_per_cav)},
          {"arrived", m.arrived},
          {"cav_lane_changes", m.cav_lane_changes},
          {"collisions", m.collisions},
          {"teleports", m.teleports},
          {"cavs_seen", m.cavs_seen},
          {"exiting_cavs", m.exiting_cavs},
          {"merging_cavs", m.merging_cavs},
          {"sim_seconds", m.sim_seconds}};
}

/// Relative agreement for reals (summation order is identical, so this is tight), exact
/// for counts; null equals null.
bool agrees(const json& a, const json& b) {
  if (a.is_null() || b.is_null()) return a.is_null() && b.is_null();
  if (a.is_number_integer() && b.is_number_integer()) return a == b;
  const double x = a.get<double>(), y = b.get<double>();
  return std::abs(x - y) <= 1e-9 * std::max(1.0, std::abs(y));
}

int run(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::cerr << "usage: metrics_from_bag BAG [--manifest manifest.json] [--compare metrics.json]\n";
    return argc < 2 ? 1 : 0;
  }
  const std::string bag_path = argv[1];
  std::string manifest = (std::filesystem::path(bag_path).parent_path() / "manifest.json").string();
  std::string compare;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--manifest") manifest = argv[i + 1];
    else if (flag == "--compare") compare = argv[i + 1];
    else throw std::invalid_argument("unknown option '" + flag + "'");
  }
  EpisodeMeasure measure(palcas::bridge::readMeasureRules(manifest));

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::map<std::uint64_t, palcas_msgs::VehicleStateArray::ConstPtr> states;
  std::map<std::uint64_t, palcas_msgs::VehicleEventArray::ConstPtr> events;
  const std::vector<std::string> topics{"/vehicle_states", "/vehicle_events"};
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topics))) {
    if (auto s = m.instantiate<palcas_msgs::VehicleStateArray>()) states[s->step] = s;
    if (auto e = m.instantiate<palcas_msgs::VehicleEventArray>()) events[e->step] = e;
  }
  if (states.empty()) throw std::runtime_error("'" + bag_path + "' holds no /vehicle_states");
  std::uint64_t expected = states.begin()->first;
  if (expected != 0)
    std::cerr << "warning: the bag starts at step " << expected << ", not 0: early steps are missing\n";
  std::uint64_t gaps = 0;
  for (const auto& [step, s] : states) {
    if (step != expected) ++gaps;
    expected = step + 1;
    auto e = events.find(step);
    measure.onStep(*s, e == events.end() ? palcas::metrics::StepRemovals{}
                                         : palcas::bridge::removalsFromEvents(*e->second));
  }
  if (gaps) std::cerr << "warning: " << gaps << " gap(s) in the step sequence\n";
  json recomputed = toJson(measure.metrics().snapshot());
  recomputed["exits_by_cluster"] = palcas::bridge::exitsJson(measure.cavExits());
  std::cout << recomputed.dump(2) << "\n";
  if (compare.empty()) return 0;
  std::ifstream in(compare);
  if (!in) throw std::runtime_error("cannot read '" + compare + "'");
  const json live = json::parse(in);
  int differences = 0;
  for (const auto& [key, v] : recomputed.items()) {
    if (!live.contains(key)) continue;
    // exits_by_cluster: the same counts and the same division, so equal exactly.
    if (v.is_array() ? v != live[key] : !agrees(v, live[key])) {
      std::cerr << "differs: " << key << " bag=" << v << " live=" << live[key] << "\n";
      ++differences;
    }
  }
  std::cerr << (differences ? "bag and live metrics DIFFER\n" : "bag and live metrics agree\n");
  return differences ? 2 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "metrics_from_bag: " << e.what() << "\n";
    return 1;
  }
}
