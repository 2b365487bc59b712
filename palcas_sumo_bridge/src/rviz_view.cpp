#include "palcas_sumo_bridge/rviz_view.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace palcas::bridge {
namespace {

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::size_t indentOf(const std::string& line) {
  const std::size_t first = line.find_first_not_of(' ');
  return first == std::string::npos ? line.size() : first;
}

/// "  Key: value" -> "Key" (empty for comments, blank lines and list items).
std::string keyOf(const std::string& line) {
  const std::size_t start = indentOf(line);
  const std::size_t colon = line.find(':', start);
  if (start >= line.size() || line[start] == '#' || line[start] == '-' || colon == std::string::npos)
    return "";
  return line.substr(start, colon - start);
}

/// Lines [begin, end) of the block under the mapping key at line `at` (deeper indentation).
std::size_t blockEnd(const std::vector<std::string>& lines, std::size_t at) {
  const std::size_t own = indentOf(lines[at]);
  std::size_t end = at + 1;
  while (end < lines.size() &&
         (lines[end].find_first_not_of(' ') == std::string::npos || indentOf(lines[end]) > own))
    ++end;
  return end;
}

/// Index of the first line in [begin, end) whose key is `key`, or end.
std::size_t findKey(const std::vector<std::string>& lines, std::size_t begin, std::size_t end,
                    const std::string& key) {
  for (std::size_t i = begin; i < end; ++i)
    if (keyOf(lines[i]) == key) return i;
  return end;
}

std::string formatNumber(double v) {
  std::ostringstream out;
  out.precision(10);
  out << v;
  return out.str();
}

}  // namespace

RoadExtent roadExtent(const std::vector<std::vector<std::pair<double, double>>>& lane_shapes) {
  const double inf = std::numeric_limits<double>::infinity();
  RoadExtent e{inf, -inf, inf, -inf};
  for (const auto& shape : lane_shapes)
    for (const auto& [x, y] : shape) {
      e.min_x_m = std::min(e.min_x_m, x);
      e.max_x_m = std::max(e.max_x_m, x);
      e.min_y_m = std::min(e.min_y_m, y);
      e.max_y_m = std::max(e.max_y_m, y);
    }
  if (e.min_x_m > e.max_x_m) throw std::invalid_argument("road extent: the network has no lane points");
  return e;
}

RoadView frameRoad(const RoadExtent& road, const WindowPx& window, const FramingRules& rules) {
  const double length_m = road.max_x_m - road.min_x_m;
  const double width_m = road.max_y_m - road.min_y_m;
  if (!(length_m > 0.0) || !(width_m >= 0.0))
    throw std::invalid_argument("road extent: x from " + formatNumber(road.min_x_m) + " to " +
                                formatNumber(road.max_x_m) + " m is empty");
  const double area_w = window.width - rules.chrome_width_px;
  const double area_h = window.height - rules.chrome_height_px;
  if (area_w < 100.0 || area_h < 100.0)
    throw std::invalid_argument("rviz window " + std::to_string(window.width) + "x" +
                                std::to_string(window.height) + " px is too small to draw the road in");
  RoadView view;
  // The length fits the width; a road that is tall rather than long fits the height.
  view.px_per_m = rules.fill_width * area_w / length_m;
  if (width_m > 0.0) view.px_per_m = std::min(view.px_per_m, rules.max_fill_height * area_h / width_m);
  // Stretch across only as far as lanes need and the height allows (never below 1: the
  // drawing is never squeezed).
  const double wanted = rules.min_lane_px / (rules.lane_width_m * view.px_per_m);
  const double allowed = width_m > 0.0 ? rules.max_fill_height * area_h / (width_m * view.px_per_m)
                                       : wanted;
  view.lateral_scale = std::max(1.0, std::min(wanted, allowed));
  view.centre_x_m = 0.5 * (road.min_x_m + road.max_x_m);
  view.centre_y_m = view.drawnY(0.5 * (road.min_y_m + road.max_y_m));
  return view;
}

WindowPx windowOf(const std::string& rviz_config) {
  const std::vector<std::string> lines = linesOf(rviz_config);
  const std::size_t at = findKey(lines, 0, lines.size(), "Window Geometry");
  if (at == lines.size() || indentOf(lines[at]) != 0)
    throw std::invalid_argument("rviz configuration: no top-level 'Window Geometry:' block");
  const std::size_t end = blockEnd(lines, at);
  WindowPx w;
  for (auto [key, value] : {std::pair{"Width", &w.width}, std::pair{"Height", &w.height}}) {
    const std::size_t i = findKey(lines, at + 1, end, key);
    if (i == end)
      throw std::invalid_argument(std::string("rviz configuration: 'Window Geometry:' has no ") + key);
    const std::string text = lines[i].substr(lines[i].find(':') + 1);
    try {
      *value = std::stoi(text);
    } catch (const std::exception&) {
      throw std::invalid_argument("rviz configuration: Window Geometry " + std::string(key) +
                                  " '" + text + "' is not a number");
    }
  }
  return w;
}

std::string withView(const std::string& rviz_config, const RoadView& view) {
  std::vector<std::string> lines = linesOf(rviz_config);
  const std::size_t views = findKey(lines, 0, lines.size(), "Views");
  if (views == lines.size())
    throw std::invalid_argument("rviz configuration: no 'Views:' block");
  const std::size_t views_end = blockEnd(lines, views);
  const std::size_t current = findKey(lines, views + 1, views_end, "Current");
  if (current == views_end)
    throw std::invalid_argument("rviz configuration: 'Views:' has no 'Current:' view");
  const std::size_t current_end = blockEnd(lines, current);
  const std::pair<const char*, double> values[] = {
      {"X", view.centre_x_m}, {"Y", view.centre_y_m}, {"Scale", view.px_per_m}};
  for (const auto& [key, value] : values) {
    const std::size_t i = findKey(lines, current + 1, current_end, key);
    if (i == current_end)
      throw std::invalid_argument(std::string("rviz configuration: the current view has no ") + key +
                                  " (a rviz/TopDownOrtho view is expected)");
    lines[i] = std::string(indentOf(lines[i]), ' ') + key + ": " + formatNumber(value);
  }
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

}  // namespace palcas::bridge
