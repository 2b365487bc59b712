#pragma once
// Topic and service names of the bridge, relative so that launch files wire them with
// <remap> and <group ns>. Absolute only where ROS fixes the name (/clock, /tf).

namespace palcas::bridge {

// The road the bridge publishes for the RSUs and the server: palcas_common/bridge_road.h.
constexpr char VEHICLE_STATES_TOPIC[] = "vehicle_states";      // palcas_msgs/VehicleStateArray
constexpr char VEHICLE_EVENTS_TOPIC[] = "vehicle_events";      // palcas_msgs/VehicleEventArray
constexpr char EPISODE_METRICS_TOPIC[] = "episode_metrics";    // palcas_msgs/EpisodeMetrics
constexpr char ADVISORY_REJECTIONS_TOPIC[] = "advisory_rejections";  // palcas_msgs/AdvisoryRejection
constexpr char ADVISORIES_TOPIC[] = "advisories";              // palcas_msgs/AdvisoryArray (in)
constexpr char MARKERS_TOPIC[] = "markers";                    // visualization_msgs/MarkerArray
// Latched: the road (zones, lane count) for bags and replays; the RSUs read the parameters.
constexpr char ROAD_DESCRIPTION_TOPIC[] = "road_description";  // palcas_msgs/RoadDescription
constexpr char REGISTER_RSU_SERVICE[] = "register_rsu";        // palcas_msgs/RegisterRsu
constexpr char CLOCK_TOPIC[] = "/clock";                       // rosgraph_msgs/Clock
constexpr char TF_TOPIC[] = "/tf";                             // tf2_msgs/TFMessage
constexpr char MAP_FRAME[] = "map";

}  // namespace palcas::bridge
