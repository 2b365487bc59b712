#include "palcas_sim/advisory_holds.h"

#include <gtest/gtest.h>

#include <set>

using palcas::sim::AdvisoryHolds;

namespace {
using Ids = std::vector<std::string>;
const std::unordered_set<std::string> NONE_LATE;
std::function<bool(const std::string&)> onRoad(std::set<std::string> ids) {
  return [ids](const std::string& id) { return ids.count(id) > 0; };
}
}  // namespace

TEST(AdvisoryHolds, ACommandHoldsForItsStepsThenEnds) {
  AdvisoryHolds holds(10);
  holds.advised("cav", "rsu_0", 100, 0);
  const auto road = onRoad({"cav"});
  for (std::uint64_t step = 100; step < 110; ++step) EXPECT_EQ(holds.ending(step, NONE_LATE, road), Ids{}) << step;
  EXPECT_EQ(holds.ending(110, NONE_LATE, road), Ids{"cav"});
  EXPECT_EQ(holds.ending(111, NONE_LATE, road), Ids{"cav"});  // ended again until re-advised
}

TEST(AdvisoryHolds, ANewAdvisoryRestartsTheHold) {
  AdvisoryHolds holds(10);
  holds.advised("cav", "rsu_0", 100, 0);
  holds.advised("cav", "rsu_1", 105, 0);  // handed over to the next zone
  EXPECT_EQ(holds.ending(110, NONE_LATE, onRoad({"cav"})), Ids{});
  EXPECT_EQ(holds.ending(115, NONE_LATE, onRoad({"cav"})), Ids{"cav"});
}

TEST(AdvisoryHolds, ALateRsuEndsItsCommandsAtOnceButNotOthers) {
  AdvisoryHolds holds(10);
  holds.advised("a", "rsu_0", 100, 0);
  holds.advised("b", "rsu_1", 100, 0);
  holds.advised("c", "rsu_0", 102, 0);  // advised at this very step: kept
  EXPECT_EQ(holds.ending(102, {"rsu_0"}, onRoad({"a", "b", "c"})), Ids{"a"});
}

TEST(AdvisoryHolds, VehiclesThatLeftAreForgotten) {
  AdvisoryHolds holds(1);
  holds.advised("a", "rsu_0", 1, 0);
  holds.advised("b", "rsu_0", 1, 0);
  EXPECT_EQ(holds.ending(5, NONE_LATE, onRoad({"b"})), Ids{"b"});
  EXPECT_EQ(holds.size(), 1u);
}

TEST(AdvisoryHolds, RefusesAZeroHold) { EXPECT_THROW(AdvisoryHolds(0), std::invalid_argument); }

TEST(AdvisoryHolds, InForceListsHeldCommandsUntilTheyEnd) {
  AdvisoryHolds holds(10);
  holds.advised("b", "rsu_0", 100, 3);
  holds.advised("a", "rsu_1", 105, 1);
  using Pairs = std::vector<std::pair<std::string, int>>;
  EXPECT_EQ(holds.inForce(), (Pairs{{"a", 1}, {"b", 3}}));
  holds.ending(110, NONE_LATE, onRoad({"a", "b"}));  // b's hold ran out
  EXPECT_EQ(holds.inForce(), (Pairs{{"a", 1}}));
  holds.advised("b", "rsu_0", 111, 2);  // advised again
  EXPECT_EQ(holds.inForce(), (Pairs{{"a", 1}, {"b", 2}}));
}

TEST(AdvisoryHolds, OnlyKeepableCommandsHoldTheKeepStepsLonger) {
  AdvisoryHolds holds(10, 5);
  holds.advised("kept", "rsu_0", 100, 2);
  holds.advised("not_kept", "rsu_0", 100, 2, false);
  const auto road = onRoad({"kept", "not_kept"});
  EXPECT_EQ(holds.ending(109, NONE_LATE, road), Ids{});
  EXPECT_EQ(holds.ending(110, NONE_LATE, road), Ids{"not_kept"});
  EXPECT_EQ(holds.ending(114, NONE_LATE, road), Ids{"not_kept"});
  EXPECT_EQ(holds.ending(115, NONE_LATE, road), (Ids{"kept", "not_kept"}));
}
