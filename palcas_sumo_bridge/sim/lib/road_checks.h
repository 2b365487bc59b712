#pragma once
// Parts of validateRoadSpec that also apply to a hand-written network (generate_network
// false): the fields that describe any road of the naming convention. Private to palcas_sim.

#include "palcas_sim/road_spec.h"

namespace palcas::sim::detail {

/// clusters in [1, 100], cluster_length_m finite in (0, 100000].
/// @throws std::invalid_argument as validateRoadSpec.
void validateRoadZones(const RoadSpec& road);

/// num_lanes in [1, 10]. @throws std::invalid_argument as validateRoadSpec.
void validateRoadLanes(const RoadSpec& road);

}  // namespace palcas::sim::detail
