#pragma once
// rviz markers and tf frames of the road: lanes, vehicles coloured by kind, RSU zones and
// the advisories of the current step. Built from the session, published by the node.

#include <palcas_msgs/AdvisoryArray.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>
#include <vector>

#include "palcas_sim/sumo_session.h"

namespace palcas::bridge {

class RvizMarkers {
 public:
  /// @param lane_shapes polylines (x, y pairs) of every lane, for the road drawing
  RvizMarkers(std::vector<std::vector<std::pair<double, double>>> lane_shapes,
              const sim::RoadLayout& road);

  /// Lanes and RSU zones (static: publish once, latched) and vehicles and advisories.
  visualization_msgs::MarkerArray roadMarkers(const ros::Time& stamp) const;
  visualization_msgs::MarkerArray dynamicMarkers(
      const ros::Time& stamp, const std::vector<sim::VehicleRecord>& vehicles,
      const std::vector<std::pair<std::string, int>>& advised) const;
  /// map -> vehicle/<id> for every vehicle and map -> rsu_<k> for every zone centre.
  tf2_msgs::TFMessage transforms(const ros::Time& stamp,
                                 const std::vector<sim::VehicleRecord>& vehicles) const;

 private:
  std::vector<std::vector<std::pair<double, double>>> lane_shapes_;
  std::vector<sim::ClusterInfo> clusters_;
  double road_width_m_;
};

}  // namespace palcas::bridge
