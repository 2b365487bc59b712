// An RSU's zone and lane count against the bridge's road (checkAgainstRoad): what it
// refuses names both values; what agrees passes.
#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <string>
#include <vector>

#include "palcas_rsu/rsu_options.h"

using palcas::rsu::checkAgainstRoad;
using palcas::rsu::RsuNodeOptions;

namespace {

RsuNodeOptions zone(int index, double start, double end, int lanes = 5) {
  RsuNodeOptions o;
  o.controller.cluster_index = index;
  o.controller.x_start_m = start;
  o.controller.x_end_m = end;
  o.controller.num_lanes = lanes;
  return o;
}

const std::vector<double> PAPER = {0.0, 800.0, 1600.0, 2400.0};

void expectRefusal(const RsuNodeOptions& o, const std::vector<double>& road, int lanes,
                   const std::string& needle) {
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [&] { checkAgainstRoad(o, road, lanes); }, needle);
}

}  // namespace

TEST(RoadCheck, AnRsuOnItsZonePasses) {
  EXPECT_NO_THROW(checkAgainstRoad(zone(1, 800.0, 1600.0), PAPER, 5));
  EXPECT_NO_THROW(checkAgainstRoad(zone(2, 1600.2, 2399.9), PAPER, 5));  // within 0.5 m
  RsuNodeOptions central = zone(0, 0.0, 2400.0);
  central.whole_road = true;
  EXPECT_NO_THROW(checkAgainstRoad(central, PAPER, 5));
  EXPECT_NO_THROW(checkAgainstRoad(zone(0, 0.0, 800.0), {}, 5));  // a road without zones
}

TEST(RoadCheck, AZoneThatIsNotOnTheRoadIsRefusedNamingBoth) {
  expectRefusal(zone(1, 600.0, 1200.0), PAPER, 5,
                "this RSU's zone is [600.0, 1200.0) m but zone 1 of the bridge's road is [800.0, 1600.0) m");
  expectRefusal(zone(3, 2400.0, 3200.0), PAPER, 5, "rsu/cluster_index is 3 but the bridge's road has 3 zone(s)");
  RsuNodeOptions central = zone(0, 0.0, 1600.0);
  central.whole_road = true;
  expectRefusal(central, PAPER, 5, "but the bridge's road spans [0.0, 2400.0) m");
}

TEST(RoadCheck, AnotherLaneCountIsRefusedNamingBoth) {
  expectRefusal(zone(0, 0.0, 800.0, 4), PAPER, 5, "the bridge's road has 5 lanes but rsu/num_lanes is 4");
}
