// The RSU node's parameter loader: the shipped files load, their defaults are the structs'
// (one source for every default), and bad values are refused naming the key. Cases copy
// ~shipped into their own namespace and change one thing.
#include <gtest/gtest.h>
#include <palcas_common/param_defaults.h>
#include <palcas_common/param_test_cases.h>
#include <ros/ros.h>

#include "common/throws_naming.h"

#include <cmath>
#include <functional>

#include "palcas_rsu/rsu_options.h"

using palcas::rsu::loadRsuNodeOptions;

namespace {

ros::NodeHandle caseFrom(const std::string& name, const std::function<void(ros::NodeHandle&)>& change) {
  return palcas::common::paramCase("~shipped", name, change);
}

void expectRefused(const std::string& name, const std::function<void(ros::NodeHandle&)>& change,
                   const std::string& needle) {
  palcas::common::expectLoadRefused([](const ros::NodeHandle& nh) { loadRsuNodeOptions(nh); }, "~shipped", name, change,
                                    needle);
}

}  // namespace

TEST(RsuOptions, ShippedFilesLoadForTheSecondZone) {
  auto o = loadRsuNodeOptions(ros::NodeHandle("~shipped"));
  EXPECT_EQ(o.controller.rsu_id, "rsu_1");
  EXPECT_TRUE(palcas::rsu::takesFromBridgeRoad(o));  // zones, lanes and state size
  palcas::rsu::adoptBridgeRoad(o, {0.0, 800.0, 1600.0, 2400.0}, 5);
  EXPECT_DOUBLE_EQ(o.controller.x_start_m, 800.0);
  EXPECT_DOUBLE_EQ(o.controller.x_end_m, 1600.0);
  EXPECT_EQ(o.controller.num_lanes, 5);
  EXPECT_EQ(o.controller.pdqn.state_size, 45);  // the paper's, from its 5 lanes
  EXPECT_EQ(o.decision_period_steps, 10);
  EXPECT_TRUE(o.controller.reward_over_period);  // departures.yaml
  EXPECT_FLOAT_EQ(o.controller.pdqn.gamma, 0.97f);
  EXPECT_DOUBLE_EQ(o.federation_heartbeat_s, 10.0);
}

TEST(RsuOptions, AFourLaneFourZoneRoadGivesItsZoneAndStateSize) {
  auto o = loadRsuNodeOptions(caseFrom("four", [](ros::NodeHandle& nh) { nh.setParam("rsu/cluster_index", 3); }));
  palcas::rsu::adoptBridgeRoad(o, {0.0, 300.0, 600.0, 900.0, 1200.0}, 4);
  EXPECT_DOUBLE_EQ(o.controller.x_start_m, 900.0);
  EXPECT_DOUBLE_EQ(o.controller.x_end_m, 1200.0);
  EXPECT_EQ(o.controller.num_lanes, 4);
  EXPECT_EQ(o.controller.pdqn.state_size, 44);
}

TEST(RsuOptions, WhatIsPinnedMustFitTheBridgesRoad) {
  auto expectMismatch = [](const std::string& name, const std::function<void(ros::NodeHandle&)>& change,
                           const std::string& needle) {
    auto o = loadRsuNodeOptions(caseFrom(name, change));
    SCOPED_TRACE(name);
    palcas_test::expectThrowNaming<std::invalid_argument>(
        [&] { palcas::rsu::adoptBridgeRoad(o, {0.0, 800.0, 1600.0, 2400.0}, 4); }, needle);
  };
  expectMismatch("lanes5", [](ros::NodeHandle& nh) { nh.setParam("rsu/num_lanes", 5); },
                 "the bridge's road has 4 lanes but rsu/num_lanes is 5");
  expectMismatch("state45", [](ros::NodeHandle& nh) { nh.setParam("learning/state_size", 45); },
                 "must be 40 + num_lanes = 44");
  expectMismatch("zones", [](ros::NodeHandle& nh) { nh.setParam("zones_m", std::vector<double>{0, 600, 1200}); },
                 "this RSU's zone is [600.0, 1200.0) m but zone 1 of the bridge's road is [800.0, 1600.0) m");
}

TEST(RsuOptions, EveryKeyOfTheDefaultFilesEqualsTheCompiledInDefault) {
  palcas::common::ParamDefaults defaults;
  try {
    loadRsuNodeOptions(ros::NodeHandle("~empty"), &defaults);  // nothing set: every default
  } catch (const std::invalid_argument&) {
    // An empty rsu_id is refused at the end; every key was read (and recorded) before.
  }
  ASSERT_GT(defaults.values.size(), 50u);
  const auto disagree = palcas::common::defaultsDisagreeing(ros::NodeHandle("~defaults"), defaults);
  for (const std::string& line : disagree) ADD_FAILURE() << line;
}

TEST(RsuOptions, TheDefaultsCheckCanFail) {
  palcas::common::ParamDefaults defaults;
  try {
    loadRsuNodeOptions(ros::NodeHandle("~empty"), &defaults);
  } catch (const std::invalid_argument&) {
  }
  const ros::NodeHandle drifted = caseFrom("drifted", [](ros::NodeHandle& nh) {
    nh.setParam("rsu/decision_period_steps", 7);  // shipped: 10
    nh.setParam("rsu/no_such_key", 1);
  });
  const auto disagree = palcas::common::defaultsDisagreeing(drifted, defaults);
  auto mentions = [&](const std::string& needle) {
    for (const std::string& line : disagree)
      if (line.find(needle) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(mentions("rsu/decision_period_steps: YAML 7, compiled-in default 10"));
  EXPECT_TRUE(mentions("rsu/no_such_key: not read by the loader"));
}

TEST(RsuOptions, BadValuesAreRefusedNamingTheKey) {
  expectRefused("typo", [](ros::NodeHandle& nh) { nh.setParam("rsu/decision_period_step", 5); },
                "rsu/decision_period_step");
  expectRefused("lanes", [](ros::NodeHandle& nh) { nh.setParam("rsu/num_lanes", -1); }, "rsu/num_lanes");
  expectRefused("zone", [](ros::NodeHandle& nh) {
    nh.setParam("rsu/cluster_index", 3);
    nh.setParam("zones_m", std::vector<double>{0, 800, 1600, 2400});
  }, "has 3 zone(s)");
  expectRefused("order", [](ros::NodeHandle& nh) { nh.setParam("zones_m", std::vector<double>{0, 800, 700}); },
                "must increase");
  expectRefused("period", [](ros::NodeHandle& nh) { nh.setParam("rsu/decision_period_steps", 2.5); },
                "not a whole number");
  expectRefused("type", [](ros::NodeHandle& nh) { nh.setParam("rsu/train", std::string("yes")); },
                "rsu/train' has the wrong type");
  expectRefused("resume", [](ros::NodeHandle& nh) { nh.setParam("resume", true); }, "nothing to resume from");
  expectRefused("nan", [](ros::NodeHandle& nh) { nh.setParam("reward/iota", std::nan("")); }, "reward/iota");
  expectRefused("wait", [](ros::NodeHandle& nh) { nh.setParam("decision_inputs_wait_s", -0.1); },
                "decision_inputs_wait_s");
  expectRefused("advice", [](ros::NodeHandle& nh) { nh.setParam("rsu/advice", std::string("magic")); },
                "'magic', not one of network, rules");
  expectRefused("rule", [](ros::NodeHandle& nh) { nh.setParam("rules/exit_margin_m", -1.0); },
                "rules/exit_margin_m");
  expectRefused("head", [](ros::NodeHandle& nh) { nh.setParam("rsu/personal_head_layers", -1); },
                "rsu/personal_head_layers");
  expectRefused("residual", [](ros::NodeHandle& nh) { nh.setParam("rsu/residual_default", std::string("none")); },
                "'none', not one of rule, keep");
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rsu_options_test");
  return RUN_ALL_TESTS();
}
