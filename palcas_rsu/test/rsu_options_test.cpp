// The RSU node's parameter loader: the shipped files load, their defaults are the structs'
// (one source for every default), and bad values are refused naming the key. Cases copy
// ~shipped into their own namespace and change one thing.
#include <gtest/gtest.h>
#include <palcas_common/param_defaults.h>
#include <palcas_common/param_test_cases.h>
#include <ros/ros.h>

#include "common/throws_naming.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
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
  expectRefused("policy_model", [](ros::NodeHandle& nh) { nh.setParam("rsu/policy_model", std::string("own")); },
                "'own', not one of global, folder_order");
  expectRefused("exit_side", [](ros::NodeHandle& nh) { nh.setParam("rsu/no_left_for_exit_within_m", -5.0); },
                "rsu/no_left_for_exit_within_m");
  expectRefused("dwell", [](ros::NodeHandle& nh) { nh.setParam("rsu/lane_change_dwell_s", -1.0); },
                "rsu/lane_change_dwell_s");
  expectRefused("lane_change_cost", [](ros::NodeHandle& nh) { nh.setParam("rsu/lane_change_cost", -0.2); },
                "rsu/lane_change_cost");
}

// The paper runs the federation's global model on every RSU; the shipped files (departures.yaml)
// run each RSU's own final model where the policy ships one.
TEST(RsuOptions, WhichModelAnEvaluatingRsuRuns) {
  using palcas::rsu::PolicyModel;
  using palcas::rsu::policyFileIn;
  EXPECT_EQ(loadRsuNodeOptions(ros::NodeHandle("~shipped")).policy_model, PolicyModel::kFolderOrder);
  EXPECT_EQ(loadRsuNodeOptions(caseFrom("paper_model", [](ros::NodeHandle& nh) {
              nh.setParam("rsu/policy_model", std::string("global"));
            })).policy_model,
            PolicyModel::kGlobal);

  namespace fs = std::filesystem;
  const fs::path policy = fs::temp_directory_path() / ("rsu_options_policy_" + std::to_string(::getpid()));
  const fs::path ckpt = policy / "checkpoints";
  fs::create_directories(ckpt / "rsu_1");
  fs::create_directories(ckpt / "default");
  std::ofstream(ckpt / "rsu_1" / "model.palcas") << "own";
  std::ofstream(ckpt / "default" / "model.palcas") << "global";
  const std::string own = (ckpt / "rsu_1" / "model.palcas").string();
  const std::string dflt = (ckpt / "default" / "model.palcas").string();
  // A default not marked as the global model (e.g. independent's, from one RSU): own first.
  std::ofstream(policy / "train.json") << "{\"arm\": \"independent\", \"shipped_models\": \"rsu\"}\n";
  EXPECT_EQ(policyFileIn(ckpt.string(), "rsu_1", PolicyModel::kGlobal), own);
  EXPECT_FALSE(palcas::rsu::defaultIsGlobalModel(ckpt.string()));
  // Shipped as tools/ship_policy.py --rsu-models writes it.
  std::ofstream(policy / "train.json") << "{\n \"default_model\": \"global\",\n \"shipped_models\": \"rsu\"\n}\n";
  EXPECT_TRUE(palcas::rsu::defaultIsGlobalModel(ckpt.string()));
  EXPECT_EQ(policyFileIn(ckpt.string(), "rsu_1", PolicyModel::kGlobal), dflt);
  EXPECT_EQ(policyFileIn(ckpt.string(), "rsu_1", PolicyModel::kFolderOrder), own);
  EXPECT_EQ(policyFileIn(ckpt.string(), "rsu_7", PolicyModel::kFolderOrder), dflt);  // a zone not trained
  // A training folder: the server's global model comes first either way.
  fs::create_directories(ckpt / "fedserver");
  std::ofstream(ckpt / "fedserver" / "global_model.palcas") << "server";
  const std::string server = (ckpt / "fedserver" / "global_model.palcas").string();
  EXPECT_EQ(policyFileIn(ckpt.string(), "rsu_1", PolicyModel::kGlobal), server);
  EXPECT_EQ(policyFileIn(ckpt.string(), "rsu_1", PolicyModel::kFolderOrder), server);
  fs::remove_all(policy);
  palcas_test::expectThrowNaming<std::runtime_error>(
      [&] { policyFileIn(ckpt.string(), "rsu_1", PolicyModel::kGlobal); }, "holds no model for rsu_1");
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rsu_options_test");
  return RUN_ALL_TESTS();
}
