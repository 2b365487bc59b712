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
// One frame id per geometry (REP-105 for the world-fixed one):
// - "map": SUMO's network coordinates (x, y as in the .net.xml); /tf places each vehicle
//   (vehicle/<id>) and RSU (rsu_<k>) in it.
constexpr char MAP_FRAME[] = "map";
// - "palcas_road": road coordinates, not a tf frame: x along the mainline from its start
//   (along its lanes on a curved road), lateral from the right edge of lane 1, lanes in the
//   paper's numbering. The header of vehicle_states, vehicle_events and road_description.
constexpr char ROAD_FRAME[] = "palcas_road";
// - "palcas_view": the rviz drawing (rviz_view.h): x as in map, y stretched by the view's
//   lateral scale, vehicles and arrows sized in pixels. The markers' frame and rviz's fixed
//   frame; not on /tf (it is not a rigid transform of map), so never measure in it.
constexpr char VIEW_FRAME[] = "palcas_view";

}  // namespace palcas::bridge
