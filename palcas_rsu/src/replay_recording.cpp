#include "palcas_rsu/replay_recording.h"

#include <palcas_core/state/state_layout.h>
#include <palcas_msgs/RoadDescription.h>
#include <palcas_msgs/VehicleStateArray.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace palcas::rsu {
namespace {

bool hasTopic(rosbag::Bag& bag, const std::string& topic) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  return view.size() > 0;
}

RecordedRoad readRoad(rosbag::Bag& bag, int lanes_in_states) {
  RecordedRoad road;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(REPLAY_ROAD_TOPIC))) {
    if (auto r = m.instantiate<palcas_msgs::RoadDescription>()) {
      road.zones_m = r->zone_boundaries_m;
      road.num_lanes = r->num_lanes;
      road.source = REPLAY_ROAD_TOPIC;
      break;
    }
  }
  if (road.zones_m.empty()) {
    // A bag recorded before the road was: its I2I messages name every zone that published.
    std::map<int, std::pair<double, double>> zones;
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(REPLAY_CLUSTER_TOPIC)))
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
      throw ReplayInputError(std::string("the bag has no ") + REPLAY_ROAD_TOPIC +
                             " (recorded since the bridge publishes it) and its " + REPLAY_CLUSTER_TOPIC +
                             " do not give every zone: the RSUs' zones are unknown");
    road.num_lanes = lanes_in_states;
    road.source = std::string(REPLAY_CLUSTER_TOPIC) + " (no " + REPLAY_ROAD_TOPIC + " in the bag)";
  }
  if (road.num_lanes != lanes_in_states)
    throw ReplayInputError("the bag's road has " + std::to_string(road.num_lanes) + " lanes but its " +
                           REPLAY_STATES_TOPIC + " say " + std::to_string(lanes_in_states));
  return road;
}

}  // namespace

Recording readRecording(const std::string& bag_path) {
  if (!std::filesystem::is_regular_file(bag_path)) throw ReplayInputError("'" + bag_path + "': no such file");
  rosbag::Bag bag;
  try {
    bag.open(bag_path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw ReplayInputError("'" + bag_path + "' is not a bag (" + e.what() + ")");
  }
  std::vector<std::string> missing;
  for (const char* t : {REPLAY_STATES_TOPIC, REPLAY_ADVISORIES_TOPIC})
    if (!hasTopic(bag, t)) missing.push_back(t);
  if (!missing.empty()) {
    std::string names;
    for (const auto& t : missing) names += (names.empty() ? "" : ", ") + t;
    throw ReplayInputError("the bag '" + bag_path + "' lacks " + names +
                           " (replay needs the recorded vehicle states and advisories: record with ./palcas run "
                           "--record; a keep or sumo_native run has no RSU to replay)");
  }
  Recording rec;
  int lanes_in_states = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(REPLAY_STATES_TOPIC)))
    if (auto s = m.instantiate<palcas_msgs::VehicleStateArray>()) {
      lanes_in_states = s->num_lanes;
      rec.step_length_s = s->step_length_s;
      break;
    }
  rec.road = readRoad(bag, lanes_in_states);
  rec.state_size = static_cast<int>(StateLayout(rec.road.num_lanes).size());

  std::string other_definition;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(REPLAY_ADVISORIES_TOPIC))) {
    if (auto a = m.instantiate<palcas_msgs::AdvisoryArray>()) {
      rec.rsu_ids.insert(a->rsu_id);
      rec.advisories[{a->step, a->rsu_id}] = *a;
    } else if (other_definition.empty()) {
      other_definition = m.getMD5Sum();
    }
  }
  if (rec.rsu_ids.empty() && !other_definition.empty())
    throw ReplayInputError("the bag's " + std::string(REPLAY_ADVISORIES_TOPIC) +
                           " were recorded with another definition of palcas_msgs/AdvisoryArray (md5 " +
                           other_definition + ", this build's " +
                           ros::message_traits::MD5Sum<palcas_msgs::AdvisoryArray>::value() +
                           "): record it again with this version");
  if (rec.rsu_ids.empty()) throw ReplayInputError("the bag's " + std::string(REPLAY_ADVISORIES_TOPIC) + " name no RSU");
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(REPLAY_CLUSTER_TOPIC)))
    if (auto c = m.instantiate<palcas_msgs::ClusterState>()) {
      rec.cluster_states.push_back(*c);
      rec.cluster_of[c->rsu_id] = c->cluster_index;
    }
  std::stable_sort(rec.cluster_states.begin(), rec.cluster_states.end(),
                   [](const auto& a, const auto& b) { return a.header.stamp < b.header.stamp; });
  rec.i2i = !rec.cluster_states.empty();
  return rec;
}

}  // namespace palcas::rsu
