// The node's parameter loader on the shipped files (rostest loads them into ~shipped and
// ~tiny), and its refusals, each naming the key. Broken cases copy ~shipped into their own
// namespace and change one thing.
#include <gtest/gtest.h>
#include <palcas_common/param_defaults.h>
#include <palcas_common/param_test_cases.h>
#include <ros/ros.h>

#include <functional>

#include "palcas_fedserver/fedserver_options.h"

using palcas::fedserver::loadFedServerOptions;

namespace {

ros::NodeHandle caseFrom(const std::string& name, const std::function<void(ros::NodeHandle&)>& change) {
  return palcas::common::paramCase("~shipped", name, change);
}

void expectRefused(const std::string& name, const std::function<void(ros::NodeHandle&)>& change,
                   const std::string& needle) {
  palcas::common::expectLoadRefused([](const ros::NodeHandle& nh) { loadFedServerOptions(nh); }, "~shipped", name, change,
                                    needle);
}

}  // namespace

TEST(FedServerOptions, ShippedFilesLoad) {
  const auto o = loadFedServerOptions(ros::NodeHandle("~shipped"));
  EXPECT_EQ(o.federation.expected_rsus, (std::vector<std::string>{"rsu_0", "rsu_1", "rsu_2"}));
  EXPECT_EQ(o.federation.effectiveQuorum(), 2u);  // quorum 0 -> ceil(2/3 * 3) = 2
  EXPECT_DOUBLE_EQ(o.federation.round_deadline_s, 30.0);
  EXPECT_DOUBLE_EQ(o.federation.liveness_timeout_s, 60.0);  // RSUs send heartbeats every 10 s
  // One source for the default: the YAML and the struct agree.
  EXPECT_DOUBLE_EQ(o.federation.liveness_timeout_s, palcas::FederationOptions{}.liveness_timeout_s);
  EXPECT_EQ(o.federation.max_samples, 1000000000u);  // fedserver.yaml
  EXPECT_EQ(o.learning.hidden_sizes, (std::vector<int>{256, 512, 256}));  // paper
  EXPECT_EQ(o.learning.state_size, 0);  // from the bridge's road (40 + L)
  EXPECT_FLOAT_EQ(o.learning.gamma, 0.995f);                               // paper
  EXPECT_EQ(o.learning.seed, 1u);
  EXPECT_EQ(o.checkpoint_dir, "");
  EXPECT_FALSE(o.resume);
}

TEST(FedServerOptions, EveryKeyOfTheDefaultFilesEqualsTheCompiledInDefault) {
  palcas::common::ParamDefaults defaults;
  loadFedServerOptions(ros::NodeHandle("~empty"), &defaults);
  ASSERT_GT(defaults.values.size(), 25u);
  for (const std::string& line : palcas::common::defaultsDisagreeing(ros::NodeHandle("~defaults"), defaults))
    ADD_FAILURE() << line;
}

TEST(FedServerOptions, TestOverridesLoad) {
  const auto o = loadFedServerOptions(ros::NodeHandle("~tiny"));
  EXPECT_EQ(o.learning.hidden_sizes, std::vector<int>{3});
  EXPECT_EQ(o.learning.state_size, 4);
  EXPECT_EQ(o.federation.expected_rsus.size(), 3u);
  EXPECT_EQ(o.federation.effectiveQuorum(), 2u);
  EXPECT_DOUBLE_EQ(o.federation.round_deadline_s, 1.0);
}

TEST(FedServerOptions, MaxSamplesIsReadAsAWholeNumber) {
  const auto nh = caseFrom("max_samples", [](ros::NodeHandle& n) { n.setParam("max_samples", 5000); });
  EXPECT_EQ(loadFedServerOptions(nh).federation.max_samples, 5000u);
}

TEST(FedServerOptions, RefusesBadParametersNamingTheKey) {
  expectRefused("typo", [](ros::NodeHandle& n) { n.setParam("round_dedline", 1.0); },
                "typo/round_dedline' (see");
  expectRefused("typo_learning", [](ros::NodeHandle& n) { n.setParam("learning/gama", 0.9); },
                "learning/gama");
  expectRefused("learning_range", [](ros::NodeHandle& n) { n.setParam("learning/gamma", 1.5); },
                "learning/gamma' = 1.5");
  expectRefused("missing_rsus", [](ros::NodeHandle& n) { n.deleteParam("expected_rsus"); },
                "expected_rsus' is missing");
  expectRefused("wrong_type", [](ros::NodeHandle& n) { n.setParam("quorum", "two"); },
                "quorum' has the wrong type");
  expectRefused("range", [](ros::NodeHandle& n) { n.setParam("round_deadline_s", 0.0); },
                "round_deadline_s' = 0");
  expectRefused("quorum", [](ros::NodeHandle& n) { n.setParam("quorum", 4); }, "quorum = 4");
  expectRefused("no_rsus", [](ros::NodeHandle& n) {
    n.setParam("expected_rsus", std::vector<std::string>{});
  }, "expected_rsus is empty");
  expectRefused("resume", [](ros::NodeHandle& n) { n.setParam("resume", true); },
                "nothing to resume from");
  expectRefused("pdqn", [](ros::NodeHandle& n) { n.setParam("learning/batch_size", 1); },
                "PdqnConfig.batch_size");
  expectRefused("fractional", [](ros::NodeHandle& n) { n.setParam("max_samples", 10.5); },
                "not a whole number");
  expectRefused("fractional_int", [](ros::NodeHandle& n) { n.setParam("quorum", 1.5); },
                "quorum' = 1.5");
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "fedserver_options_test");
  ros::NodeHandle keep_alive;
  return RUN_ALL_TESTS();
}
