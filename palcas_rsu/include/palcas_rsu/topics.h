#pragma once
// Topic and service names of the RSU node, relative: launch files put each RSU in its own
// namespace (rsu_0, rsu_1, ...) and remap the shared ones to the bridge's and the server's.

namespace palcas::rsu {

constexpr char VEHICLE_STATES_TOPIC[] = "vehicle_states";    // in: palcas_msgs/VehicleStateArray
constexpr char VEHICLE_EVENTS_TOPIC[] = "vehicle_events";    // in: palcas_msgs/VehicleEventArray
constexpr char CLUSTER_STATES_TOPIC[] = "cluster_states";    // in/out (I2I): palcas_msgs/ClusterState
constexpr char ADVISORIES_TOPIC[] = "advisories";            // out: palcas_msgs/AdvisoryArray
constexpr char RSU_STATUS_TOPIC[] = "rsu_status";            // out: palcas_msgs/RsuStatus
constexpr char SUBMITTED_WEIGHTS_TOPIC[] = "submitted_weights";  // out, latched: what it sent, once per round
constexpr char MODEL_TOPIC[] = "model";                      // out, latched: the global model it loaded
constexpr char GLOBAL_MODEL_VERSION_TOPIC[] = "global_model_version";  // in, latched: the server's global version
constexpr char REGISTER_RSU_SERVICE[] = "register_rsu";      // client: palcas_msgs/RegisterRsu
constexpr char SUBMIT_WEIGHTS_SERVICE[] = "submit_weights";  // client: palcas_msgs/SubmitWeights
constexpr char FETCH_MODEL_SERVICE[] = "fetch_global_model"; // client: palcas_msgs/FetchGlobalModel

}  // namespace palcas::rsu
