// The road's one vocabulary: codes equal the message constants, names are what the CSV and
// JSON files carry, and a bad code is refused naming it.
#include "palcas_core/common/road_terms.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

using palcas_test::expectThrowNaming;

namespace palcas {
namespace {

TEST(RoadTerms, RouteKindCodesRoundTripAndNameTheirKind) {
  const char* names[] = {"main_through", "main_exit", "ramp_through", "ramp_exit"};
  for (int code = 0; code < ROUTE_KIND_COUNT; ++code) {
    const RouteKind kind = routeKindFromCode(code);
    EXPECT_EQ(static_cast<int>(kind), code);
    EXPECT_EQ(routeKindName(kind), names[code]);
  }
  EXPECT_EQ(routeKindName(static_cast<RouteKind>(9)), "unknown");
}

TEST(RoadTerms, ABadRouteCodeIsRefusedNamingIt) {
  expectThrowNaming<std::invalid_argument>([] { routeKindFromCode(4); }, "route_kind code 4");
  expectThrowNaming<std::invalid_argument>([] { routeKindFromCode(-1); }, "route_kind code -1");
}

TEST(RoadTerms, ExitAndRampRoutes) {
  EXPECT_TRUE(routeHasExit(RouteKind::kMainExit));
  EXPECT_TRUE(routeHasExit(RouteKind::kRampExit));
  EXPECT_FALSE(routeHasExit(RouteKind::kMainThrough));
  EXPECT_TRUE(routeFromRamp(RouteKind::kRampThrough));
  EXPECT_FALSE(routeFromRamp(RouteKind::kMainExit));
}

TEST(RoadTerms, RoadPartNamesAndTheUnknownPartOutsideTheCount) {
  EXPECT_EQ(roadPartName(RoadPart::kMainline), "mainline");
  EXPECT_EQ(roadPartName(RoadPart::kAccelLane), "accel_lane");
  EXPECT_EQ(roadPartName(RoadPart::kOnRamp), "on_ramp");
  EXPECT_EQ(roadPartName(RoadPart::kOffRamp), "off_ramp");
  EXPECT_EQ(roadPartName(RoadPart::kUnknown), "unknown");
  EXPECT_EQ(static_cast<int>(RoadPart::kUnknown), ROAD_PART_COUNT);
}

}  // namespace
}  // namespace palcas
