// The rule advisor (rule_advisor.h) alone, and behind RsuController's decision interface.
#include "palcas_core/rsu/rule_advisor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/throws_naming.h"
#include "palcas_core/rsu/rsu_controller.h"

using palcas::Action;
using palcas::GlobalDensities;
using palcas::RoadSnapshot;
using palcas::VehicleSnapshot;
using palcas::rsu::AdviceSource;
using palcas::rsu::ResidualDefault;
using palcas::rsu::RsuController;
using palcas::rsu::RsuControllerOptions;
using palcas::rsu::ruleDecision;
using palcas::rsu::RuleAdvisorOptions;
using palcas::rsu::VehicleOutcomes;

namespace {

constexpr double NO_EXIT = std::numeric_limits<double>::infinity();
constexpr int LANES = 5;

VehicleSnapshot cav(const std::string& id, int lane, double x, double to_exit_m = NO_EXIT) {
  VehicleSnapshot v;
  v.id = id;
  v.is_cav = true;
  v.lane = lane;
  v.x_m = x;
  v.lateral_m = lane >= 1 ? 3.2 * (lane - 0.5) : -1.6;
  v.speed_mps = 25.0;
  v.distance_to_exit_m = to_exit_m;
  return v;
}

VehicleSnapshot onAccelLane(const std::string& id, double x) {
  VehicleSnapshot v = cav(id, 0, x);
  v.on_accel_lane = true;
  v.accel_lane_length_m = 200.0;
  v.accel_lane_pos_m = 50.0;
  return v;
}

Action advice(const VehicleSnapshot& v, const RuleAdvisorOptions& o = {}) {
  return ruleDecision(v, LANES, o).action;
}

}  // namespace

TEST(RuleAdvisor, ExitBoundCavMovesRightOnlyOnceItsDistanceIsShortForTheLanesLeft) {
  RuleAdvisorOptions o;
  o.exit_distance_per_lane_m = 300.0;
  o.exit_margin_m = 100.0;
  // Lane 3: two lanes to cross, needs 100 + 2 x 300 = 700 m.
  EXPECT_EQ(advice(cav("a", 3, 0.0, 701.0), o), Action::kKeep);
  EXPECT_EQ(advice(cav("a", 3, 0.0, 699.0), o), Action::kLaneRight);
  // Lane 5: four lanes, 1300 m.
  EXPECT_EQ(advice(cav("b", 5, 0.0, 1299.0), o), Action::kLaneRight);
  EXPECT_EQ(advice(cav("b", 5, 0.0, 1301.0), o), Action::kKeep);
  // Already in lane 1: nothing to cross, never pushed further right or left.
  EXPECT_EQ(advice(cav("c", 1, 0.0, 10.0), o), Action::kKeep);
  EXPECT_EQ(advice(cav("c", 1, 0.0, 5000.0), o), Action::kKeep);
}

TEST(RuleAdvisor, ThroughCavsLeaveTheKeepOutLanesAndStayElsewhere) {
  RuleAdvisorOptions o;
  o.through_keep_out_lanes = 1;
  EXPECT_EQ(advice(cav("t", 1, 0.0), o), Action::kLaneLeft);
  EXPECT_EQ(advice(cav("t", 2, 0.0), o), Action::kKeep);
  o.through_keep_out_lanes = 2;
  EXPECT_EQ(advice(cav("t", 2, 0.0), o), Action::kLaneLeft);
  EXPECT_EQ(advice(cav("t", 3, 0.0), o), Action::kKeep);
  o.through_keep_out_lanes = 0;  // off
  EXPECT_EQ(advice(cav("t", 1, 0.0), o), Action::kKeep);
  // Never left of the leftmost lane, however many lanes are kept clear.
  o.through_keep_out_lanes = LANES;
  EXPECT_EQ(advice(cav("t", LANES, 0.0), o), Action::kKeep);
}

TEST(RuleAdvisor, OnRampCavIsAdvisedOntoTheMainlineUnlessSwitchedOff) {
  RuleAdvisorOptions o;
  EXPECT_EQ(advice(onAccelLane("m", 100.0), o), Action::kLaneLeft);
  o.advise_merge = false;
  EXPECT_EQ(advice(onAccelLane("m", 100.0), o), Action::kKeep);
  // On a ramp off the mainline (lane 0, not an acceleration lane): nothing.
  EXPECT_EQ(advice(cav("r", 0, 100.0, 20.0), o), Action::kKeep);
}

TEST(RuleAdvisor, NeverAdvisesAnAcceleration) {
  for (int lane = 1; lane <= LANES; ++lane)
    for (double to_exit : {NO_EXIT, 50.0, 400.0, 3000.0}) {
      const auto d = ruleDecision(cav("x", lane, 0.0, to_exit), LANES, {});
      EXPECT_NE(d.action, Action::kAccelerate);
      EXPECT_EQ(d.accel_mps2, 0.0f);
    }
}

TEST(RuleAdvisor, BadThresholdsAreRefusedByName) {
  RuleAdvisorOptions o;
  o.exit_distance_per_lane_m = 0.0;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { o.validate(); }, "exit_distance_per_lane_m");
  o = {};
  o.exit_margin_m = std::numeric_limits<double>::quiet_NaN();
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { o.validate(); }, "exit_margin_m");
  o = {};
  o.through_keep_out_lanes = -1;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { o.validate(); }, "through_keep_out_lanes");
}

namespace {

RsuControllerOptions ruleController() {
  RsuControllerOptions o;
  o.rsu_id = "rsu_0";
  o.x_start_m = 0.0;
  o.x_end_m = 800.0;
  o.train = false;
  o.advice_source = AdviceSource::kRules;
  o.pdqn.hidden_sizes = {8};
  return o;
}

}  // namespace

TEST(RuleAdvisor, RsuControllerWithRulesAdvisesEveryMemberByTheRule) {
  RsuController rsu(ruleController());
  RoadSnapshot road;
  road.num_lanes = LANES;
  road.vehicles = {cav("exit_far", 4, 100.0, 2000.0), cav("exit_near", 4, 300.0, 500.0),
                   cav("through_lane1", 1, 400.0), onAccelLane("merging", 200.0),
                   cav("outside_zone", 1, 900.0)};
  VehicleSnapshot hdv = cav("hdv", 1, 150.0);
  hdv.is_cav = false;
  road.vehicles.push_back(hdv);
  const auto out = rsu.advise(road, 10, 1.0, GlobalDensities{}, VehicleOutcomes{});
  ASSERT_EQ(out.advisories.size(), 4u);  // the CAVs of [0, 800) only
  EXPECT_EQ(out.advisories[0].vehicle_id, "exit_far");
  EXPECT_EQ(out.advisories[0].decision.action, Action::kKeep);
  EXPECT_EQ(out.advisories[1].decision.action, Action::kLaneRight);
  EXPECT_EQ(out.advisories[2].decision.action, Action::kLaneLeft);
  EXPECT_EQ(out.advisories[3].vehicle_id, "merging");
  EXPECT_EQ(out.advisories[3].decision.action, Action::kLaneLeft);
  EXPECT_EQ(rsu.stats().action_counts[static_cast<size_t>(Action::kLaneRight)], 1u);
  // The same road gives the same advice: the rule holds no state.
  const auto again = rsu.advise(road, 20, 2.0, GlobalDensities{}, VehicleOutcomes{});
  for (size_t i = 0; i < out.advisories.size(); ++i)
    EXPECT_EQ(again.advisories[i].decision.action, out.advisories[i].decision.action);
}

TEST(RuleAdvisor, RsuControllerRefusesToTrainARuleAndBadRuleOptions) {
  RsuControllerOptions o = ruleController();
  o.train = true;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController rsu(o); }, "advice_source rules");
  o = ruleController();
  o.rules.exit_distance_per_lane_m = -5.0;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController rsu(o); },
                                                        "rules: RuleAdvisorOptions: exit_distance_per_lane_m");
}

namespace {

// The actions an RSU with options `o` advises the five CAVs of one zone (a fresh controller).
std::vector<Action> residualActions(const RsuControllerOptions& o) {
  RoadSnapshot road;
  road.num_lanes = LANES;
  road.vehicles = {cav("exit_far", 4, 100.0, 2000.0), cav("exit_near", 4, 300.0, 500.0),
                   cav("through_lane1", 1, 400.0), onAccelLane("merging", 200.0), cav("through_lane3", 3, 600.0)};
  RsuController rsu(o);
  std::vector<Action> out;
  for (const auto& a : rsu.advise(road, 10, 1.0, GlobalDensities{}, VehicleOutcomes{}).advisories)
    out.push_back(a.decision.action);
  return out;
}

}  // namespace

TEST(RuleAdvisor, ARuleResidualNetworkAdvisesTheRuleUntilDepartingPaysByTheMargin) {
  const auto& actions = residualActions;
  const std::vector<Action> rule = actions(ruleController());
  RsuControllerOptions network = ruleController();
  network.advice_source = AdviceSource::kNetwork;
  const std::vector<Action> alone = actions(network);
  ASSERT_EQ(rule.size(), 5u);
  ASSERT_NE(alone, rule);  // the untrained network advises otherwise: the test can tell them apart
  RsuControllerOptions residual = network;
  residual.rule_residual = true;
  residual.residual_margin = 1e9;  // never worth it: the rule's advice throughout
  EXPECT_EQ(actions(residual), rule);
  residual.residual_margin = 0.0;  // the network's wherever its Q is strictly higher
  EXPECT_EQ(actions(residual), alone);
  residual.residual_margin = -1.0;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController rsu(residual); }, "residual_margin");
  RsuControllerOptions on_rules = ruleController();
  on_rules.rule_residual = true;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController rsu(on_rules); }, "rule_residual");
}

TEST(RuleAdvisor, AResidualOnKeepAdvisesKeepUntilDepartingPaysByTheMargin) {
  const auto& actions = residualActions;
  RsuControllerOptions network = ruleController();
  network.advice_source = AdviceSource::kNetwork;
  const std::vector<Action> alone = actions(network);
  const std::vector<Action> keep(5, Action::kKeep);
  ASSERT_NE(alone, keep);  // the untrained network advises something else: the test can tell
  ASSERT_NE(actions(ruleController()), keep);  // and so does the rule: KEEP is not the rule's
  RsuControllerOptions residual = network;
  residual.rule_residual = true;
  residual.residual_default = ResidualDefault::kKeep;
  residual.residual_margin = 1e9;  // never worth it: KEEP throughout (in assist mode, no advice)
  EXPECT_EQ(actions(residual), keep);
  residual.residual_margin = 0.0;  // the network's wherever its Q beats KEEP's
  EXPECT_EQ(actions(residual), alone);
}

namespace {

/// The rule controller advising from its network, the rule's exit service overriding it.
RsuControllerOptions overriddenNetwork() {
  RsuControllerOptions o = ruleController();
  o.advice_source = AdviceSource::kNetwork;
  o.exit_rule_override = true;
  return o;
}

/// exit_far (lane 4, 2000 m to its exit), exit_near (lane 4, 500 m: the rule's one RIGHT) and a
/// through CAV, all in the zone.
RoadSnapshot exitBoundAndThrough() {
  RoadSnapshot road;
  road.num_lanes = LANES;
  road.vehicles = {cav("exit_far", 4, 100.0, 2000.0), cav("exit_near", 4, 300.0, 500.0), cav("through", 3, 600.0)};
  return road;
}

}  // namespace

TEST(RuleAdvisor, TheExitRuleOverrideSendsTheRulesExitBoundCavsRightWhateverTheNetworkSaid) {
  RsuControllerOptions network = ruleController();
  network.advice_source = AdviceSource::kNetwork;
  RsuControllerOptions overridden = network;
  overridden.exit_rule_override = true;
  // exit_near (lane 4, 500 m to go, below the rule's 100 + 3 x 300 m) is the rule's one RIGHT.
  const std::vector<Action> rule = residualActions(ruleController());
  ASSERT_EQ(rule[1], Action::kLaneRight);
  std::vector<Action> expected = residualActions(network);
  expected[1] = Action::kLaneRight;
  EXPECT_EQ(residualActions(overridden), expected) << "only exit_near's advice changes";

  // Decisions from outside (the batched learner's adviseWith) get the same override.
  RoadSnapshot road = exitBoundAndThrough();
  const std::vector<palcas::Decision> keep(3, palcas::Decision{Action::kKeep, 0.0f});
  const auto actions = [&](const RsuControllerOptions& o) {
    RsuController rsu(o);
    std::vector<Action> out;
    for (const auto& a : rsu.adviseWith(road, 10, 1.0, GlobalDensities{}, VehicleOutcomes{}, keep).advisories)
      out.push_back(a.decision.action);
    return out;
  };
  EXPECT_EQ(actions(network), (std::vector<Action>{Action::kKeep, Action::kKeep, Action::kKeep}));
  EXPECT_EQ(actions(overridden), (std::vector<Action>{Action::kKeep, Action::kLaneRight, Action::kKeep}));
}

TEST(RuleAdvisor, TheExitRuleOverrideActsOnlyBelowItsDensity) {
  const RsuControllerOptions overridden = overriddenNetwork();
  RoadSnapshot road = exitBoundAndThrough();
  // Three vehicles in an 800 m zone of five lanes: 3 / 0.8 / 5 = 0.75 veh/km per lane.
  const std::vector<palcas::Decision> keep(3, palcas::Decision{Action::kKeep, 0.0f});
  const auto nearAction = [&](double below) {
    RsuControllerOptions o = overridden;
    o.exit_rule_below_density_veh_per_km = below;
    RsuController rsu(o);
    return rsu.adviseWith(road, 10, 1.0, GlobalDensities{}, VehicleOutcomes{}, keep).advisories[1].decision.action;
  };
  EXPECT_EQ(nearAction(0.0), Action::kLaneRight) << "0: at any density";
  EXPECT_EQ(nearAction(0.76), Action::kLaneRight) << "the zone is below the limit";
  EXPECT_EQ(nearAction(0.75), Action::kKeep) << "at the limit the network's advice stands";
  EXPECT_EQ(nearAction(0.5), Action::kKeep);

  for (double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    RsuControllerOptions o = overridden;
    o.exit_rule_below_density_veh_per_km = bad;
    palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController rsu(o); },
                                                         "exit_rule_below_density_veh_per_km");
  }
}

TEST(RuleAdvisor, TheExitRuleOverrideWaitsForTheZonesTrafficAndReadsItsWindowsMeanDensity) {
  RsuControllerOptions o = overriddenNetwork();
  o.exit_rule_below_density_veh_per_km = 1.0;
  o.exit_rule_density_window_s = 10.0;
  RsuController rsu(o);
  // 3 vehicles in the 800 m zone of five lanes: 0.75 veh/km per lane; 9 vehicles: 2.25.
  RoadSnapshot light = exitBoundAndThrough();
  RoadSnapshot busy = light;
  for (int i = 0; i < 6; ++i) busy.vehicles.push_back(cav("other" + std::to_string(i), 1 + i % 3, 50.0 + 100.0 * i));
  RoadSnapshot empty;
  empty.num_lanes = LANES;
  uint64_t step = 0;
  const auto nearAction = [&](const RoadSnapshot& road, double time_s) {
    const std::vector<palcas::Decision> keep(road.vehicles.size(), palcas::Decision{Action::kKeep, 0.0f});
    const auto out = rsu.adviseWith(road, ++step, time_s, GlobalDensities{}, VehicleOutcomes{}, keep);
    return out.advisories.size() > 1 ? out.advisories[1].decision.action : Action::kKeep;
  };
  for (int t = 1; t <= 10; ++t)
    EXPECT_EQ(nearAction(light, t), Action::kKeep) << "t " << t << ": the zone has held traffic for less than 10 s";
  EXPECT_EQ(nearAction(light, 11), Action::kLaneRight) << "10 s of a light zone";
  EXPECT_EQ(nearAction(busy, 12), Action::kLaneRight) << "the window's mean, (10 x 0.75 + 2.25) / 11, is below 1";
  EXPECT_EQ(nearAction(busy, 13), Action::kKeep) << "(9 x 0.75 + 2 x 2.25) / 11 is not";
  nearAction(empty, 14);
  for (int t = 15; t < 25; ++t)
    EXPECT_EQ(nearAction(light, t), Action::kKeep) << "t " << t << ": an empty zone started the wait again";
  EXPECT_EQ(nearAction(light, 25), Action::kLaneRight);
  step = 0;  // the bridge restarted: a new episode, and a new wait
  EXPECT_EQ(nearAction(light, 30), Action::kKeep);

  for (double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    RsuControllerOptions invalid = o;
    invalid.exit_rule_density_window_s = bad;
    palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController r(invalid); },
                                                         "exit_rule_density_window_s");
  }
  RsuControllerOptions no_limit = o;
  no_limit.exit_rule_below_density_veh_per_km = 0.0;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController r(no_limit); },
                                                       "exit_rule_density_window_s");
}

TEST(RuleAdvisor, TheExitRuleOverrideActsOnlyBelowItsZonesInflowCountedOverItsWindow) {
  RsuControllerOptions o = overriddenNetwork();
  // 10 s window, five lanes: 13 vehicles new in the window are 13 x 360 / 5 = 936 veh/h per
  // lane, below 1000; 14 are 1008, not.
  o.exit_rule_below_inflow_veh_per_h_per_lane = 1000.0;
  o.exit_rule_inflow_window_s = 10.0;
  RsuController rsu(o);
  RoadSnapshot road = exitBoundAndThrough();
  const auto human = [](const std::string& id, int lane, double x) {
    VehicleSnapshot v = cav(id, lane, x);
    v.is_cav = false;
    return v;
  };
  const auto arrive = [&](const std::string& name, int count, double x_m) {
    for (int i = 0; i < count; ++i) road.vehicles.push_back(human(name + std::to_string(i), 1 + i % LANES, x_m + 7.0 * i));
  };
  uint64_t step = 0;
  const std::vector<palcas::Decision> keep(3, palcas::Decision{Action::kKeep, 0.0f});
  const auto nearAction = [&](double time_s) {
    return rsu.adviseWith(road, ++step, time_s, GlobalDensities{}, VehicleOutcomes{}, keep).advisories[1].decision.action;
  };
  EXPECT_EQ(nearAction(1.0), Action::kKeep) << "the first decision with traffic starts the wait and counts nothing";
  for (int t = 2; t <= 10; ++t) EXPECT_EQ(nearAction(t), Action::kKeep) << "t " << t << ": less than 10 s of traffic";
  EXPECT_EQ(nearAction(11.0), Action::kLaneRight) << "10 s of traffic, none new";
  arrive("in_zone", 13, 400.0);
  arrive("downstream", 4, 820.0);  // beyond the zone's end: not its inflow
  EXPECT_EQ(nearAction(12.0), Action::kLaneRight) << "13 new in the window: 936 veh/h per lane";
  arrive("more", 1, 700.0);
  EXPECT_EQ(nearAction(13.0), Action::kKeep) << "14 new in the window: 1008 veh/h per lane";
  for (int t = 14; t <= 21; ++t) EXPECT_EQ(nearAction(t), Action::kKeep) << "t " << t << ": 14 still in (t - 10, t]";
  EXPECT_EQ(nearAction(22.0), Action::kLaneRight) << "the 13 of t = 12 have left the window";

  // Three vehicles back after an empty zone: 216 veh/h per lane if counted, so only the wait
  // keeps the override off until t = 34.
  const std::vector<VehicleSnapshot> first_three(road.vehicles.begin(), road.vehicles.begin() + 3);
  road.vehicles.clear();
  rsu.adviseWith(road, ++step, 23.0, GlobalDensities{}, VehicleOutcomes{}, {});
  road.vehicles = first_three;
  for (int t = 24; t <= 33; ++t)
    EXPECT_EQ(nearAction(t), Action::kKeep) << "t " << t << ": an empty zone started the wait again";
  EXPECT_EQ(nearAction(34.0), Action::kLaneRight) << "the wait's first decision counted nothing";
  step = 0;  // the bridge restarted: a new episode, and a new wait
  EXPECT_EQ(nearAction(40.0), Action::kKeep);

  RsuControllerOptions dense = o;  // both gates: the density's shuts the override alone
  dense.exit_rule_below_density_veh_per_km = 0.5;
  RsuController both(dense);
  for (int t = 1; t <= 12; ++t) {
    const auto out = both.adviseWith(road, t, t, GlobalDensities{}, VehicleOutcomes{}, keep);
    EXPECT_EQ(out.advisories[1].decision.action, Action::kKeep) << "t " << t;
  }

  for (double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    RsuControllerOptions invalid = o;
    invalid.exit_rule_below_inflow_veh_per_h_per_lane = bad;
    palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController r(invalid); },
                                                         "exit_rule_below_inflow_veh_per_h_per_lane");
  }
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    RsuControllerOptions invalid = o;
    invalid.exit_rule_inflow_window_s = bad;
    palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController r(invalid); },
                                                         "exit_rule_inflow_window_s");
  }
}
