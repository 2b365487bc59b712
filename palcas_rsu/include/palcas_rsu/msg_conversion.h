#pragma once
// Conversions between palcas_msgs and palcas_core's RSU types, free functions in one place.
// ModelWeights <-> ModelBlob, shared with the federation server, is in
// palcas_common/model_weights.h.

#include <palcas_core/road_snapshot.h>
#include <palcas_core/rsu_controller.h>
#include <palcas_msgs/Advisory.h>
#include <palcas_msgs/ClusterState.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <palcas_msgs/VehicleStateArray.h>

#include <string>

namespace palcas::rsu {

RoadSnapshot toSnapshot(const palcas_msgs::VehicleStateArray& states);
palcas_msgs::Advisory toMsg(const CavAdvisory& advisory, uint32_t model_version);
palcas_msgs::ClusterState toMsg(const ClusterSummary& summary, const RsuControllerOptions& rsu,
                                uint64_t step, double time_s);
/// Files every event under its kind (events that end nothing are ignored).
void addOutcomes(const palcas_msgs::VehicleEventArray& events, VehicleOutcomes& outcomes);

}  // namespace palcas::rsu
