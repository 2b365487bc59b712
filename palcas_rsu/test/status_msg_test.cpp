// RsuStatus from the controller's statistics and the node's context (toStatusMsg): every
// field lands where rqt_plot and the diagnostics read it.
#include <gtest/gtest.h>

#include <cmath>

#include "palcas_rsu/msg_conversion.h"

using palcas::rsu::RsuControllerStats;
using palcas::rsu::StatusContext;
using palcas::rsu::toStatusMsg;

TEST(StatusMsg, CarriesTheStatisticsAndTheContext) {
  RsuControllerStats s;
  s.member_count = 7;
  s.action_counts = {1, 2, 3, 1};
  s.mean_reward = -0.25;
  s.sum_reward = -1.75;
  s.q_loss = 0.5;
  s.epsilon = 0.3;
  s.gradient_steps = 1234;
  s.samples_since_federation = 56;
  s.model_version = 9;
  s.federation_round = 4;
  StatusContext c;
  c.header.stamp = ros::Time(12.3);
  c.step = 123;
  c.rsu_id = "rsu_2";
  c.train = true;
  c.decision_ms = 1.5f;
  c.stale_peers = 1;
  c.federation_reachable = true;
  const palcas_msgs::RsuStatus m = toStatusMsg(s, c);
  EXPECT_EQ(m.header.stamp, ros::Time(12.3));
  EXPECT_EQ(m.step, 123u);
  EXPECT_EQ(m.rsu_id, "rsu_2");
  EXPECT_EQ(m.mode, "train");
  EXPECT_FLOAT_EQ(m.decision_ms, 1.5f);
  EXPECT_EQ(m.members, 7u);
  ASSERT_EQ(m.action_counts.size(), 4u);
  EXPECT_EQ(m.action_counts[2], 3u);
  EXPECT_DOUBLE_EQ(m.mean_reward, -0.25);
  EXPECT_DOUBLE_EQ(m.sum_reward, -1.75);
  EXPECT_DOUBLE_EQ(m.q_loss, 0.5);
  EXPECT_TRUE(std::isnan(m.param_loss));  // no gradient step of the parameter network yet
  EXPECT_DOUBLE_EQ(m.epsilon, 0.3);
  EXPECT_EQ(m.gradient_steps, 1234u);
  EXPECT_EQ(m.samples_since_federation, 56u);
  EXPECT_EQ(m.model_version, 9u);
  EXPECT_EQ(m.federation_round, 4u);
  EXPECT_EQ(m.stale_peers, 1u);
  EXPECT_TRUE(m.federation_reachable);
  c.train = false;
  EXPECT_EQ(toStatusMsg(s, c).mode, "eval");
}
