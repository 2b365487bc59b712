#include "palcas_core/state/state_layout.h"

#include <stdexcept>

namespace palcas {
namespace {

const char* const EGO_NAMES[EGO_FEATURE_COUNT] = {"x",     "lateral", "speed",
                                                  "accel", "lane",    "distance_to_exit"};
const char* const SLOT_NAMES[NEIGHBOUR_SLOT_COUNT] = {"own_lead",    "own_follow", "left_lead",
                                                      "left_follow", "right_lead", "right_follow"};
const char* const FEATURE_NAMES[NEIGHBOUR_FEATURE_COUNT] = {"distance", "speed", "accel", "lane",
                                                            "distance_to_exit"};
const char* const GLOBAL_NAMES[GLOBAL_FEATURE_COUNT] = {"upstream", "own", "downstream"};

}  // namespace

StateLayout::StateLayout(int num_lanes) : num_lanes_(num_lanes) {
  if (num_lanes < 1)
    throw std::invalid_argument("StateLayout: num_lanes must be >= 1, got " +
                                std::to_string(num_lanes));
}

int StateLayout::clusterDensity(int lane) const {
  if (lane < 1 || lane > num_lanes_)
    throw std::invalid_argument("StateLayout: lane " + std::to_string(lane) +
                                " does not exist (1.." + std::to_string(num_lanes_) + ")");
  return clusterMeanSpeed() + lane;
}

std::string StateLayout::name(int index) const {
  if (index < 0 || index >= size())
    throw std::out_of_range("StateLayout: index " + std::to_string(index) + " outside 0.." +
                            std::to_string(size() - 1));
  if (index < EGO_FEATURE_COUNT) return std::string("ego.") + EGO_NAMES[index];
  if (index < clusterMeanSpeed()) {
    const int rel = index - EGO_FEATURE_COUNT;
    return std::string(SLOT_NAMES[rel / NEIGHBOUR_FEATURE_COUNT]) + "." +
           FEATURE_NAMES[rel % NEIGHBOUR_FEATURE_COUNT];
  }
  if (index == clusterMeanSpeed()) return "cluster.mean_speed";
  if (index < globalOffset())
    return "cluster.density_lane" + std::to_string(index - clusterMeanSpeed());
  return std::string("global.") + GLOBAL_NAMES[index - globalOffset()];
}

}  // namespace palcas
