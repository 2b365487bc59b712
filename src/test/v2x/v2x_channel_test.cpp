#include "palcas_core/v2x/v2x_channel.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <string>

using namespace palcas::v2x;
using palcas::RoadSnapshot;
using palcas::VehicleSnapshot;

namespace {

constexpr double STEP_S = 0.1;

ChannelParams on() {
  ChannelParams p;
  p.enabled = true;
  p.seed = 42;
  return p;
}

VehicleSnapshot vehicle(const std::string& id, double x_m) {
  VehicleSnapshot v;
  v.id = id;
  v.x_m = x_m;
  v.speed_mps = 20.0;
  return v;
}

RoadSnapshot road(std::uint64_t step, int vehicles) {
  RoadSnapshot r;
  r.num_lanes = 3;
  for (int i = 0; i < vehicles; ++i) r.vehicles.push_back(vehicle("v" + std::to_string(i), 10.0 * i + 2.0 * step));
  return r;
}

}  // namespace

TEST(V2xChannel, OffDeliversEverythingAtOnce) {
  ChannelParams p;  // enabled = false, whatever the links say
  p.advisory.loss_probability = 0.9;
  p.advisory.latency_s = 5.0;
  p.rsu_range_m = 1.0;
  const Channel c(p, STEP_S);
  for (std::uint64_t k = 0; k < 100; ++k) {
    const Delivery d = c.transmit(MessageClass::ADVISORY, "rsu_0", "v" + std::to_string(k), k);
    EXPECT_FALSE(d.lost);
    EXPECT_EQ(d.delay_steps, 0u);
  }
  EXPECT_TRUE(c.inRange(0.0, 1e6));
}

TEST(V2xChannel, KeepAdviceCountsInWholeStepsAndOnlyWithTheChannelOn) {
  ChannelParams p = on();
  p.keep_advice_s = 1.0;
  EXPECT_EQ(Channel(p, STEP_S).keepAdviceSteps(), 10u);
  p.keep_advice_s = 0.3;
  EXPECT_EQ(Channel(p, STEP_S).keepAdviceSteps(), 3u);  // 0.3 / 0.1 is 2.999... in doubles
  p.keep_advice_s = 0.25;
  EXPECT_EQ(Channel(p, STEP_S).keepAdviceSteps(), 2u);  // a partial step is not kept
  p.enabled = false;
  EXPECT_EQ(Channel(p, STEP_S).keepAdviceSteps(), 0u);
}

TEST(V2xChannel, SameSeedSameFateWhateverTheOrder) {
  ChannelParams p = on();
  p.vehicle_state = {0.05, 0.3, 0.3};
  const Channel a(p, STEP_S), b(p, STEP_S);
  // b asks in reverse order: each message's fate depends on it alone.
  std::vector<Delivery> forward, backward(500);
  for (int i = 0; i < 500; ++i) forward.push_back(a.transmit(MessageClass::VEHICLE_STATE, "v" + std::to_string(i), "rsu_1", 7));
  for (int i = 499; i >= 0; --i) backward[i] = b.transmit(MessageClass::VEHICLE_STATE, "v" + std::to_string(i), "rsu_1", 7);
  for (int i = 0; i < 500; ++i) {
    EXPECT_EQ(forward[i].lost, backward[i].lost) << i;
    EXPECT_EQ(forward[i].delay_steps, backward[i].delay_steps) << i;
  }
  p.seed = 43;
  const Channel other(p, STEP_S);
  int differs = 0;
  for (int i = 0; i < 500; ++i) {
    const Delivery d = other.transmit(MessageClass::VEHICLE_STATE, "v" + std::to_string(i), "rsu_1", 7);
    differs += d.lost != forward[i].lost || d.delay_steps != forward[i].delay_steps;
  }
  EXPECT_GT(differs, 100) << "another seed should give other losses and delays";
}

TEST(V2xChannel, LossRateAndDelayFollowTheLink) {
  ChannelParams p = on();
  p.advisory = {0.1, 0.2, 0.1};  // 100 ms + U(0, 200 ms), 10 % lost
  const Channel c(p, STEP_S);
  int lost = 0, n = 20000;
  double delay_sum = 0.0;
  std::uint64_t min_steps = 99, max_steps = 0;
  for (int i = 0; i < n; ++i) {
    const Delivery d = c.transmit(MessageClass::ADVISORY, "rsu_" + std::to_string(i % 3), "v" + std::to_string(i), i / 7);
    lost += d.lost;
    delay_sum += d.delay_s;
    EXPECT_GE(d.delay_s, 0.1);
    EXPECT_LE(d.delay_s, 0.3 + 1e-12);
    // Delivered at the first step at or after send + delay.
    EXPECT_GE(static_cast<double>(d.delay_steps) * STEP_S, d.delay_s - 1e-9);
    EXPECT_LT(static_cast<double>(d.delay_steps) * STEP_S, d.delay_s + STEP_S);
    min_steps = std::min(min_steps, d.delay_steps);
    max_steps = std::max(max_steps, d.delay_steps);
  }
  EXPECT_NEAR(static_cast<double>(lost) / n, 0.1, 0.01);  // 20000 draws: sd 0.002
  EXPECT_NEAR(delay_sum / n, 0.2, 0.005);
  EXPECT_EQ(min_steps, 2u);  // 0.1 s + a jitter > 0: past the first step
  EXPECT_EQ(max_steps, 3u);
  // An exact step multiple is that many steps, not one more.
  p.advisory = {0.1, 0.0, 0.0};
  EXPECT_EQ(Channel(p, STEP_S).transmit(MessageClass::ADVISORY, "rsu_0", "v", 3).delay_steps, 1u);
}

TEST(V2xChannel, ClassesAndDirectionsDrawApart) {
  ChannelParams p = on();
  p.vehicle_state.loss_probability = p.advisory.loss_probability = p.cluster_state.loss_probability = 0.5;
  const Channel c(p, STEP_S);
  int same_class = 0, same_direction = 0;
  for (int k = 0; k < 2000; ++k) {
    same_class += c.transmit(MessageClass::VEHICLE_STATE, "v", "rsu_0", k).lost ==
                  c.transmit(MessageClass::CLUSTER_STATE, "v", "rsu_0", k).lost;
    same_direction += c.transmit(MessageClass::CLUSTER_STATE, "rsu_0", "rsu_1", k).lost ==
                      c.transmit(MessageClass::CLUSTER_STATE, "rsu_1", "rsu_0", k).lost;
  }
  // Independent coins agree about half the time; a shared draw would agree always.
  EXPECT_NEAR(same_class / 2000.0, 0.5, 0.05);
  EXPECT_NEAR(same_direction / 2000.0, 0.5, 0.05);
}

TEST(V2xChannel, BadParametersAreRefusedNamingTheField) {
  auto refused = [](ChannelParams p, const std::string& field) {
    palcas_test::expectThrowNaming<std::invalid_argument>([&] { Channel c(p, STEP_S); }, field);
  };
  ChannelParams p = on();
  p.advisory.latency_s = -0.1;
  refused(p, "advisory.latency_s");
  p = on();
  p.cluster_state.jitter_s = std::nan("");
  refused(p, "cluster_state.jitter_s");
  p = on();
  p.vehicle_state.loss_probability = 1.0;
  refused(p, "vehicle_state.loss_probability");
  p = on();
  p.rsu_range_m = 0.0;
  refused(p, "rsu_range_m");
  p = on();
  p.max_advice_age_s = -1.0;
  refused(p, "max_advice_age_s");
  p = on();
  p.keep_advice_s = INFINITY;
  refused(p, "keep_advice_s");
  p = on();
  p.max_state_age_s = INFINITY;
  refused(p, "max_state_age_s");
  EXPECT_THROW(Channel(on(), 0.0), std::invalid_argument);
}

TEST(UplinkView, OffIsTheTruth) {
  const Channel c(ChannelParams{}, STEP_S);
  UplinkView view(c, "rsu_0", 300.0);
  const RoadSnapshot truth = road(0, 5);
  const RoadSnapshot seen = view.receive(truth, 0);
  ASSERT_EQ(seen.vehicles.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(seen.vehicles[i].id, truth.vehicles[i].id);
}

TEST(UplinkView, LatencyShowsStaleStatesAndAges) {
  ChannelParams p = on();
  p.vehicle_state = {0.2, 0.0, 0.0};  // two steps late
  const Channel c(p, STEP_S);
  UplinkView view(c, "rsu_0", 0.0);
  EXPECT_TRUE(view.receive(road(0, 3), 0).vehicles.empty());
  EXPECT_TRUE(view.receive(road(1, 3), 1).vehicles.empty());
  const RoadSnapshot at2 = view.receive(road(2, 3), 2);
  ASSERT_EQ(at2.vehicles.size(), 3u);
  EXPECT_DOUBLE_EQ(at2.vehicles[1].x_m, 10.0);  // the position it had at step 0
  view.receive(road(3, 3), 3);
  view.receive(road(4, 3), 4);
  const RoadSnapshot at5 = view.receive(road(5, 3), 5);
  EXPECT_DOUBLE_EQ(at5.vehicles[1].x_m, 10.0 + 2.0 * 3);  // sent at step 3
  EXPECT_NEAR(view.ageS("v1"), 0.2, 1e-12);
  EXPECT_TRUE(std::isnan(view.ageS("nobody")));
  EXPECT_THROW(view.receive(road(5, 3), 5), std::invalid_argument);
}

TEST(UplinkView, LostStatesLeaveTheLastOneUntilItIsTooOld) {
  ChannelParams p = on();
  p.vehicle_state.loss_probability = 0.5;
  p.max_state_age_s = 0.3;
  p.rsu_range_m = INFINITY;  // it drives 2 km
  const Channel c(p, STEP_S);
  UplinkView view(c, "rsu_0", 0.0);
  RoadSnapshot one;
  one.num_lanes = 3;
  one.vehicles.push_back(vehicle("v", 0.0));
  int seen = 0;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    one.vehicles[0].x_m = static_cast<double>(k);
    const RoadSnapshot r = view.receive(one, k);
    if (r.vehicles.empty()) continue;
    ++seen;
    const double age = view.ageS("v");
    EXPECT_LE(age, 0.3 + 1e-9);
    EXPECT_DOUBLE_EQ(r.vehicles[0].x_m, static_cast<double>(k) - std::round(age / STEP_S));
  }
  const UplinkCounts& n = view.counts();
  EXPECT_EQ(n.sent, 2000u);
  EXPECT_EQ(n.lost + n.delivered, 2000u);
  EXPECT_NEAR(static_cast<double>(n.lost) / 2000.0, 0.5, 0.05);
  // Seen unless four in a row were lost (p = 1/16).
  EXPECT_NEAR(seen / 2000.0, 1.0 - 1.0 / 16.0, 0.03);
  EXPECT_GT(n.forgotten, 0u);
}

TEST(UplinkView, VehiclesBeyondTheRangeAreNeverHeard) {
  ChannelParams p = on();
  p.rsu_range_m = 100.0;
  const Channel c(p, STEP_S);
  UplinkView view(c, "rsu_1", 400.0);
  RoadSnapshot r;
  r.vehicles = {vehicle("near", 350.0), vehicle("edge", 500.0), vehicle("far", 501.0), vehicle("behind", 299.0)};
  const RoadSnapshot seen = view.receive(r, 0);
  ASSERT_EQ(seen.vehicles.size(), 2u);
  EXPECT_EQ(seen.vehicles[0].id, "edge");
  EXPECT_EQ(seen.vehicles[1].id, "near");
  EXPECT_EQ(view.counts().out_of_range, 2u);
}

TEST(UplinkView, AVehicleThatLeftTheRoadLeavesTheViewAtOnce) {
  ChannelParams p = on();
  p.vehicle_state = {0.3, 0.0, 0.0};
  const Channel c(p, STEP_S);
  UplinkView view(c, "rsu_0", 0.0);
  for (std::uint64_t k = 0; k < 5; ++k) view.receive(road(k, 2), k);
  EXPECT_EQ(view.receive(road(5, 2), 5).vehicles.size(), 2u);
  // v1 exits: its last state is fresh enough, but it is gone.
  const RoadSnapshot seen = view.receive(road(6, 1), 6);
  ASSERT_EQ(seen.vehicles.size(), 1u);
  EXPECT_EQ(seen.vehicles[0].id, "v0");
}

TEST(DelayLine, ReleasesInArrivalOrder) {
  DelayLine<int> line;
  line.push(5, 1);
  line.push(3, 2);
  line.push(5, 3);
  line.push(9, 4);
  EXPECT_TRUE(line.release(2).empty());
  EXPECT_EQ(line.release(5), (std::vector<int>{2, 1, 3}));
  EXPECT_EQ(line.size(), 1u);
  EXPECT_EQ(line.release(100), (std::vector<int>{4}));
}
