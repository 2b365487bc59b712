#pragma once
// The bridge's road on the parameter server: the bridge sets it from the network it built
// before it opens RSU registration, and the RSUs and the federation server take what they
// do not set themselves from it (zones, lane count, state size 40 + L). One road, one source.

#include <ros/node_handle.h>
#include <ros/param.h>
#include <ros/time.h>

#include <optional>
#include <vector>

namespace palcas::common {

// Absolute names: RSUs and the server live in their own namespaces.
constexpr char ROAD_ZONES_PARAM[] = "/palcas/road_zones_m";  ///< zone boundaries [m], clusters + 1
constexpr char ROAD_LANES_PARAM[] = "/palcas/road_num_lanes";  ///< mainline lanes L

struct BridgeRoad {
  std::vector<double> zones_m;
  int num_lanes = 0;
};

/// The bridge's road if it is on the parameter server now, else nullopt.
inline std::optional<BridgeRoad> bridgeRoad(const ros::NodeHandle& nh) {
  BridgeRoad road;
  if (nh.getParam(ROAD_ZONES_PARAM, road.zones_m) && nh.getParam(ROAD_LANES_PARAM, road.num_lanes))
    return road;
  return std::nullopt;
}

/// Waits up to timeout_s of wall time for the bridge's road (the bridge builds its network
/// first, about a second). nullopt when it did not appear or ROS shut down.
inline std::optional<BridgeRoad> waitForBridgeRoad(const ros::NodeHandle& nh, double timeout_s) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  for (;;) {
    if (auto road = bridgeRoad(nh)) return road;
    if (!ros::ok() || ros::WallTime::now() >= deadline) return std::nullopt;
    ros::WallDuration(0.05).sleep();
  }
}

}  // namespace palcas::common
