#pragma once
// Conversions between palcas_msgs and palcas_core's RSU types, free functions in one place.
// ModelWeights <-> ModelBlob, shared with the federation server, is in
// palcas_common/model_weights.h.

#include <palcas_core/common/road_snapshot.h>
#include <palcas_core/rsu/rsu_controller.h>
#include <palcas_msgs/Advisory.h>
#include <palcas_msgs/ClusterState.h>
#include <palcas_msgs/RsuStatus.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <palcas_msgs/VehicleStateArray.h>

#include <string>

namespace palcas::rsu {

RoadSnapshot toSnapshot(const palcas_msgs::VehicleStateArray& states);
palcas_msgs::Advisory toMsg(const CavAdvisory& advisory, uint32_t model_version);
palcas_msgs::ClusterState toMsg(const ClusterSummary& summary, const RsuControllerOptions& rsu,
                                uint64_t step, double time_s);
/// What the node adds to the controller's statistics in a decision's RsuStatus.
struct StatusContext {
  std_msgs::Header header;  ///< of the state decided on
  uint64_t step = 0;
  std::string rsu_id;
  bool train = false;
  float decision_ms = 0.0f;
  uint32_t stale_peers = 0;
  bool federation_reachable = false;
};
palcas_msgs::RsuStatus toStatusMsg(const RsuControllerStats& stats, const StatusContext& context);
/// Files every event under its kind (events that end nothing are ignored).
void addOutcomes(const palcas_msgs::VehicleEventArray& events, VehicleOutcomes& outcomes);

}  // namespace palcas::rsu
