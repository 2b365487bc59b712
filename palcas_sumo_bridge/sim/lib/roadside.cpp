#include "palcas_sim/roadside.h"

#include <cmath>
#include <stdexcept>

namespace palcas::sim {

MapPose poseAlong(const std::vector<std::pair<double, double>>& line, double distance_m, double right_m) {
  if (line.size() < 2)
    throw std::invalid_argument("poseAlong: a line needs 2 points, got " + std::to_string(line.size()));
  if (!std::isfinite(distance_m) || !std::isfinite(right_m))
    throw std::invalid_argument("poseAlong: distance " + std::to_string(distance_m) + " m / offset " +
                                std::to_string(right_m) + " m must be finite");
  double length_m = 0.0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (!std::isfinite(line[i].first) || !std::isfinite(line[i].second))
      throw std::invalid_argument("poseAlong: point " + std::to_string(i) + " is not finite");
    if (i > 0) length_m += std::hypot(line[i].first - line[i - 1].first, line[i].second - line[i - 1].second);
  }
  if (!(length_m > 0.0)) throw std::invalid_argument("poseAlong: the line has no length");
  double left_m = std::min(std::max(distance_m, 0.0), length_m);
  // The segment holding the point (a zero-length one is skipped: it has no direction).
  std::size_t i = 1;
  for (; i < line.size(); ++i) {
    const double seg = std::hypot(line[i].first - line[i - 1].first, line[i].second - line[i - 1].second);
    if (seg > 0.0 && (left_m <= seg || i + 1 == line.size())) break;
    left_m -= seg;
  }
  if (i == line.size()) --i;  // the last segment had no length: step back to one that has
  while (std::hypot(line[i].first - line[i - 1].first, line[i].second - line[i - 1].second) == 0.0) --i;
  const double dx = line[i].first - line[i - 1].first, dy = line[i].second - line[i - 1].second;
  const double seg = std::hypot(dx, dy);
  const double t = std::min(std::max(left_m / seg, 0.0), 1.0);
  MapPose p;
  p.heading_rad = std::atan2(dy, dx);
  // Right of the direction (dx, dy) is (dy, -dx).
  p.x_m = line[i - 1].first + t * dx + right_m * dy / seg;
  p.y_m = line[i - 1].second + t * dy - right_m * dx / seg;
  return p;
}

}  // namespace palcas::sim
