#include "palcas_core/reward/terminal_rewards.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"
#include "reward/terminal_rewards_amounts.h"

#include <limits>
#include <stdexcept>

using palcas::leftTheRoad;
using palcas::stillOnTheRoad;
using palcas::TerminalRewards;
using palcas::TransitionOutcome;
using palcas::TransitionReward;
using palcas_test::exactTerminalRewards;
using palcas_test::expectThrowNaming;

namespace {

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double INF = std::numeric_limits<double>::infinity();

TransitionOutcome outcome(bool collided, bool exit_taken, bool exit_missed, bool merge_failed) {
  TransitionOutcome o;
  o.collided = collided;
  o.exit_taken = exit_taken;
  o.exit_missed = exit_missed;
  o.merge_failed = merge_failed;
  return o;
}

}  // namespace

TEST(TerminalRewards, DefaultsAreThePapersNone) {
  const TerminalRewards none;
  const TransitionOutcome all = outcome(true, true, true, true);
  EXPECT_EQ(leftTheRoad(-0.5, all, none).reward, -0.5);
  EXPECT_TRUE(leftTheRoad(-0.5, all, none).done);
  EXPECT_EQ(stillOnTheRoad(-0.5, false, all, none).reward, -0.5);
  EXPECT_FALSE(stillOnTheRoad(-0.5, false, all, none).done);  // exit_missed_terminal false
}

TEST(TerminalRewards, LeavingTheRoadIsTerminalAndPaysEachOutcome) {
  const TerminalRewards t = exactTerminalRewards();
  EXPECT_EQ(leftTheRoad(-0.5, TransitionOutcome{}, t).reward, -0.5);  // arrived, vanished
  EXPECT_EQ(leftTheRoad(-0.5, outcome(true, false, false, false), t).reward, -10.5);
  EXPECT_EQ(leftTheRoad(-0.5, outcome(false, true, false, false), t).reward, 1.5);
  EXPECT_EQ(leftTheRoad(-0.5, outcome(false, false, false, true), t).reward, -4.5);
  // -0.5 - 10 + 2 - 4; a missed exit is a mainline outcome: not paid off the road.
  EXPECT_EQ(leftTheRoad(-0.5, outcome(true, true, true, true), t).reward, -12.5);
  for (bool c : {false, true})
    for (bool e : {false, true}) EXPECT_TRUE(leftTheRoad(0.0, outcome(c, e, false, false), t).done);
}

TEST(TerminalRewards, OnTheRoadAMissedExitEndsTheTransitionOnlyWhenAsked) {
  TerminalRewards t = exactTerminalRewards();
  const TransitionReward missed =
      stillOnTheRoad(-0.25, false, outcome(false, false, true, false), t);
  EXPECT_EQ(missed.reward, -8.25);
  EXPECT_TRUE(missed.done);
  t.exit_missed_terminal = false;
  EXPECT_FALSE(stillOnTheRoad(-0.25, false, outcome(false, false, true, false), t).done);
  // A done flag set by the place on the road stays set.
  EXPECT_TRUE(stillOnTheRoad(-0.25, true, TransitionOutcome{}, t).done);
  // Merge failed and exit missed together: both paid.
  EXPECT_EQ(stillOnTheRoad(-0.25, false, outcome(false, false, true, true), t).reward, -12.25);
  // Collision and exit taken are not on-the-road outcomes.
  const TransitionReward kept = stillOnTheRoad(-0.25, false, outcome(true, true, false, false), t);
  EXPECT_EQ(kept.reward, -0.25);
  EXPECT_FALSE(kept.done);
}

TEST(TerminalRewards, RejectsBadAmountsAndRewardsNamingThem) {
  auto bad = [](auto change, const char* field) {
    TerminalRewards t;
    change(t);
    expectThrowNaming<std::invalid_argument>([&] { palcas::validateTerminalRewards(t); }, field);
  };
  bad([](TerminalRewards& t) { t.collision_penalty = -1.0; }, "collision_penalty = -1");
  bad([](TerminalRewards& t) { t.collision_penalty = NaN; }, "collision_penalty = nan");
  bad([](TerminalRewards& t) { t.exit_taken_bonus = INF; }, "exit_taken_bonus = inf");
  bad([](TerminalRewards& t) { t.exit_missed_penalty = -0.5; }, "exit_missed_penalty");
  bad([](TerminalRewards& t) { t.merge_failed_penalty = NaN; }, "merge_failed_penalty");
  EXPECT_NO_THROW(palcas::validateTerminalRewards(exactTerminalRewards()));
  expectThrowNaming<std::invalid_argument>(
      [] { leftTheRoad(NaN, TransitionOutcome{}, TerminalRewards{}); }, "reward_so_far");
  expectThrowNaming<std::invalid_argument>(
      [] { stillOnTheRoad(-INF, false, TransitionOutcome{}, TerminalRewards{}); }, "reward");
}
