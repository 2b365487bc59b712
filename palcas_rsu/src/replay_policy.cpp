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
#include "palcas_rsu/replay_recording.h"
#include "palcas_rsu/rsu_decider.h"
#include "palcas_rsu/rsu_options.h"

namespace fs = std::filesystem;
using palcas::rsu::RsuNodeOptions;

namespace {

using palcas::rsu::Recording;
using InputError = palcas::rsu::ReplayInputError;
constexpr const char* STATES_TOPIC = palcas::rsu::REPLAY_STATES_TOPIC;

/// Two I2I densities agree when both are unknown (NaN) or equal.
bool sameDensity(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

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

/// One replayed RSU: its controller and I2I bookkeeping, as RsuNode holds them.
struct ReplayedRsu {
  std::string id;
  /// The RSU node's own decision path (rsu_decider.h), evaluating the policy: the same V2X
  /// uplink, I2I bookkeeping and controller call as the live RSU.
  std::unique_ptr<palcas::rsu::RsuDecider> decider;
  fs::path model;
  std::optional<std::uint64_t> last_decided_step;  ///< of the replay
};

/// One ReplayedRsu per RSU of the recording, each with the node's own options (the loader's,
/// then its identity and the recorded road, as the node adopts the bridge's) and its model
/// from `checkpoints` (the node's load order), checked against the recorded road.
std::vector<ReplayedRsu> buildRsus(const Recording& rec, const RsuNodeOptions& base, const fs::path& checkpoints) {
  std::vector<ReplayedRsu> rsus;
  for (const std::string& id : rec.rsu_ids) {
    ReplayedRsu r;
    r.id = id;
    RsuNodeOptions options = base;
    palcas::rsu::RsuControllerOptions& c = options.controller;
    c.rsu_id = id;
    c.train = false;
    options.whole_road = id == "central";  // the centralized baseline's one agent
    options.i2i = rec.i2i && !options.whole_road;
    if (auto it = rec.cluster_of.find(id); it != rec.cluster_of.end()) {
      c.cluster_index = it->second;
    } else if (id.rfind("rsu_", 0) == 0 && id.size() > 4 &&
               id.find_first_not_of("0123456789", 4) == std::string::npos) {
      c.cluster_index = std::stoi(id.substr(4));
    } else if (!options.whole_road) {
      throw InputError("RSU '" + id + "' in the bag: its cluster is unknown (not rsu_<k>, central, nor in " +
                       palcas::rsu::REPLAY_CLUSTER_TOPIC + ")");
    }
    if (!options.zones_m.empty()) palcas::rsu::applyZones(options, "zones_m");
    try {
      palcas::rsu::adoptBridgeRoad(options, rec.road.zones_m, rec.road.num_lanes);
    } catch (const std::invalid_argument& e) {
      throw InputError(id + " on the recorded road: " + e.what());
    }
    try {
      r.model = palcas::rsu::policyFileIn(checkpoints.string(), id, options.policy_model);
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
    if (model_states >= 0 && model_states != rec.state_size)
      throw InputError("the model '" + r.model.string() + "' takes a state of " + std::to_string(model_states) +
                       " features, but the recorded road has " + std::to_string(rec.road.num_lanes) +
                       " lanes: its state has " + std::to_string(palcas::LANE_INDEPENDENT_FEATURE_COUNT) + " + " +
                       std::to_string(rec.road.num_lanes) + " = " + std::to_string(rec.state_size) +
                       " (a policy trained on another road)");
    if (options.v2x.enabled) {
      try {
        palcas::v2x::Channel check(options.v2x, rec.step_length_s);  // the RSU builds it at the first state
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
  return rsus;
}

/// What the replay counted beside the comparison itself.
struct ReplayCounts {
  std::uint64_t decision_steps = 0;
  std::uint64_t decisions_unrecorded = 0;     ///< replayed advisories without a recorded answer
  std::uint64_t not_decided = 0;              ///< decisions that refused a malformed state
  std::uint64_t i2i_delivered_otherwise = 0;  ///< decisions whose live peer states differ from the bag's order
  std::uint64_t recorded_without_states = 0;  ///< recorded advisories whose states the bag lost
  std::uint64_t steps_missing = 0;            ///< steps whose vehicle states the bag lost
  std::uint64_t own_density_from_bag = 0;     ///< decisions given the live RSU's own density, not the replay's
};

/// An RSU's own density as it published it (its ClusterState) at a decision step.
struct PublishedDensity {
  std::uint64_t step = 0;
  double density_veh_per_km = 0.0;
};

/// The episode's vehicle states, step by step, through every replayed RSU, each decision
/// compared with the recorded one.
ReplayCounts replayEpisode(const std::string& bag_path, const Recording& rec, std::vector<ReplayedRsu>& rsus,
                           int period, palcas::rsu::ReplayComparison& comparison) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  ReplayCounts n;
  std::set<std::pair<std::uint64_t, std::string>> answered;  // recorded (step, rsu) the replay reached
  std::size_t next_cluster_state = 0;
  std::optional<std::uint64_t> previous_step;
  std::map<std::string, PublishedDensity> own_published;  // each RSU's last recorded ClusterState
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(STATES_TOPIC))) {
    const auto states = m.instantiate<palcas_msgs::VehicleStateArray>();
    if (!states) continue;
    // Advisories and cluster states are matched by step and time: one episode per bag.
    if (previous_step && states->step < *previous_step)
      throw InputError("the bag holds more than one episode (" + std::string(STATES_TOPIC) + " go from step " +
                       std::to_string(*previous_step) + " back to " + std::to_string(states->step) +
                       "): replay handles a bag of one episode (./palcas run records one per arm)");
    // A recorder that falls behind (rosbag record keeps 100 messages per topic) loses states.
    if (!previous_step) n.steps_missing += states->step;
    else if (states->step > *previous_step) n.steps_missing += states->step - *previous_step - 1;
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
    ++n.decision_steps;
    const double now_s = states->header.stamp.toSec();
    // Peers' statistics up to (not including) this decision's time; PeerStates itself also
    // ignores those of the same step, as the live RSU does.
    while (next_cluster_state < rec.cluster_states.size() &&
           rec.cluster_states[next_cluster_state].header.stamp.toSec() < now_s - 1e-9) {
      const palcas_msgs::ClusterState& c = rec.cluster_states[next_cluster_state++];
      own_published[c.rsu_id] = PublishedDensity{c.step, c.density_veh_per_km};
      for (ReplayedRsu& r : rsus)
        if (r.decider->options().i2i) r.decider->onClusterState(c);  // a malformed one: ignored live too
    }
    for (ReplayedRsu& r : rsus) {
      const auto key = std::make_pair(states->step, r.id);
      const auto recorded = rec.advisories.find(key);
      // Which peer states had reached the live RSU is not in the bag (topics between RSUs
      // race, above all while they connect at start-up): decide on the ones it used.
      std::optional<palcas::GlobalDensities> used;
      if (r.decider->options().i2i && recorded != rec.advisories.end()) {
        // The own density is the zone's at the RSU's previous decision. When the bag lost that
        // decision's states the replay did not take it, but the live RSU published its density.
        double own = r.decider->lastOwnDensity();
        const auto published = own_published.find(r.id);
        if (published != own_published.end() &&
            (!r.last_decided_step || published->second.step > *r.last_decided_step)) {
          if (!sameDensity(own, published->second.density_veh_per_km)) ++n.own_density_from_bag;
          own = published->second.density_veh_per_km;
        }
        used = palcas::GlobalDensities{recorded->second.i2i_upstream_density_veh_per_km, own,
                                       recorded->second.i2i_downstream_density_veh_per_km};
      }
      const palcas::rsu::RsuDecision d =
          r.decider->decide(*states, palcas::rsu::RsuDecider::Clock::now(), used ? &*used : nullptr);
      if (d.decided) r.last_decided_step = states->step;
      if (used && (!sameDensity(d.from_peers.upstream, used->upstream) ||
                   !sameDensity(d.from_peers.downstream, used->downstream)))
        ++n.i2i_delivered_otherwise;
      if (!d.decided) ++n.not_decided;  // the live RSU answered empty too
      if (recorded == rec.advisories.end()) {
        n.decisions_unrecorded += d.advisories.advisories.size();
        continue;
      }
      answered.insert(key);
      comparison.compare(states->step, now_s, r.id, recorded->second, d.advisories);
    }
  }
  // Recorded decisions whose vehicle states the bag lost: nothing to replay them from.
  for (const auto& [key, array] : rec.advisories)
    if (!array.advisories.empty() && key.first % static_cast<std::uint64_t>(period) == 0 && !answered.count(key))
      n.recorded_without_states += array.advisories.size();
  return n;
}

void printReport(const palcas::rsu::ReplayArgs& args, const Recording& rec, const std::vector<ReplayedRsu>& rsus,
                 const palcas::rsu::ReplayComparison& comparison, const ReplayCounts& n) {
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
              static_cast<unsigned long>(n.decision_steps), static_cast<unsigned long>(n.decisions_unrecorded),
              static_cast<unsigned long>(n.recorded_without_states),
              n.not_decided ? (", " + std::to_string(n.not_decided) + " decisions refused a malformed state").c_str() : "");
  if (rec.i2i)
    std::printf("I2I: %lu decision(s) where the live RSU had other peer states than the bag's order gives "
                "(a message not yet received, or one the V2X channel lost or delayed); replayed with the ones it used\n",
                static_cast<unsigned long>(n.i2i_delivered_otherwise));
  if (n.steps_missing > 0) {
    std::printf("states missing from the bag: %lu step(s) (the recorder fell behind)", static_cast<unsigned long>(n.steps_missing));
    if (rec.i2i)
      std::printf("; %lu decision(s) replayed with the own density the live RSU published after a lost decision step",
                  static_cast<unsigned long>(n.own_density_from_bag));
    // The live uplink heard every step; the replayed one hears only the recorded ones.
    if (rsus.front().decider->options().v2x.enabled)
      std::printf("; with the V2X channel on, decisions after a lost step may differ (the live RSU heard it)");
    std::printf("\n");
  }
}

int run(const palcas::rsu::ReplayArgs& args) {
  const Recording rec = palcas::rsu::readRecording(args.bag);
  ros::NodeHandle private_nh("~");
  const RsuNodeOptions base = palcas::rsu::loadRsuNodeOptions(private_nh);
  std::vector<ReplayedRsu> rsus = buildRsus(rec, base, checkpointsOf(args.policy));
  const int period = base.decision_period_steps;

  std::ofstream csv(args.csv);
  if (!csv) throw InputError("cannot write the CSV '" + args.csv + "'");
  csv << palcas::rsu::ReplayComparison::CSV_HEADER << "\n";
  std::printf("replay: %s\n  road: %zu zone(s), %d lanes (state size %d) from %s; decision every %d steps; I2I %s%s\n",
              args.bag.c_str(), rec.road.zones_m.size() - 1, rec.road.num_lanes, rec.state_size,
              rec.road.source.c_str(), period, rec.i2i ? "on" : "off",
              base.v2x.enabled ? "; V2X channel on (as recorded: the uplink replayed step by step)" : "");
  for (const ReplayedRsu& r : rsus)
    std::printf("  %s [%.0f, %.0f) m: %s\n", r.id.c_str(), r.decider->options().controller.x_start_m,
                r.decider->options().controller.x_end_m, r.model.c_str());

  palcas::rsu::ReplayComparison comparison(args.accel_tolerance);
  const ReplayCounts counts = replayEpisode(args.bag, rec, rsus, period, comparison);
  for (const std::string& row : comparison.disagreementRows()) csv << row << "\n";
  printReport(args, rec, rsus, comparison, counts);
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
