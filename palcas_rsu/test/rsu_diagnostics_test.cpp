// An RSU's /diagnostics levels from its status, without a ROS master.
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>

#include "palcas_rsu/rsu_diagnostics.h"

using diagnostic_msgs::DiagnosticStatus;
using diagnostic_updater::DiagnosticStatusWrapper;
using palcas::rsu::RecentTimes;
using palcas::rsu::RsuHealthFacts;
using palcas::rsu::describeRsu;

TEST(RsuDiagnostics, WarnsBeforeTheFirstDecisionWithStalePeersAndWithoutTheServer) {
  RsuHealthFacts f;
  f.i2i = f.federation = true;
  DiagnosticStatusWrapper waiting;
  describeRsu(f, waiting);
  EXPECT_EQ(waiting.level, DiagnosticStatus::WARN) << waiting.message;

  f.decided = true;
  f.last.mode = "train";
  f.last.members = 7;
  f.last.federation_reachable = true;
  DiagnosticStatusWrapper ok;
  describeRsu(f, ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK) << ok.message;
  EXPECT_NE(ok.message.find("7 CAV(s)"), std::string::npos) << ok.message;

  f.last.stale_peers = 1;
  DiagnosticStatusWrapper stale;
  describeRsu(f, stale);
  EXPECT_EQ(stale.level, DiagnosticStatus::WARN) << stale.message;
  f.last.stale_peers = 0;
  f.last.federation_reachable = false;
  DiagnosticStatusWrapper unreachable;
  describeRsu(f, unreachable);
  EXPECT_EQ(unreachable.level, DiagnosticStatus::WARN) << unreachable.message;
  f.last.mode = "eval";  // an evaluation does not federate: no warning for the server
  DiagnosticStatusWrapper eval;
  describeRsu(f, eval);
  EXPECT_EQ(eval.level, DiagnosticStatus::OK) << eval.message;
}

TEST(RsuDiagnostics, RecentTimesKeepTheLastOnesAndTheirNearestRank) {
  RecentTimes t(100);
  EXPECT_EQ(t.percentile(99.0), 0.0);
  for (int i = 1; i <= 300; ++i) t.add(i);  // keeps 201..300
  EXPECT_DOUBLE_EQ(t.percentile(99.0), 299.0);
  EXPECT_DOUBLE_EQ(t.percentile(50.0), 250.0);
  EXPECT_DOUBLE_EQ(t.percentile(0.0), 201.0);
}
