// TransitionBook alone: where each pending CAV went and what its transition is worth.
// The controller's tests (rsu_controller_test) check the same rules end to end.
#include "palcas_core/rsu/transition_book.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"
#include "reward/terminal_rewards_amounts.h"

#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

using palcas::ALL_ACTIONS;
using palcas::VehicleSnapshot;
using palcas::rsu::Closings;
using palcas::rsu::EventSets;
using palcas::rsu::MemberColumns;
using palcas::rsu::PendingDecision;
using palcas::rsu::PendingFates;
using palcas::rsu::RoadIndex;
using palcas::rsu::StateNow;
using palcas::rsu::TransitionBook;
using palcas::rsu::VehicleOutcomes;
using palcas_test::exactTerminalRewards;
using palcas_test::expectThrowNaming;

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

// A pending decision whose state is the single number `tag` and whose reward is `reward`.
PendingDecision decided(float tag, double reward, double exit_m = INF) {
  PendingDecision p;
  p.state = palcas::nn::Vector::Constant(1, tag);
  p.reward = reward;
  p.distance_to_exit_m = exit_m;
  return p;
}

VehicleSnapshot on(const std::string& id, int lane, double exit_m = INF, bool cav = true) {
  VehicleSnapshot v;
  v.id = id;
  v.is_cav = cav;
  v.lane = lane;
  v.distance_to_exit_m = exit_m;
  return v;
}

RoadIndex index(const std::vector<VehicleSnapshot>& road) {
  RoadIndex out;
  for (const VehicleSnapshot& v : road) out.emplace(v.id, &v);
  return out;
}

StateNow now(float tag, double reward) {
  return StateNow{palcas::nn::Vector::Constant(1, tag), ALL_ACTIONS, reward};
}

}  // namespace

TEST(TransitionBook, SortsEveryPendingCavByWhatBecameOfIt) {
  TransitionBook book;
  std::map<std::string, PendingDecision> pending;
  for (const char* id : {"collided", "member", "off_ramp", "outside", "vanished", "exited"})
    pending[id] = decided(0.0f, 0.0);
  book.advance({}, pending);
  const std::vector<VehicleSnapshot> road = {on("collided", 2), on("member", 2), on("off_ramp", 0),
                                             on("outside", 3)};
  VehicleOutcomes outcomes;
  outcomes.collided = {"collided"};
  outcomes.exited = {"exited"};
  const PendingFates f = book.sort(index(road), MemberColumns{{"member", 0}}, EventSets(outcomes));
  EXPECT_EQ(f.removed, (std::vector<std::string>{"collided", "exited"}));
  EXPECT_EQ(f.members, std::vector<std::string>{"member"});
  EXPECT_EQ(f.exit_taken, std::vector<std::string>{"off_ramp"});
  EXPECT_EQ(f.outside_zone, std::vector<std::string>{"outside"});
  EXPECT_EQ(f.vanished, std::vector<std::string>{"vanished"});
}

TEST(TransitionBook, ClosesInIdOrderWithTheTerminalRewards) {
  TransitionBook book;
  std::map<std::string, PendingDecision> pending;
  pending["a_member"] = decided(1.0f, -1.0, 50.0);  // passes its exit
  pending["b_collided"] = decided(2.0f, -1.0);
  pending["c_off_ramp"] = decided(3.0f, -1.0);
  pending["d_handed_over"] = decided(4.0f, -1.0);
  pending["e_vanished"] = decided(5.0f, -1.0);
  book.advance({}, pending);
  const std::vector<VehicleSnapshot> road = {on("a_member", 2), on("c_off_ramp", 0),
                                             on("d_handed_over", 1)};
  VehicleOutcomes outcomes;
  outcomes.collided = {"b_collided"};
  const EventSets events(outcomes);
  const PendingFates fates = book.sort(index(road), MemberColumns{{"a_member", 0}}, events);
  const std::unordered_map<std::string, StateNow> states = {{"a_member", now(10.0f, -0.5)},
                                                            {"d_handed_over", now(40.0f, -0.25)}};
  const Closings c = book.close(fates, index(road), states, events, exactTerminalRewards(), false);
  ASSERT_EQ(c.closures.size(), 4u);
  EXPECT_EQ(c.vanished, std::vector<std::string>{"e_vanished"});
  // member past its exit: its reward now - 8, terminal, s' = its state now
  EXPECT_EQ(c.closures[0].id, "a_member");
  EXPECT_EQ(c.closures[0].reward, -8.5);
  EXPECT_TRUE(c.closures[0].done);
  EXPECT_EQ(c.closures[0].next_state(0), 10.0f);
  // collided: reward at the decision - 10, s' = s
  EXPECT_EQ(c.closures[1].reward, -11.0);
  EXPECT_TRUE(c.closures[1].done);
  EXPECT_EQ(c.closures[1].next_state(0), 2.0f);
  // off-ramp: exit taken, + 2
  EXPECT_EQ(c.closures[2].reward, 1.0);
  EXPECT_TRUE(c.closures[2].done);
  // handed over: continues
  EXPECT_EQ(c.closures[3].reward, -0.25);
  EXPECT_FALSE(c.closures[3].done);
  EXPECT_EQ(c.closures[3].next_state(0), 40.0f);

  // The vanished CAV goes to limbo and is closed at the next decision, with a late event.
  book.advance(c.vanished, {});
  EXPECT_EQ(book.pendingCount(), 0u);
  EXPECT_EQ(book.decisionOf("e_vanished").state(0), 5.0f);
  VehicleOutcomes late;
  late.teleported = {"e_vanished"};
  const EventSets late_events(late);
  const PendingFates none_on_road = book.sort(RoadIndex{}, MemberColumns{}, late_events);
  const Closings next =
      book.close(none_on_road, RoadIndex{}, {}, late_events, exactTerminalRewards(), false);
  ASSERT_EQ(next.closures.size(), 1u);
  EXPECT_EQ(next.closures[0].reward, -11.0);
  EXPECT_TRUE(next.closures[0].done);
  EXPECT_EQ(book.dropAll(), 1u);  // the limbo entry
}

TEST(TransitionBook, PeriodRewardIsTheMeanOfTheStepsAndNow) {
  TransitionBook book;
  book.advance({}, {{"a", decided(1.0f, -1.0)}});
  book.addStepReward("a", -0.5);
  book.addStepReward("a", -1.5);
  book.addStepReward("unknown", 3.0);  // not pending: ignored
  const std::vector<VehicleSnapshot> road = {on("a", 2)};
  const EventSets none{VehicleOutcomes{}};
  const PendingFates fates = book.sort(index(road), MemberColumns{{"a", 0}}, none);
  const Closings c =
      book.close(fates, index(road), {{"a", now(1.0f, -1.0)}}, none, exactTerminalRewards(), true);
  ASSERT_EQ(c.closures.size(), 1u);
  EXPECT_EQ(c.closures[0].reward, -1.0);  // (-0.5 - 1.5 - 1) / 3
}

TEST(TransitionBook, RefusesWhatItCannotCloseNamingTheId) {
  TransitionBook book;
  book.advance({}, {{"a", decided(1.0f, -1.0)}});
  const std::vector<VehicleSnapshot> road = {on("a", 2)};
  const EventSets none{VehicleOutcomes{}};
  const PendingFates fates = book.sort(index(road), MemberColumns{{"a", 0}}, none);
  expectThrowNaming<std::invalid_argument>(
      [&] { book.close(fates, index(road), {}, none, exactTerminalRewards(), false); }, "'a'");
  expectThrowNaming<std::invalid_argument>([&] { book.addStepReward("a", INF); }, "'a'");
  expectThrowNaming<std::invalid_argument>([&] { book.advance({"b"}, {}); }, "'b'");
  expectThrowNaming<std::out_of_range>([&] { book.decisionOf("b"); }, "'b'");
  EXPECT_EQ(book.pendingCount(), 1u);  // nothing changed
}
