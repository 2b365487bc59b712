#pragma once
// What replay_policy reads from a recorded episode before it replays anything: the road, the
// recording RSUs and their advisories, the I2I cluster states in time order. Every way a bag
// can be unfit for replay is refused here, naming the bag and what it lacks.

#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/ClusterState.h>

#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace palcas::rsu {

/// Bad input for replay (not a bag, missing topics, an unknown road, no model, a model that
/// does not fit): replay_policy exits 1 with its message.
struct ReplayInputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The topics a recorded episode holds (absolute: a bag keeps the names as published).
constexpr char REPLAY_STATES_TOPIC[] = "/vehicle_states";
constexpr char REPLAY_ADVISORIES_TOPIC[] = "/advisories";
constexpr char REPLAY_CLUSTER_TOPIC[] = "/cluster_states";
constexpr char REPLAY_ROAD_TOPIC[] = "/road_description";

/// The road as the bag describes it.
struct RecordedRoad {
  std::vector<double> zones_m;  ///< zone boundaries, zones + 1 of them
  int num_lanes = 0;
  std::string source;  ///< where it was read: /road_description, or the cluster states of an older bag
};

/// One recorded episode's inputs to replay.
struct Recording {
  RecordedRoad road;
  int state_size = 0;           ///< the RSUs' state size on that road (40 + L)
  double step_length_s = 0.0;   ///< the bridge's step, from the first vehicle states
  /// What each recording RSU said, by (bridge step, RSU id).
  std::map<std::pair<std::uint64_t, std::string>, palcas_msgs::AdvisoryArray> advisories;
  std::set<std::string> rsu_ids;
  std::vector<palcas_msgs::ClusterState> cluster_states;  ///< in stamp order
  std::map<std::string, int> cluster_of;                  ///< RSU id -> the zone its cluster states name
  bool i2i = false;  ///< the RSUs shared cluster states (palcas, palcas_assist, no_priority)
};

/// Reads `bag_path`. @throws ReplayInputError naming the bag and the problem: no such file,
/// not a bag, no vehicle states or advisories, advisories of another message definition or
/// naming no RSU, a road whose lane count differs from the states', no road description and
/// cluster states that do not give every zone.
Recording readRecording(const std::string& bag_path);

}  // namespace palcas::rsu
