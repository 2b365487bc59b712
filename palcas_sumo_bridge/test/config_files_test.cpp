// Every shipped configuration goes through the real loader (rostest: the launch file loads
// config/bridge.yaml and each scenario's scenario.yaml into a namespace per case), and bad
// files are refused naming the key.
#include <gtest/gtest.h>
#include <palcas_common/param_defaults.h>
#include <ros/ros.h>

#include "common/throws_naming.h"

#include "palcas_sumo_bridge/bridge_options.h"

using palcas::bridge::loadBridgeOptions;

TEST(ConfigFiles, PaperScenarioAndBridgeDefaultsLoad) {
  const auto o = loadBridgeOptions(ros::NodeHandle("~paper"));
  EXPECT_DOUBLE_EQ(o.scenario.mainline_flow_vphpl, 1000.0);  // calibrated (README, departures)
  EXPECT_DOUBLE_EQ(o.scenario.onramp_flow_vphpl, 600.0);     // paper
  EXPECT_DOUBLE_EQ(o.scenario.road.cluster_length_m, 800.0);      // paper
  EXPECT_DOUBLE_EQ(o.scenario.step_length_s, 0.1);
  EXPECT_DOUBLE_EQ(o.scenario.lateral_resolution_m, 3.2);
  EXPECT_DOUBLE_EQ(o.scenario.cav_speed.fast_mps, 33.528);
  EXPECT_TRUE(o.scenario.route_shares.empty());  // the default rule (defaultRouteShares)
  EXPECT_EQ(o.scenario.road.clusters, 3);         // paper
  EXPECT_EQ(o.scenario.road.num_lanes, 5);        // paper
  EXPECT_TRUE(o.scenario.generate_network);
  EXPECT_DOUBLE_EQ(o.session.cluster_length_m, 800.0);
  EXPECT_DOUBLE_EQ(o.session.lane_change_duration_s, 2.0);  // paper
  EXPECT_DOUBLE_EQ(o.comfort_threshold_mps2, 1.47);         // paper
  EXPECT_EQ(o.session.cav_lane_change_mode, 1536);
  EXPECT_TRUE(o.session.own_car_following);
  EXPECT_TRUE(o.session.own_merge);
  EXPECT_DOUBLE_EQ(o.session.max_advised_accel_mps2, 1.47);  // departure; paper: 0 (no clip)
  // Departure, on by default: a busy zone's own lane changes accelerate at most at a_th.
  EXPECT_DOUBLE_EQ(o.session.guard.busy_change_max_accel_mps2, o.comfort_threshold_mps2);
  EXPECT_EQ(o.trajectory_period_steps, 0);
  EXPECT_TRUE(o.session.remove_collided);
  EXPECT_EQ(o.out_dir, "/tmp/palcas_config_test");
}

TEST(ConfigFiles, PrintedDemandScenarioLoads) {
  const auto o = loadBridgeOptions(ros::NodeHandle("~paper_printed"));
  EXPECT_DOUBLE_EQ(o.scenario.mainline_flow_vphpl, 3200.0);  // paper, as printed
  EXPECT_DOUBLE_EQ(o.scenario.onramp_flow_vphpl, 600.0);     // paper
  EXPECT_DOUBLE_EQ(o.scenario.road.cluster_length_m, 800.0);
}

TEST(ConfigFiles, TinyScenarioLoads) {
  const auto o = loadBridgeOptions(ros::NodeHandle("~tiny"));
  EXPECT_DOUBLE_EQ(o.scenario.road.cluster_length_m, 300.0);
  EXPECT_EQ(o.scenario.road.clusters, 2);
  EXPECT_EQ(o.scenario.road.num_lanes, 3);
}

TEST(ConfigFiles, OwnRoadScenarioLoads) {
  // A user's own road: its network file and (here given) mainline reach the scenario.
  const auto o = loadBridgeOptions(ros::NodeHandle("~curved"));
  EXPECT_EQ(o.scenario.network_file, "curved.netccfg");
  EXPECT_EQ(o.scenario.mainline_edges, (std::vector<std::string>{"west_in", "weave", "bend", "straight", "narrow"}));
  EXPECT_TRUE(o.scenario.route_file.empty());
  EXPECT_EQ(o.scenario.road.clusters, 2);
  EXPECT_EQ(o.scenario.road.num_lanes, 5);
}

TEST(ConfigFiles, EveryKeyOfBridgeYamlEqualsTheCompiledInDefault) {
  // A key whose YAML value drifted from the code's default would make runs without the
  // YAML (tests, other launch files) behave differently.
  palcas::common::ParamDefaults defaults;
  loadBridgeOptions(ros::NodeHandle("~empty"), &defaults);
  ASSERT_GT(defaults.values.size(), 30u);
  for (const std::string& line : palcas::common::defaultsDisagreeing(ros::NodeHandle("~defaults"), defaults))
    ADD_FAILURE() << line;
}

TEST(ConfigFiles, TheV2xChannelIsOffUnlessAFileTurnsItOn) {
  const auto off = loadBridgeOptions(ros::NodeHandle("~paper"));
  EXPECT_FALSE(off.v2x.enabled);
  const auto o = loadBridgeOptions(ros::NodeHandle("~impaired"));
  EXPECT_TRUE(o.v2x.enabled);
  EXPECT_DOUBLE_EQ(o.v2x.advisory.latency_s, 0.3);
  EXPECT_DOUBLE_EQ(o.v2x.vehicle_state.loss_probability, 0.3);
  EXPECT_DOUBLE_EQ(o.v2x.cluster_state.latency_s, 0.3);
  EXPECT_DOUBLE_EQ(o.v2x.rsu_range_m, 509.4);  // MOSAIC SNS's default single-hop radius
  EXPECT_DOUBLE_EQ(o.v2x.max_advice_age_s, 0.5);
  EXPECT_DOUBLE_EQ(o.v2x.keep_advice_s, 1.0);
  EXPECT_FALSE(o.v2x.keep_slowing_advice);
  EXPECT_EQ(o.v2x.seed, 104u);
  // A loss probability of 1.
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [] { loadBridgeOptions(ros::NodeHandle("~bad_v2x")); }, "v2x/advisory/loss_probability");
}

TEST(ConfigFiles, UnknownKeyIsNamed) {
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [] { loadBridgeOptions(ros::NodeHandle("~typo")); }, "lockstep_dedline");
}

TEST(ConfigFiles, WrongTypeAndOutOfRangeAreNamed) {
  const auto refused = [](const std::string& ns, const std::string& key) {
    palcas_test::expectThrowNaming<std::invalid_argument>(
        [&] { loadBridgeOptions(ros::NodeHandle(ns)); }, key);
  };
  refused("~wrong_type", "lockstep_deadline_s");         // a string deadline
  refused("~out_of_range", "penetration_rate");          // a penetration rate of 1.2
  refused("~bad_guard", "guard_floor_speed_share");      // a guard floor of 1.5 x allowed speed
  refused("~bad_busy_change", "guard_busy_change_max_accel_mps2");  // a negative accel bound
  refused("~bad_guard_enabled", "guard_enabled");        // a string master switch
}

TEST(ConfigFiles, TheGuardsMasterSwitchLeavesItsKeysAsTheyAre) {
  const auto on = loadBridgeOptions(ros::NodeHandle("~paper"));
  EXPECT_TRUE(on.session.guard.enabled);
  const auto off = loadBridgeOptions(ros::NodeHandle("~guard_off"));
  EXPECT_FALSE(off.session.guard.enabled);
  EXPECT_DOUBLE_EQ(off.session.guard.floor_speed_share, on.session.guard.floor_speed_share);
  EXPECT_DOUBLE_EQ(off.session.guard.busy_speed_share, on.session.guard.busy_speed_share);
  EXPECT_EQ(off.session.guard.insertion_edge, on.session.guard.insertion_edge);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "config_files_test");
  return RUN_ALL_TESTS();
}
