// replay_policy: the RSUs of a policy run OPEN LOOP on a recorded episode (a rosbag of
// `./palcas run --record` / system.launch record:=true), their advisories compared with the
// recorded ones. Every decision is made by the RSU node's own decision path (RsuDecider:
// the same snapshot conversion, V2X uplink, I2I bookkeeping, decision period and policy
// loading order), eval mode, with the recorded cluster states and, where the bag says which
// neighbours' densities the live RSU used, those. Usage and output:
// palcas_rsu/README.md, "replay_policy".
//
// The RSU parameters (config/rsu.yaml, reward.yaml, learning.yaml, departures.yaml and
// overrides) are read from the parameter server under ~ exactly as the node reads them;
// `./palcas replay` starts a private master and loads them.

#include <palcas_core/learning/model_blob.h>
#include <palcas_core/state/state_layout.h>
#include <palcas_core/v2x/v2x_channel.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/ClusterState.h>
#include <palcas_msgs/RoadDescription.h>
#include <palcas_msgs/VehicleStateArray.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "palcas_rsu/msg_conversion.h"
#include "palcas_rsu/replay_comparison.h"
#include "palcas_rsu/rsu_decider.h"
#include "palcas_rsu/rsu_options.h"

namespace fs = std::filesystem;
using palcas::rsu::RsuNodeOptions;

namespace {

constexpr char STATES_TOPIC[] = "/vehicle_states";
constexpr char ADVISORIES_TOPIC[] = "/advisories";
constexpr char CLUSTER_TOPIC[] = "/cluster_states";
constexpr char ROAD_TOPIC[] = "/road_description";

/// Bad input (not a bag, missing topics, no model, a model that does not fit): exit 1.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// Two I2I densities agree when both are unknown (NaN) or equal.
bool sameDensity(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

/// The road as the bag describes it.
struct Road {
  std::vector<double> zones_m;
  int num_lanes = 0;
  std::string source;
};

/// DIR is a training's checkpoints/ folder or a policy folder containing checkpoints/.
fs::path checkpointsOf(const std::string& dir) {
  if (!fs::is_directory(dir)) throw InputError("--policy '" + dir + "': no such folder");
  if (fs::is_directory(fs::path(dir) / "checkpoints")) return fs::path(dir) / "checkpoints";
  return fs::path(dir);
}

/// The state size a model file's networks take (the first Linear layer of the parameter
/// network), or -1 when its layout does not say.
long stateSizeOfLayout(const std::string& layout) {
  const std::string key = "mu[Linear(";
  const auto at = layout.find(key);
  if (at == std::string::npos) return -1;
  return std::strtol(layout.c_str() + at + key.size(), nullptr, 10);
}

bool hasTopic(rosbag::Bag& bag, const std::string& topic) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  return view.size() > 0;
}

Road readRoad(rosbag::Bag& bag, int lanes_in_states) {
  Road road;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(ROAD_TOPIC))) {
    if (auto r = m.instantiate<palcas_msgs::RoadDescription>()) {
      road.zones_m = r->zone_boundaries_m;
      road.num_lanes = r->num_lanes;
      road.source = ROAD_TOPIC;
      break;
    }
  }
  if (road.zones_m.empty()) {
    // A bag recorded before the road was: its I2I messages name every zone that published.
    std::map<int, std::pair<double, double>> zones;
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(CLUSTER_TOPIC)))
      if (auto c = m.instantiate<palcas_msgs::ClusterState>()) zones[c->cluster_index] = {c->x_start_m, c->x_end_m};
    bool contiguous = !zones.empty() && zones.begin()->first == 0;
    int expect = 0;
    for (const auto& [k, span] : zones) {
      if (k != expect++ || (!road.zones_m.empty() && std::abs(road.zones_m.back() - span.first) > 1e-6)) {
        contiguous = false;
        break;
      }
      if (road.zones_m.empty()) road.zones_m.push_back(span.first);
      road.zones_m.push_back(span.second);
    }
    if (!contiguous)
      throw InputError(std::string("the bag has no ") + ROAD_TOPIC + " (recorded since the bridge publishes it) and its " +
                       CLUSTER_TOPIC + " do not give every zone: the RSUs' zones are unknown");
    road.num_lanes = lanes_in_states;
    road.source = std::string(CLUSTER_TOPIC) + " (no " + ROAD_TOPIC + " in the bag)";
  }
  if (road.num_lanes != lanes_in_states)
    throw InputError("the bag's road has " + std::to_string(road.num_lanes) + " lanes but its " + STATES_TOPIC +
                     " say " + std::to_string(lanes_in_states));
  return road;
}

/// One replayed RSU: its controller and I2I bookkeeping, as RsuNode holds them.
struct ReplayedRsu {
  std::string id;
  /// The RSU node's own decision path (rsu_decider.h), evaluating the policy: the same V2X
  /// uplink, I2I bookkeeping and controller call as the live RSU.
  std::unique_ptr<palcas::rsu::RsuDecider> decider;
  fs::path model;
};

int run(const palcas::rsu::ReplayArgs& args) {
  if (!fs::is_regular_file(args.bag)) throw InputError("'" + args.bag + "': no such file");
  rosbag::Bag bag;
  try {
    bag.open(args.bag, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw InputError("'" + args.bag + "' is not a bag (" + e.what() + ")");
  }
  std::vector<std::string> missing;
  for (const char* t : {STATES_TOPIC, ADVISORIES_TOPIC})
    if (!hasTopic(bag, t)) missing.push_back(t);
  if (!missing.empty()) {
    std::string names;
    for (const auto& t : missing) names += (names.empty() ? "" : ", ") + t;
    throw InputError("the bag '" + args.bag + "' lacks " + names +
                     " (replay needs the recorded vehicle states and advisories: record with ./palcas run --record; "
                     "a keep or sumo_native run has no RSU to replay)");
  }
  int lanes_in_states = 0;
  double step_length_s = 0.0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(STATES_TOPIC)))
    if (auto s = m.instantiate<palcas_msgs::VehicleStateArray>()) {
      lanes_in_states = s->num_lanes;
      step_length_s = s->step_length_s;
      break;
    }
  const Road road = readRoad(bag, lanes_in_states);
  const int state_size = static_cast<int>(palcas::StateLayout(road.num_lanes).size());

  // What the recording RSUs said, and who they were.
  std::map<std::pair<std::uint64_t, std::string>, palcas_msgs::AdvisoryArray> recorded;
  std::set<std::string> rsu_ids;
  std::string other_definition;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(ADVISORIES_TOPIC))) {
    if (auto a = m.instantiate<palcas_msgs::AdvisoryArray>()) {
      rsu_ids.insert(a->rsu_id);
      recorded[{a->step, a->rsu_id}] = *a;
    } else if (other_definition.empty()) {
      other_definition = m.getMD5Sum();
    }
  }
  if (rsu_ids.empty() && !other_definition.empty())
    throw InputError("the bag's " + std::string(ADVISORIES_TOPIC) + " were recorded with another definition of " +
                     "palcas_msgs/AdvisoryArray (md5 " + other_definition + ", this build's " +
                     ros::message_traits::MD5Sum<palcas_msgs::AdvisoryArray>::value() +
                     "): record it again with this version");
  // I2I: every cluster state in stamp order, fed to the RSUs up to each decision's time.
  std::vector<palcas_msgs::ClusterState> cluster_states;
  std::map<std::string, int> cluster_of;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(CLUSTER_TOPIC)))
    if (auto c = m.instantiate<palcas_msgs::ClusterState>()) {
      cluster_states.push_back(*c);
      cluster_of[c->rsu_id] = c->cluster_index;
    }
  std::stable_sort(cluster_states.begin(), cluster_states.end(),
                   [](const auto& a, const auto& b) { return a.header.stamp < b.header.stamp; });
  // The RSUs shared cluster states only with I2I on (palcas, palcas_assist, no_priority).
  const bool i2i = !cluster_states.empty();
  if (rsu_ids.empty()) throw InputError("the bag's " + std::string(ADVISORIES_TOPIC) + " name no RSU");

  // Options: the node's own loader on the parameters under ~, then this RSU's identity and
  // the recorded road, as the node adopts the bridge's.
  ros::NodeHandle private_nh("~");
  const RsuNodeOptions base = palcas::rsu::loadRsuNodeOptions(private_nh);
  const fs::path checkpoints = checkpointsOf(args.policy);
  std::vector<ReplayedRsu> rsus;
  for (const std::string& id : rsu_ids) {
    ReplayedRsu r;
    r.id = id;
    RsuNodeOptions options = base;
    palcas::rsu::RsuControllerOptions& c = options.controller;
    c.rsu_id = id;
    c.train = false;
    options.whole_road = id == "central";  // the centralized baseline's one agent
    options.i2i = i2i && !options.whole_road;
    if (auto it = cluster_of.find(id); it != cluster_of.end()) {
      c.cluster_index = it->second;
    } else if (id.rfind("rsu_", 0) == 0 && id.size() > 4 &&
               id.find_first_not_of("0123456789", 4) == std::string::npos) {
      c.cluster_index = std::stoi(id.substr(4));
    } else if (!options.whole_road) {
      throw InputError("RSU '" + id + "' in the bag: its cluster is unknown (not rsu_<k>, central, nor in " +
                       CLUSTER_TOPIC + ")");
    }
    if (!options.zones_m.empty()) palcas::rsu::applyZones(options, "zones_m");
    try {
      palcas::rsu::adoptBridgeRoad(options, road.zones_m, road.num_lanes);
    } catch (const std::invalid_argument& e) {
      throw InputError(id + " on the recorded road: " + e.what());
    }
    try {
      r.model = palcas::rsu::policyFileIn(checkpoints.string(), id);
    } catch (const std::runtime_error& e) {
      throw InputError(e.what());
    }
    palcas::ModelBlob blob;
    try {
      blob = palcas::loadModelBlob(r.model.string());
    } catch (const std::exception& e) {
      throw InputError("'" + r.model.string() + "' is not a PALCAS model: " + e.what());
    }
    const long model_states = stateSizeOfLayout(blob.layout_id);
    if (model_states >= 0 && model_states != state_size)
      throw InputError("the model '" + r.model.string() + "' takes a state of " + std::to_string(model_states) +
                       " features, but the recorded road has " + std::to_string(road.num_lanes) +
                       " lanes: its state has " + std::to_string(palcas::LANE_INDEPENDENT_FEATURE_COUNT) + " + " + std::to_string(road.num_lanes) + " = " +
                       std::to_string(state_size) + " (a policy trained on another road)");
    if (options.v2x.enabled) {
      try {
        palcas::v2x::Channel check(options.v2x, step_length_s);  // the RSU builds it at the first state
      } catch (const std::invalid_argument& e) {
        throw InputError(id + ": the recorded V2X channel: " + e.what());
      }
    }
    options.policy_dir = checkpoints.string();
    options.resume = false;
    options.checkpoint_dir.clear();
    try {
      r.decider = std::make_unique<palcas::rsu::RsuDecider>(options);
    } catch (const std::exception& e) {
      throw InputError("the model '" + r.model.string() + "' does not fit the RSU network these parameters " +
                       "build (give the learning override the policy was trained with: --learning FILE): " + e.what());
    }
    rsus.push_back(std::move(r));
  }
  const int period = base.decision_period_steps;

  std::ofstream csv(args.csv);
  if (!csv) throw InputError("cannot write the CSV '" + args.csv + "'");
  csv << palcas::rsu::ReplayComparison::CSV_HEADER << "\n";

  std::printf("replay: %s\n  road: %zu zone(s), %d lanes (state size %d) from %s; decision every %d steps; I2I %s%s\n",
              args.bag.c_str(), road.zones_m.size() - 1, road.num_lanes, state_size, road.source.c_str(), period,
              i2i ? "on" : "off", base.v2x.enabled ? "; V2X channel on (as recorded: the uplink replayed step by step)" : "");
  for (const ReplayedRsu& r : rsus)
    std::printf("  %s [%.0f, %.0f) m: %s\n", r.id.c_str(), r.decider->options().controller.x_start_m,
                r.decider->options().controller.x_end_m, r.model.c_str());

  palcas::rsu::ReplayComparison comparison(args.accel_tolerance);
  std::uint64_t decisions_unrecorded = 0, decision_steps = 0, not_decided = 0;
  std::set<std::pair<std::uint64_t, std::string>> answered;  // recorded (step, rsu) the replay reached
  std::size_t next_cluster_state = 0;
  std::uint64_t i2i_delivered_otherwise = 0;  // decisions whose live peer states differ from the bag's order

  std::optional<std::uint64_t> previous_step;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(STATES_TOPIC))) {
    const auto states = m.instantiate<palcas_msgs::VehicleStateArray>();
    if (!states) continue;
    // Advisories and cluster states are matched by step and time: one episode per bag.
    if (previous_step && states->step < *previous_step)
      throw InputError("the bag holds more than one episode (" + std::string(STATES_TOPIC) + " go from step " +
                       std::to_string(*previous_step) + " back to " + std::to_string(states->step) +
                       "): replay handles a bag of one episode (./palcas run records one per arm)");
    previous_step = states->step;
    // Every RSU hears every step (the V2X uplink when it was on), as the live one did.
    bool decision_step = false;
    for (ReplayedRsu& r : rsus) {
      try {
        decision_step = r.decider->onStates(*states) || decision_step;
      } catch (const std::invalid_argument&) {
        // A malformed state between decisions: the live RSU refused it too.
      } catch (const std::runtime_error& e) {
        throw InputError(r.id + ": " + e.what());
      }
    }
    if (!decision_step) continue;
    ++decision_steps;
    const double now_s = states->header.stamp.toSec();
    // Peers' statistics up to (not including) this decision's time; PeerStates itself also
    // ignores those of the same step, as the live RSU does.
    while (next_cluster_state < cluster_states.size() &&
           cluster_states[next_cluster_state].header.stamp.toSec() < now_s - 1e-9) {
      const palcas_msgs::ClusterState& c = cluster_states[next_cluster_state++];
      for (ReplayedRsu& r : rsus)
        if (r.decider->options().i2i) r.decider->onClusterState(c);  // a malformed one: ignored live too
    }
    for (ReplayedRsu& r : rsus) {
      const auto key = std::make_pair(states->step, r.id);
      const auto rec = recorded.find(key);
      // Which peer states had reached the live RSU is not in the bag (topics between RSUs
      // race, above all while they connect at start-up): decide on the ones it used.
      std::optional<palcas::GlobalDensities> used;
      if (r.decider->options().i2i && rec != recorded.end())
        used = palcas::GlobalDensities{rec->second.i2i_upstream_density_veh_per_km, std::nan(""),
                                       rec->second.i2i_downstream_density_veh_per_km};
      const palcas::rsu::RsuDecision d =
          r.decider->decide(*states, palcas::rsu::RsuDecider::Clock::now(), used ? &*used : nullptr);
      if (used && (!sameDensity(d.from_peers.upstream, used->upstream) ||
                   !sameDensity(d.from_peers.downstream, used->downstream)))
        ++i2i_delivered_otherwise;
      if (!d.decided) ++not_decided;  // the live RSU answered empty too
      if (rec == recorded.end()) {
        decisions_unrecorded += d.advisories.advisories.size();
        continue;
      }
      answered.insert(key);
      comparison.compare(states->step, now_s, r.id, rec->second, d.advisories);
    }
  }
  // Recorded decisions whose vehicle states the bag lost: nothing to replay them from.
  std::uint64_t recorded_without_states = 0;
  for (const auto& [key, array] : recorded)
    if (!array.advisories.empty() && key.first % static_cast<std::uint64_t>(period) == 0 && !answered.count(key))
      recorded_without_states += array.advisories.size();

  for (const std::string& row : comparison.disagreementRows()) csv << row << "\n";
  const palcas::rsu::Agreement& total = comparison.total();
  std::printf("decisions compared: %lu, agreement: %s\n", static_cast<unsigned long>(total.compared),
              total.percent().c_str());
  for (const ReplayedRsu& r : rsus) {
    const auto it = comparison.byRsu().find(r.id);
    const palcas::rsu::Agreement a = it == comparison.byRsu().end() ? palcas::rsu::Agreement{} : it->second;
    std::printf("  %s: %lu compared, agreement %s\n", r.id.c_str(), static_cast<unsigned long>(a.compared),
                a.percent().c_str());
  }
  for (int action : {0, 1, 2, 3, -1}) {
    const auto it = comparison.byRecordedAction().find(action);
    if (it == comparison.byRecordedAction().end() && action < 0) continue;
    const palcas::rsu::Agreement a = it == comparison.byRecordedAction().end() ? palcas::rsu::Agreement{} : it->second;
    std::printf("  recorded %s: %lu compared, agreement %s\n", palcas::rsu::replayActionName(action),
                static_cast<unsigned long>(a.compared), a.percent().c_str());
  }
  std::printf("first divergence: %s\n",
              comparison.firstDivergence().empty() ? "none" : comparison.firstDivergence().c_str());
  std::printf("disagreements: %lu -> %s\n", static_cast<unsigned long>(total.compared - total.agreed),
              args.csv.c_str());
  std::printf("decision steps in the bag: %lu; not compared: %lu replayed advisories without a recorded answer, "
              "%lu recorded advisories without recorded states%s\n",
              static_cast<unsigned long>(decision_steps), static_cast<unsigned long>(decisions_unrecorded),
              static_cast<unsigned long>(recorded_without_states),
              not_decided ? (", " + std::to_string(not_decided) + " decisions refused a malformed state").c_str() : "");
  if (i2i)
    std::printf("I2I: %lu decision(s) where the live RSU had other peer states than the bag's order gives "
                "(a message not yet received, or one the V2X channel lost or delayed); replayed with the ones it used\n",
                static_cast<unsigned long>(i2i_delivered_otherwise));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "replay_policy", ros::init_options::NoSigintHandler);
  std::vector<std::string> rest;
  ros::removeROSArgs(argc, argv, rest);
  rest.erase(rest.begin());
  palcas::rsu::ReplayArgs args;
  try {
    args = palcas::rsu::parseReplayArgs(rest);
  } catch (const palcas::rsu::ReplayUsageError& e) {
    std::cerr << "replay_policy: " << e.what() << "\n" << palcas::rsu::REPLAY_USAGE;
    return 2;
  }
  if (args.help) {
    std::cout << palcas::rsu::REPLAY_USAGE;
    return 0;
  }
  if (!ros::master::check()) {
    std::cerr << "replay_policy: no ROS master at " << ros::master::getURI()
              << ": the RSU parameters are read from it (./palcas replay starts one and loads them)\n";
    return 1;
  }
  try {
    return run(args);
  } catch (const InputError& e) {
    std::cerr << "replay_policy: " << e.what() << "\n";
    return 1;
  } catch (const std::invalid_argument& e) {
    std::cerr << "replay_policy: bad RSU parameter: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "replay_policy: " << e.what() << "\n";
    return 1;
  }
}
