// Where an RSU stands in the map (palcas_sim/roadside.h): along a lane's shape, to its right,
// on straight, turned and bent lines, and the errors for a line that cannot place anything.
#include "palcas_sim/roadside.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/throws_naming.h"

using palcas::sim::MapPose;
using palcas::sim::poseAlong;
using Line = std::vector<std::pair<double, double>>;

namespace {
constexpr double PI = 3.14159265358979323846;
}

TEST(Roadside, AlongAStraightRoadTheRightIsMinusY) {
  const MapPose p = poseAlong({{0.0, -14.4}, {2400.0, -14.4}}, 1200.0, 5.6);
  EXPECT_NEAR(p.x_m, 1200.0, 1e-9);
  EXPECT_NEAR(p.y_m, -20.0, 1e-9);
  EXPECT_NEAR(p.heading_rad, 0.0, 1e-12);
}

TEST(Roadside, OnARoadRunningNorthTheRightIsPlusX) {
  const MapPose p = poseAlong({{10.0, 0.0}, {10.0, 100.0}}, 30.0, 4.0);
  EXPECT_NEAR(p.x_m, 14.0, 1e-9);
  EXPECT_NEAR(p.y_m, 30.0, 1e-9);
  EXPECT_NEAR(p.heading_rad, PI / 2, 1e-12);
}

TEST(Roadside, ABentLineIsFollowedSegmentBySegment) {
  // East 100 m, then north-east: 50 m past the bend.
  const Line bent = {{0.0, 0.0}, {100.0, 0.0}, {100.0, 0.0}, {100.0 + 50.0 * std::sqrt(0.5), 50.0 * std::sqrt(0.5)},
                     {100.0 + 200.0 * std::sqrt(0.5), 200.0 * std::sqrt(0.5)}};
  const MapPose p = poseAlong(bent, 150.0, 0.0);
  EXPECT_NEAR(p.x_m, 100.0 + 50.0 * std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(p.y_m, 50.0 * std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(p.heading_rad, PI / 4, 1e-12);
  // Before the start and past the end: clamped to the ends, with the end segments' direction.
  const MapPose before = poseAlong(bent, -20.0, 1.0);
  EXPECT_NEAR(before.x_m, 0.0, 1e-9);
  EXPECT_NEAR(before.y_m, -1.0, 1e-9);
  const MapPose past = poseAlong(bent, 1e6, 0.0);
  EXPECT_NEAR(past.x_m, bent.back().first, 1e-9);
  EXPECT_NEAR(past.heading_rad, PI / 4, 1e-12);
}

TEST(Roadside, ALineThatCannotPlaceAnythingIsRefused) {
  palcas_test::expectThrowNaming<std::invalid_argument>([] { poseAlong({{0.0, 0.0}}, 0.0, 0.0); }, "needs 2 points");
  palcas_test::expectThrowNaming<std::invalid_argument>([] { poseAlong({{1.0, 1.0}, {1.0, 1.0}}, 0.0, 0.0); },
                                                        "no length");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { poseAlong({{0.0, 0.0}, {nan, 1.0}}, 0.0, 0.0); },
                                                        "point 1 is not finite");
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { poseAlong({{0.0, 0.0}, {1.0, 0.0}}, nan, 0.0); },
                                                        "must be finite");
}
