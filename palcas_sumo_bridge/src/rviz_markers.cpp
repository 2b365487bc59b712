#include "palcas_sumo_bridge/rviz_markers.h"

#include <geometry_msgs/TransformStamped.h>

#include <algorithm>
#include <cmath>

#include "palcas_sumo_bridge/topics.h"

namespace palcas::bridge {
namespace {

std_msgs::ColorRGBA rgba(float r, float g, float b, float a) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

visualization_msgs::Marker baseMarker(const ros::Time& stamp, const std::string& ns, int id,
                                      int type) {
  visualization_msgs::Marker m;
  m.header.frame_id = MAP_FRAME;
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  return m;
}

geometry_msgs::Point point(double x, double y, double z) {
  geometry_msgs::Point p;
  p.x = x;
  p.y = y;
  p.z = z;
  return p;
}

// Colours: CAVs blue, human-driven grey; RSU zones alternate green / orange.
const std_msgs::ColorRGBA CAV_COLOUR = rgba(0.1f, 0.4f, 1.0f, 1.0f);
const std_msgs::ColorRGBA HDV_COLOUR = rgba(0.6f, 0.6f, 0.6f, 1.0f);

}  // namespace

RvizMarkers::RvizMarkers(std::vector<std::vector<std::pair<double, double>>> lane_shapes,
                         const sim::RoadLayout& road)
    : lane_shapes_(std::move(lane_shapes)), clusters_(road.clusters()),
      road_width_m_(road.numMainLanes() * 3.2) {}

visualization_msgs::MarkerArray RvizMarkers::roadMarkers(const ros::Time& stamp) const {
  visualization_msgs::MarkerArray out;
  auto lanes = baseMarker(stamp, "lanes", 0, visualization_msgs::Marker::LINE_LIST);
  lanes.scale.x = 0.3;
  lanes.color = rgba(0.25f, 0.25f, 0.25f, 1.0f);
  for (const auto& shape : lane_shapes_)
    for (std::size_t i = 1; i < shape.size(); ++i) {
      lanes.points.push_back(point(shape[i - 1].first, shape[i - 1].second, 0.0));
      lanes.points.push_back(point(shape[i].first, shape[i].second, 0.0));
    }
  out.markers.push_back(lanes);
  for (const sim::ClusterInfo& c : clusters_) {
    auto zone = baseMarker(stamp, "rsu_zones", c.index, visualization_msgs::Marker::CUBE);
    zone.pose.position = point(0.5 * (c.x_start_m + c.x_end_m), 0.5 * road_width_m_ - 2.0, -0.2);
    zone.scale.x = c.x_end_m - c.x_start_m - 2.0;
    zone.scale.y = road_width_m_ + 12.0;
    zone.scale.z = 0.1;
    zone.color = c.index % 2 ? rgba(1.0f, 0.6f, 0.1f, 0.15f) : rgba(0.2f, 0.8f, 0.3f, 0.15f);
    out.markers.push_back(zone);
    auto label = baseMarker(stamp, "rsu_labels", c.index, visualization_msgs::Marker::TEXT_VIEW_FACING);
    label.pose.position = point(0.5 * (c.x_start_m + c.x_end_m), road_width_m_ + 15.0, 2.0);
    label.scale.z = 12.0;
    label.color = rgba(1.0f, 1.0f, 1.0f, 1.0f);
    label.text = "rsu_" + std::to_string(c.index);
    out.markers.push_back(label);
  }
  return out;
}

visualization_msgs::MarkerArray RvizMarkers::dynamicMarkers(
    const ros::Time& stamp, const std::vector<sim::VehicleRecord>& vehicles,
    const std::vector<std::pair<std::string, int>>& advised) const {
  visualization_msgs::MarkerArray out;
  // One CUBE_LIST for all vehicles: one message part, cheap for rviz at hundreds of cars.
  auto cars = baseMarker(stamp, "vehicles", 0, visualization_msgs::Marker::CUBE_LIST);
  cars.scale.x = 4.5;
  cars.scale.y = 2.0;
  cars.scale.z = 1.5;
  std::unordered_map<std::string, const sim::VehicleRecord*> by_id;
  for (const sim::VehicleRecord& v : vehicles) {
    cars.points.push_back(point(v.x_m - 0.5 * v.length_m, v.map_y_m, 0.75));
    cars.colors.push_back(v.is_cav ? CAV_COLOUR : HDV_COLOUR);
    by_id[v.id] = &v;
  }
  out.markers.push_back(cars);
  // Advisories: an arrow from each advised CAV towards where it is told to go.
  auto arrows = baseMarker(stamp, "advisories", 0, visualization_msgs::Marker::LINE_LIST);
  arrows.scale.x = 0.6;
  for (const auto& [id, action] : advised) {
    auto it = by_id.find(id);
    if (it == by_id.end()) continue;
    const sim::VehicleRecord& v = *it->second;
    const double dy = action == 0 ? 3.2 : action == 1 ? -3.2 : 0.0;
    const double dx = action == 2 ? 8.0 : 4.0;
    arrows.points.push_back(point(v.x_m, v.map_y_m, 1.6));
    arrows.points.push_back(point(v.x_m + dx, v.map_y_m + dy, 1.6));
    const auto colour = action == 2 ? rgba(1.0f, 0.2f, 0.2f, 1.0f)
                        : action == 3 ? rgba(1.0f, 1.0f, 1.0f, 0.8f)
                                      : rgba(1.0f, 0.9f, 0.0f, 1.0f);
    arrows.colors.push_back(colour);
    arrows.colors.push_back(colour);
  }
  if (arrows.points.empty()) arrows.action = visualization_msgs::Marker::DELETE;
  out.markers.push_back(arrows);
  return out;
}

tf2_msgs::TFMessage RvizMarkers::transforms(const ros::Time& stamp,
                                            const std::vector<sim::VehicleRecord>& vehicles) const {
  tf2_msgs::TFMessage out;
  out.transforms.reserve(vehicles.size() + clusters_.size());
  auto make = [&](const std::string& child, double x, double y, double yaw) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = stamp;
    t.header.frame_id = MAP_FRAME;
    t.child_frame_id = child;
    t.transform.translation.x = x;
    t.transform.translation.y = y;
    t.transform.rotation.z = std::sin(0.5 * yaw);
    t.transform.rotation.w = std::cos(0.5 * yaw);
    out.transforms.push_back(t);
  };
  for (const sim::VehicleRecord& v : vehicles) make("vehicle/" + v.id, v.x_m, v.map_y_m, v.heading_rad);
  for (const sim::ClusterInfo& c : clusters_)
    make("rsu_" + std::to_string(c.index), 0.5 * (c.x_start_m + c.x_end_m), -10.0, 0.0);
  return out;
}

}  // namespace palcas::bridge
