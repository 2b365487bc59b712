#pragma once
// rviz markers and tf frames of the road: lanes, vehicles coloured by kind, RSU zones and
// the advisories of the current step. Built from the session, published by the node.
//
// The markers are drawn in the view's coordinates (rviz_view.h): x as in SUMO, y stretched
// by RoadView::lateral_scale so lanes are apart on screen, and vehicles and arrows sized in
// screen pixels (at least) rather than metres, so they show at the framing zoom: frame
// "palcas_view". The tf frames stay in true SUMO coordinates: frame "map" (topics.h).

#include <palcas_msgs/AdvisoryArray.h>
#include <std_msgs/ColorRGBA.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>
#include <vector>

#include "palcas_sim/sumo_session.h"
#include "palcas_sumo_bridge/rviz_view.h"

namespace palcas::bridge {

/// Colour of an advisory arrow by action code (palcas_msgs/Advisory): LANE_LEFT yellow,
/// LANE_RIGHT magenta, ACCELERATE red, KEEP white; any other code grey.
std_msgs::ColorRGBA advisoryColour(int action);

class RvizMarkers {
 public:
  /// @param lane_shapes polylines (x, y pairs) of every lane, for the road drawing
  /// @param view how the road is framed (scale, lateral stretch)
  /// @param rsu_poses where each zone's RSU stands in the map (SumoSession::rsuPoses)
  RvizMarkers(std::vector<std::vector<std::pair<double, double>>> lane_shapes,
              const sim::RoadLayout& road, const RoadView& view, std::vector<sim::MapPose> rsu_poses = {});

  /// Lanes and RSU zones (static: publish once, latched) and vehicles and advisories.
  visualization_msgs::MarkerArray roadMarkers(const ros::Time& stamp) const;
  /// Vehicles (one box each) and one arrow per advisory in force (vehicle id, action
  /// code); a vehicle no longer on the road gets none.
  visualization_msgs::MarkerArray dynamicMarkers(
      const ros::Time& stamp, const std::vector<sim::VehicleRecord>& vehicles,
      const std::vector<std::pair<std::string, int>>& advised) const;
  /// map -> vehicle/<id> for every vehicle and map -> rsu_<k> for every RSU pose given.
  tf2_msgs::TFMessage transforms(const ros::Time& stamp,
                                 const std::vector<sim::VehicleRecord>& vehicles) const;

 private:
  std::vector<std::vector<std::pair<double, double>>> lane_shapes_;
  std::vector<sim::ClusterInfo> clusters_;
  std::vector<sim::MapPose> rsu_poses_;
  RoadView view_;
  RoadExtent extent_;
};

}  // namespace palcas::bridge
