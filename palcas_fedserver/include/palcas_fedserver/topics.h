#pragma once
// Topic and service names of the federation server, relative so that launch files wire
// them with <remap> and <group ns>.

namespace palcas::fedserver {

constexpr char SUBMIT_WEIGHTS_SERVICE[] = "submit_weights";          // palcas_msgs/SubmitWeights
constexpr char FETCH_GLOBAL_MODEL_SERVICE[] = "fetch_global_model";  // palcas_msgs/FetchGlobalModel
constexpr char FEDERATION_STATUS_TOPIC[] = "federation_status";      // palcas_msgs/FederationStatus, latched
constexpr char GLOBAL_MODEL_VERSION_TOPIC[] = "global_model_version";  // std_msgs/UInt32, latched
/// rsu_id of the global model in ModelWeights messages.
constexpr char SERVER_ID[] = "server";

}  // namespace palcas::fedserver
