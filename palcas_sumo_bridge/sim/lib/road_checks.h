#pragma once
// Parts of validateRoadSpec that also apply to a hand-written network (generate_network
// false): the fields that describe any road of the naming convention. Private to palcas_sim.

#include "palcas_sim/road_spec.h"

namespace palcas::sim::detail {

/// clusters in [1, 100], cluster_length_m finite in (0, 100000].
/// @throws std::invalid_argument as validateRoadSpec.
void validateRoadZones(const RoadSpec& road);

/// An own road's zone_starts_m / zone_start_edges (RoadSpec): at most one given, one per
/// zone, x from 0 increasing by at least 1 m, edge ids non-empty and distinct. Their fit to
/// the road is discoverOwnRoad's to check. @throws std::invalid_argument naming the key.
void validateZoneStarts(const RoadSpec& road);

/// Refuses zone_starts_m / zone_start_edges on a road of the naming convention.
void refuseZoneStarts(const RoadSpec& road);

/// num_lanes in [1, 10]. @throws std::invalid_argument as validateRoadSpec.
void validateRoadLanes(const RoadSpec& road);

}  // namespace palcas::sim::detail
