// The rviz view of a road: framing of the shipped roads in the shipped window, lateral
// stretch, the configuration rewrite, and the advisory arrows drawn on that view.
#include "palcas_sumo_bridge/rviz_view.h"

#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "palcas_sumo_bridge/rviz_markers.h"

using palcas::bridge::frameRoad;
using palcas::bridge::FramingRules;
using palcas::bridge::RoadExtent;
using palcas::bridge::RoadView;
using palcas::bridge::WindowPx;

namespace {

// Lane centre extents of the shipped roads (generated from config/scenarios/*/scenario.yaml: mainline
// from x = 0 along y = 0 downwards, on-ramps starting lower).
const RoadExtent PAPER{0.0, 2400.0, -36.0, -1.6};
const RoadExtent TINY{0.0, 600.0, -21.6, -1.6};

std::string shippedConfig() {
  std::ifstream in(PALCAS_RVIZ_CONFIG);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// What the framing promises, whatever the road.
void expectFramed(const RoadExtent& road, const WindowPx& window) {
  const FramingRules rules;
  const RoadView view = frameRoad(road, window, rules);
  const double area_w = window.width - rules.chrome_width_px;
  const double area_h = window.height - rules.chrome_height_px;
  const double length_px = (road.max_x_m - road.min_x_m) * view.px_per_m;
  const double height_px = (road.max_y_m - road.min_y_m) * view.lateral_scale * view.px_per_m;
  EXPECT_LE(length_px, area_w);                         // the whole road is in the window ...
  EXPECT_GE(length_px, 0.9 * area_w);                   // ... and spans nearly all its width
  EXPECT_LE(height_px, rules.max_fill_height * area_h + 1e-9);
  EXPECT_GE(rules.lane_width_m * view.lateral_scale * view.px_per_m, rules.min_lane_px - 1e-9);
  EXPECT_GE(view.lateral_scale, 1.0);
  EXPECT_DOUBLE_EQ(view.centre_x_m, 0.5 * (road.min_x_m + road.max_x_m));
  EXPECT_DOUBLE_EQ(view.centre_y_m, 0.5 * (road.min_y_m + road.max_y_m) * view.lateral_scale);
}

}  // namespace

TEST(RvizView, ExtentOfLaneShapes) {
  const RoadExtent e = palcas::bridge::roadExtent({{{0.0, -1.6}, {300.0, -1.6}}, {{10.0, -20.0}, {60.0, -8.0}}});
  EXPECT_DOUBLE_EQ(e.min_x_m, 0.0);
  EXPECT_DOUBLE_EQ(e.max_x_m, 300.0);
  EXPECT_DOUBLE_EQ(e.min_y_m, -20.0);
  EXPECT_DOUBLE_EQ(e.max_y_m, -1.6);
  EXPECT_THROW(palcas::bridge::roadExtent({}), std::invalid_argument);
  EXPECT_THROW(palcas::bridge::roadExtent({{}}), std::invalid_argument);
}

TEST(RvizView, FramesBothShippedRoadsInTheShippedWindow) {
  const WindowPx window = palcas::bridge::windowOf(shippedConfig());
  expectFramed(PAPER, window);
  expectFramed(TINY, window);
  // The long road needs the stretch: its lanes would be under 2 px at true proportions.
  EXPECT_GT(frameRoad(PAPER, window).lateral_scale, 5.0);
}

TEST(RvizView, FramesOtherWindowsAndShapes) {
  expectFramed(PAPER, WindowPx{800, 600});
  expectFramed(TINY, WindowPx{1920, 1080});
  // A wide, short area is never squeezed across; a tall one fits the height.
  const RoadView square = frameRoad(RoadExtent{0.0, 100.0, -100.0, 0.0}, WindowPx{1400, 860});
  EXPECT_DOUBLE_EQ(square.lateral_scale, 1.0);
  EXPECT_LE(100.0 * square.px_per_m, 0.6 * (860 - FramingRules{}.chrome_height_px) + 1e-9);
  // A straight road without width: framed by its length.
  EXPECT_NO_THROW(frameRoad(RoadExtent{0.0, 500.0, -1.6, -1.6}, WindowPx{}));
}

TEST(RvizView, RefusesWhatCannotBeFramed) {
  EXPECT_THROW(frameRoad(RoadExtent{5.0, 5.0, 0.0, 1.0}, WindowPx{}), std::invalid_argument);
  EXPECT_THROW(frameRoad(PAPER, WindowPx{120, 860}), std::invalid_argument);
}

TEST(RvizView, ReadsTheWindowSize) {
  const WindowPx w = palcas::bridge::windowOf("Panels: []\nWindow Geometry:\n  Height: 700\n  Width: 1000\n  X: 0\n");
  EXPECT_EQ(w.width, 1000);
  EXPECT_EQ(w.height, 700);
  EXPECT_THROW(palcas::bridge::windowOf("Panels: []\n"), std::invalid_argument);
  EXPECT_THROW(palcas::bridge::windowOf("Window Geometry:\n  Height: 700\n"), std::invalid_argument);
  EXPECT_THROW(palcas::bridge::windowOf("Window Geometry:\n  Height: tall\n  Width: 9\n"),
               std::invalid_argument);
}

TEST(RvizView, RewritesOnlyTheCurrentView) {
  const std::string config = shippedConfig();
  RoadView view;
  view.centre_x_m = 300.0;
  view.centre_y_m = -25.5;
  view.px_per_m = 2.25;
  const std::string framed = palcas::bridge::withView(config, view);
  EXPECT_NE(framed.find("      X: 300\n      Y: -25.5\n      Scale: 2.25\n"), std::string::npos) << framed;
  EXPECT_NE(framed.find("Class: rviz/TopDownOrtho"), std::string::npos);
  // Every other line as it was.
  std::istringstream a(config), b(framed);
  int changed = 0;
  for (std::string la, lb; std::getline(a, la) && std::getline(b, lb);) changed += la != lb;
  EXPECT_LE(changed, 3);
  EXPECT_THROW(palcas::bridge::withView("Panels: []\n", view), std::invalid_argument);
  EXPECT_THROW(palcas::bridge::withView("Views:\n  Current:\n    X: 1\n    Y: 2\n", view),
               std::invalid_argument);
}

TEST(RvizMarkers, OneArrowPerAdvisoryColouredByAction) {
  namespace msg = palcas_msgs;
  std::set<std::tuple<float, float, float>> colours;
  for (int a : {msg::Advisory::LANE_LEFT, msg::Advisory::LANE_RIGHT, msg::Advisory::ACCELERATE,
                msg::Advisory::KEEP}) {
    const auto c = palcas::bridge::advisoryColour(a);
    colours.insert({c.r, c.g, c.b});
  }
  EXPECT_EQ(colours.size(), 4u);  // four actions, four colours

  using palcas::sim::EdgeInfo;
  const palcas::sim::RoadLayout road(
      {EdgeInfo{"main_0_up", {}, -1, 0.0, 300.0, 3, false}}, 3, 300.0);
  const RoadView view = frameRoad(TINY, WindowPx{});
  const palcas::bridge::RvizMarkers markers({{{0.0, -1.6}, {600.0, -1.6}}}, road, view);
  std::vector<palcas::sim::VehicleRecord> vehicles(3);
  for (int i = 0; i < 3; ++i) {
    vehicles[i].id = "v" + std::to_string(i);
    vehicles[i].x_m = 100.0 * (i + 1);
    vehicles[i].map_x_m = vehicles[i].x_m;  // drawn at its map position (the same on a straight road)
    vehicles[i].map_y_m = -4.8;
    vehicles[i].is_cav = true;
  }
  const auto out = markers.dynamicMarkers(
      ros::Time(1.0), vehicles,
      {{"v0", msg::Advisory::LANE_LEFT}, {"v1", msg::Advisory::ACCELERATE}, {"gone", msg::Advisory::KEEP}});
  ASSERT_EQ(out.markers.size(), 3u);  // vehicles, arrow shafts, arrow heads
  const auto& cars = out.markers[0];
  EXPECT_EQ(cars.points.size(), 3u);
  EXPECT_GE(cars.scale.x * view.px_per_m, 12.0 - 1e-9);  // at least 12 px long on screen
  const auto& shafts = out.markers[1];
  const auto& heads = out.markers[2];
  ASSERT_EQ(shafts.points.size(), 4u);  // two arrows: the vanished vehicle gets none
  ASSERT_EQ(heads.points.size(), 6u);
  const auto left = palcas::bridge::advisoryColour(msg::Advisory::LANE_LEFT);
  EXPECT_EQ(shafts.colors[0].g, left.g);
  EXPECT_EQ(heads.colors[0].b, left.b);
  // LEFT points one drawn lane towards +y; ACCELERATE straight ahead.
  EXPECT_NEAR(heads.points[0].y - view.drawnY(-4.8), view.drawnY(3.2), 1e-9);
  EXPECT_NEAR(heads.points[3].y, view.drawnY(-4.8), 1e-9);
  EXPECT_GT(heads.points[3].x, 200.0);
  // No advisories: the last step's arrows are deleted, not left standing.
  const auto none = markers.dynamicMarkers(ros::Time(2.0), vehicles, {});
  EXPECT_EQ(none.markers[1].action, visualization_msgs::Marker::DELETE);
  EXPECT_EQ(none.markers[2].action, visualization_msgs::Marker::DELETE);
}

TEST(RvizMarkers, EachRsuFrameIsWhereItsPoseSays) {
  using palcas::sim::EdgeInfo;
  const palcas::sim::RoadLayout road({EdgeInfo{"main_0_up", {}, -1, 0.0, 600.0, 3, false}}, 3, 300.0);
  const RoadView view = frameRoad(TINY, WindowPx{});
  const palcas::bridge::RvizMarkers markers({{{0.0, -1.6}, {600.0, -1.6}}}, road, view,
                                            {{150.0, -7.2, 0.0}, {420.0, 35.0, 1.5707963267948966}});
  const auto tf = markers.transforms(ros::Time(3.0), {});
  ASSERT_EQ(tf.transforms.size(), 2u);
  EXPECT_EQ(tf.transforms[1].header.frame_id, "map");
  EXPECT_EQ(tf.transforms[1].child_frame_id, "rsu_1");
  EXPECT_DOUBLE_EQ(tf.transforms[1].transform.translation.x, 420.0);
  EXPECT_DOUBLE_EQ(tf.transforms[1].transform.translation.y, 35.0);
  EXPECT_NEAR(tf.transforms[1].transform.rotation.z, std::sqrt(0.5), 1e-12);  // a quarter turn
  EXPECT_NEAR(tf.transforms[1].transform.rotation.w, std::sqrt(0.5), 1e-12);
}
