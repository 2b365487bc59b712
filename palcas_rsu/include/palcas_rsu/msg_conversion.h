#pragma once
// Conversions between palcas_msgs and palcas_core's RSU types. Free functions in one place;
// test/msg_conversion_test.cpp covers them. ModelWeights <-> ModelBlob is also used by the
// federation server.

#include <palcas_core/model_blob.h>
#include <palcas_core/road_snapshot.h>
#include <palcas_core/rsu_controller.h>
#include <palcas_msgs/Advisory.h>
#include <palcas_msgs/ClusterState.h>
#include <palcas_msgs/ModelWeights.h>
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

ModelBlob toModelBlob(const palcas_msgs::ModelWeights& msg);
palcas_msgs::ModelWeights toMsg(const ModelBlob& blob, const std::string& sender, uint32_t round,
                                uint32_t model_version, uint64_t sample_count);

}  // namespace palcas::rsu
