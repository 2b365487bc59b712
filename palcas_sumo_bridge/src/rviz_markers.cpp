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
  m.header.frame_id = VIEW_FRAME;  // the stretched drawing, not map (topics.h)
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

// Colours: CAVs blue, human-driven light grey on dark asphalt; RSU zones alternate green /
// orange. Advisory colours (advisoryColour) differ from all of these, so they stand out.
const std_msgs::ColorRGBA CAV_COLOUR = rgba(0.1f, 0.45f, 1.0f, 1.0f);
const std_msgs::ColorRGBA HDV_COLOUR = rgba(0.75f, 0.75f, 0.75f, 1.0f);
const std_msgs::ColorRGBA ROAD_COLOUR = rgba(0.3f, 0.3f, 0.33f, 1.0f);

// Sizes on screen [px] at the framing scale. Vehicles and arrows are drawn larger than
// they are (a 4.5 m car is 2 px on the 2.4 km paper road), never smaller.
constexpr double VEHICLE_MIN_LENGTH_PX = 12.0;
constexpr double VEHICLE_MIN_WIDTH_PX = 6.0;
constexpr double ARROW_SHAFT_PX = 4.0;
constexpr double ARROW_HEAD_PX = 12.0;
constexpr double LANE_CHANGE_ARROW_FORWARD_PX = 20.0;
constexpr double ACCELERATE_ARROW_PX = 30.0;
constexpr double KEEP_ARROW_PX = 16.0;
// Heights: the top-down camera shows higher markers over lower ones.
constexpr double ZONE_Z = -1.0, ROAD_Z = 0.0, VEHICLE_Z = 1.0, ARROW_Z = 2.0, LABEL_Z = 3.0;

}  // namespace

std_msgs::ColorRGBA advisoryColour(int action) {
  switch (action) {
    case palcas_msgs::Advisory::LANE_LEFT: return rgba(1.0f, 0.9f, 0.0f, 1.0f);
    case palcas_msgs::Advisory::LANE_RIGHT: return rgba(1.0f, 0.2f, 1.0f, 1.0f);
    case palcas_msgs::Advisory::ACCELERATE: return rgba(1.0f, 0.15f, 0.1f, 1.0f);
    case palcas_msgs::Advisory::KEEP: return rgba(1.0f, 1.0f, 1.0f, 1.0f);
    default: return rgba(0.5f, 0.5f, 0.5f, 1.0f);
  }
}

RvizMarkers::RvizMarkers(std::vector<std::vector<std::pair<double, double>>> lane_shapes,
                         const sim::RoadLayout& road, const RoadView& view, std::vector<sim::MapPose> rsu_poses)
    : lane_shapes_(std::move(lane_shapes)), clusters_(road.clusters()), rsu_poses_(std::move(rsu_poses)), view_(view),
      extent_(roadExtent(lane_shapes_)) {}

visualization_msgs::MarkerArray RvizMarkers::roadMarkers(const ros::Time& stamp) const {
  visualization_msgs::MarkerArray out;
  // Each lane a band of asphalt with a dark seam to its neighbours: the lanes read apart.
  const double lane_drawn_m = view_.drawnY(FramingRules{}.lane_width_m);
  auto lanes = baseMarker(stamp, "lanes", 0, visualization_msgs::Marker::LINE_LIST);
  lanes.scale.x = 0.85 * lane_drawn_m;
  lanes.color = ROAD_COLOUR;
  for (const auto& shape : lane_shapes_)
    for (std::size_t i = 1; i < shape.size(); ++i) {
      lanes.points.push_back(point(shape[i - 1].first, view_.drawnY(shape[i - 1].second), ROAD_Z));
      lanes.points.push_back(point(shape[i].first, view_.drawnY(shape[i].second), ROAD_Z));
    }
  out.markers.push_back(lanes);
  const double top_m = view_.drawnY(extent_.max_y_m), bottom_m = view_.drawnY(extent_.min_y_m);
  const double margin_m = view_.metresForPx(8.0);
  for (const sim::ClusterInfo& c : clusters_) {
    auto zone = baseMarker(stamp, "rsu_zones", c.index, visualization_msgs::Marker::CUBE);
    zone.pose.position = point(0.5 * (c.x_start_m + c.x_end_m), 0.5 * (top_m + bottom_m), ZONE_Z);
    zone.scale.x = c.x_end_m - c.x_start_m - view_.metresForPx(2.0);
    zone.scale.y = top_m - bottom_m + 2.0 * margin_m;
    zone.scale.z = 0.1;
    zone.color = c.index % 2 ? rgba(1.0f, 0.6f, 0.1f, 0.2f) : rgba(0.2f, 0.8f, 0.3f, 0.2f);
    out.markers.push_back(zone);
    auto label = baseMarker(stamp, "rsu_labels", c.index, visualization_msgs::Marker::TEXT_VIEW_FACING);
    label.pose.position = point(0.5 * (c.x_start_m + c.x_end_m), top_m + margin_m + view_.metresForPx(14.0), LABEL_Z);
    label.scale.z = view_.metresForPx(18.0);
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
  const double lane_drawn_m = view_.drawnY(FramingRules{}.lane_width_m);
  cars.scale.x = std::max(4.5, view_.metresForPx(VEHICLE_MIN_LENGTH_PX));
  cars.scale.y = std::max(0.55 * lane_drawn_m, view_.metresForPx(VEHICLE_MIN_WIDTH_PX));
  cars.scale.z = 0.5;
  std::unordered_map<std::string, const sim::VehicleRecord*> by_id;
  for (const sim::VehicleRecord& v : vehicles) {
    // Its front at its position, like SUMO; a box longer than the car grows backwards.
    cars.points.push_back(point(v.map_x_m - 0.5 * cars.scale.x, view_.drawnY(v.map_y_m), VEHICLE_Z));
    cars.colors.push_back(v.is_cav ? CAV_COLOUR : HDV_COLOUR);
    by_id[v.id] = &v;
  }
  out.markers.push_back(cars);
  // Advisories: an arrow from each advised CAV towards where it is told to go (one lane
  // left or right, ahead); shafts in one LINE_LIST, heads in one TRIANGLE_LIST.
  auto shafts = baseMarker(stamp, "advisories", 0, visualization_msgs::Marker::LINE_LIST);
  shafts.scale.x = view_.metresForPx(ARROW_SHAFT_PX);
  auto heads = baseMarker(stamp, "advisories", 1, visualization_msgs::Marker::TRIANGLE_LIST);
  const double head_m = view_.metresForPx(ARROW_HEAD_PX);
  for (const auto& [id, action] : advised) {
    auto it = by_id.find(id);
    if (it == by_id.end()) continue;
    const sim::VehicleRecord& v = *it->second;
    const bool left = action == palcas_msgs::Advisory::LANE_LEFT;
    const bool change = left || action == palcas_msgs::Advisory::LANE_RIGHT;
    const double dx = view_.metresForPx(change ? LANE_CHANGE_ARROW_FORWARD_PX
                                        : action == palcas_msgs::Advisory::ACCELERATE ? ACCELERATE_ARROW_PX
                                                                                       : KEEP_ARROW_PX);
    const double dy = change ? (left ? lane_drawn_m : -lane_drawn_m) : 0.0;  // left = +y in SUMO
    const double x0 = v.map_x_m - 0.5 * cars.scale.x, y0 = view_.drawnY(v.map_y_m);
    const double x1 = v.map_x_m + dx, y1 = y0 + dy;
    const double len = std::hypot(x1 - x0, y1 - y0);
    const double ux = (x1 - x0) / len, uy = (y1 - y0) / len;
    const auto colour = advisoryColour(action);
    shafts.points.push_back(point(x0, y0, ARROW_Z));
    shafts.points.push_back(point(x1 - 0.5 * head_m * ux, y1 - 0.5 * head_m * uy, ARROW_Z));
    shafts.colors.insert(shafts.colors.end(), 2, colour);
    const double bx = x1 - head_m * ux, by = y1 - head_m * uy, half = 0.5 * head_m;
    heads.points.push_back(point(x1, y1, ARROW_Z));
    heads.points.push_back(point(bx - half * uy, by + half * ux, ARROW_Z));
    heads.points.push_back(point(bx + half * uy, by - half * ux, ARROW_Z));
    heads.colors.insert(heads.colors.end(), 3, colour);
  }
  // An empty list would make rviz warn; DELETE clears the last step's arrows instead.
  if (shafts.points.empty()) {
    shafts.action = visualization_msgs::Marker::DELETE;
    heads.action = visualization_msgs::Marker::DELETE;
  }
  out.markers.push_back(shafts);
  out.markers.push_back(heads);
  return out;
}

tf2_msgs::TFMessage RvizMarkers::transforms(const ros::Time& stamp,
                                            const std::vector<sim::VehicleRecord>& vehicles) const {
  tf2_msgs::TFMessage out;
  out.transforms.reserve(vehicles.size() + rsu_poses_.size());
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
  for (const sim::VehicleRecord& v : vehicles) make("vehicle/" + v.id, v.map_x_m, v.map_y_m, v.heading_rad);
  for (std::size_t k = 0; k < rsu_poses_.size(); ++k)
    make("rsu_" + std::to_string(k), rsu_poses_[k].x_m, rsu_poses_[k].y_m, rsu_poses_[k].heading_rad);
  return out;
}

}  // namespace palcas::bridge
