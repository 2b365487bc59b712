// replay_policy's command line and its comparison of replayed with recorded decisions,
// without a bag or a master.
#include <gtest/gtest.h>

#include "palcas_rsu/replay_comparison.h"

using palcas::rsu::parseReplayArgs;
using palcas::rsu::ReplayComparison;
using palcas::rsu::ReplayUsageError;
using Msg = palcas_msgs::Advisory;

namespace {

palcas_msgs::AdvisoryArray array(std::vector<std::tuple<std::string, int, double>> advice) {
  palcas_msgs::AdvisoryArray a;
  for (const auto& [id, action, accel] : advice) {
    Msg m;
    m.vehicle_id = id;
    m.action = static_cast<uint8_t>(action);
    m.accel_mps2 = accel;
    a.advisories.push_back(m);
  }
  return a;
}

std::string usageError(const std::vector<std::string>& argv) {
  try {
    parseReplayArgs(argv);
  } catch (const ReplayUsageError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ReplayArgs, TakesABagAPolicyAndDefaultsTheCsvBesideTheBag) {
  const auto a = parseReplayArgs({"/runs/x/episode.bag", "--policy", "policies/palcas"});
  EXPECT_EQ(a.bag, "/runs/x/episode.bag");
  EXPECT_EQ(a.policy, "policies/palcas");
  EXPECT_EQ(a.csv, "/runs/x/episode.replay.csv");
  EXPECT_DOUBLE_EQ(a.accel_tolerance, palcas::rsu::DEFAULT_ACCEL_TOLERANCE);
  EXPECT_TRUE(parseReplayArgs({"--help"}).help);
}

TEST(ReplayArgs, RefusesWhatIsWrongNamingIt) {
  EXPECT_EQ(usageError({"--policy", "p"}), "no bag given");
  EXPECT_EQ(usageError({"b.bag"}), "--policy DIR is required");
  EXPECT_EQ(usageError({"b.bag", "c.bag", "--policy", "p"}), "one bag only; 'c.bag' is a second");
  EXPECT_EQ(usageError({"b.bag", "--policy"}), "option --policy needs a value");
  EXPECT_EQ(usageError({"b.bag", "--policy", "p", "--rate", "2"}), "unknown option '--rate'");
  for (const char* bad : {"-1", "nan", "x", "inf"})
    EXPECT_EQ(usageError({"b.bag", "--policy", "p", "--accel-tolerance", bad}),
              std::string("--accel-tolerance '") + bad + "': expected a number >= 0")
        << bad;
}

TEST(ReplayComparison, SameAdviceAgreesAndAccelerationsWithinTheTolerance) {
  ReplayComparison c(1e-3);
  c.compare(10, 1.0, "rsu_0", array({{"a", Msg::KEEP, 0.0}, {"b", Msg::ACCELERATE, 1.0}}),
            array({{"a", Msg::KEEP, 0.0}, {"b", Msg::ACCELERATE, 1.0005}}));
  EXPECT_EQ(c.total().compared, 2u);
  EXPECT_EQ(c.total().agreed, 2u);
  EXPECT_EQ(c.total().percent(), "100.00 %");
  EXPECT_TRUE(c.firstDivergence().empty());
  EXPECT_TRUE(c.disagreementRows().empty());
}

TEST(ReplayComparison, EachDisagreementIsARowAndTheFirstIsSaid) {
  ReplayComparison c(1e-3);
  // b: another acceleration; c: advised only in the recording; d: only in the replay.
  c.compare(20, 2.0, "rsu_1", array({{"b", Msg::ACCELERATE, 1.0}, {"c", Msg::LANE_LEFT, 0.0}}),
            array({{"b", Msg::ACCELERATE, 1.5}, {"d", Msg::LANE_RIGHT, 0.0}}));
  EXPECT_EQ(c.total().compared, 3u);
  EXPECT_EQ(c.total().agreed, 0u);
  ASSERT_EQ(c.disagreementRows().size(), 3u);
  EXPECT_EQ(c.disagreementRows()[0], "20,2.000,rsu_1,b,ACCELERATE,1.000000,ACCELERATE,1.500000");
  EXPECT_EQ(c.disagreementRows()[1], "20,2.000,rsu_1,c,LANE_LEFT,0.000000,none,0.000000");
  EXPECT_EQ(c.disagreementRows()[2], "20,2.000,rsu_1,d,none,0.000000,LANE_RIGHT,0.000000");
  EXPECT_EQ(c.firstDivergence(),
            "step 20 (t = 2.0 s), rsu_1, vehicle b: recorded ACCELERATE +1.0000, replayed ACCELERATE +1.5000");
  // Grouped by RSU and by what the recording said (-1: nothing).
  EXPECT_EQ(c.byRsu().at("rsu_1").compared, 3u);
  EXPECT_EQ(c.byRecordedAction().at(Msg::ACCELERATE).compared, 1u);
  EXPECT_EQ(c.byRecordedAction().at(Msg::LANE_LEFT).compared, 1u);
  EXPECT_EQ(c.byRecordedAction().at(-1).compared, 1u);
  c.compare(30, 3.0, "rsu_0", array({{"e", Msg::KEEP, 0.0}}), array({{"e", Msg::KEEP, 0.0}}));
  EXPECT_EQ(c.total().percent(), "25.00 %");
  EXPECT_EQ(c.byRsu().at("rsu_0").percent(), "100.00 %");
  EXPECT_EQ(palcas::rsu::Agreement{}.percent(), "n/a");
}
