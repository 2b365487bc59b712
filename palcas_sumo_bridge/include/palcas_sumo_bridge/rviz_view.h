#pragma once
// The rviz view of a road: where the top-down camera looks, at which scale, and how much
// the drawing stretches the road across its length so lanes, vehicles and advisory arrows
// can be told apart. rviz cannot fit its camera to what it draws, so the bridge computes
// the view from the lane shapes and writes it into a copy of the shipped .rviz file.
// ROS-free: plain numbers and text, unit-tested in test/rviz_view_test.cpp.

#include <string>
#include <utility>
#include <vector>

namespace palcas::bridge {

/// Axis-aligned box around every lane centre line [m, SUMO network coordinates].
struct RoadExtent {
  double min_x_m = 0.0;
  double max_x_m = 0.0;
  double min_y_m = 0.0;
  double max_y_m = 0.0;
};

/// @throws std::invalid_argument when there is no point at all (no lanes).
RoadExtent roadExtent(const std::vector<std::vector<std::pair<double, double>>>& lane_shapes);

/// Size of an rviz window [px], as its "Window Geometry" says.
struct WindowPx {
  int width = 1400;
  int height = 860;
};

/// Rules of the framing. A freeway is a hundred times longer than wide: fitted to the
/// window's width at true proportions, a 3.2 m lane is under 2 px on the 2.4 km paper road.
struct FramingRules {
  double fill_width = 0.92;       ///< share of the render area's width the road's length takes
  double max_fill_height = 0.6;   ///< the stretched road takes at most this share of the height
  double lane_width_m = 3.2;      ///< SUMO lane width of the scenarios
  double min_lane_px = 18.0;      ///< stretch across until a lane is this many px wide
  // The render area is the window minus rviz's menu, tool and status bars and its frame
  // (measured on rviz 1.14 with the shipped configuration: no side panels).
  int chrome_width_px = 60;
  int chrome_height_px = 110;
};

/// Where the top-down orthographic camera looks and how the markers are drawn.
struct RoadView {
  double centre_x_m = 0.0;     ///< camera centre, in drawing coordinates (x as in SUMO)
  double centre_y_m = 0.0;     ///< camera centre, in drawing coordinates (y stretched)
  double px_per_m = 1.0;       ///< rviz TopDownOrtho "Scale": screen px per drawn metre
  double lateral_scale = 1.0;  ///< drawn y = SUMO y * lateral_scale (>= 1)

  /// A length that covers at least `px` screen pixels [drawn m].
  double metresForPx(double px) const { return px / px_per_m; }
  double drawnY(double sumo_y_m) const { return sumo_y_m * lateral_scale; }
};

/// The camera that shows the whole road, its length across fill_width of the render
/// area, stretched across the road (never squeezed) until a lane is min_lane_px wide
/// but no taller than max_fill_height of the render area.
/// @throws std::invalid_argument for an empty extent or a window too small to draw in.
RoadView frameRoad(const RoadExtent& road, const WindowPx& window, const FramingRules& rules = {});

/// The window size in an rviz configuration's "Window Geometry" block.
/// @throws std::invalid_argument naming what is missing.
WindowPx windowOf(const std::string& rviz_config);

/// The configuration with its current view replaced: TopDownOrtho centred on the view at
/// its scale. Everything else is kept as written.
/// @throws std::invalid_argument when the configuration has no "Views: Current:" block
///         with X, Y and Scale.
std::string withView(const std::string& rviz_config, const RoadView& view);

}  // namespace palcas::bridge
