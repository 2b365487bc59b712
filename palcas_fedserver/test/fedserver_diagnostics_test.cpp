// The federation server's /diagnostics levels from its status, without a ROS master.
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>

#include "palcas_fedserver/fedserver_node.h"

using diagnostic_msgs::DiagnosticStatus;
using diagnostic_updater::DiagnosticStatusWrapper;
using palcas::fedserver::FederationFacts;
using palcas::fedserver::describeFederation;

TEST(FedServerDiagnostics, OkWhileRoundsAverageWarnOnRefusalsErrorOnANonFiniteAverage) {
  FederationFacts f;
  f.expected_rsus = 3;
  f.status.round = 4;
  f.status.global_version = 4;
  f.status.submitted = {"rsu_0"};
  f.status.rejected_by_reason = {{"forged", 0}, {"stale_round", 0}};
  f.open_round_age_s = 12.0;
  DiagnosticStatusWrapper ok;
  describeFederation(f, ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK) << ok.message;
  EXPECT_NE(ok.message.find("1 of 3 submitted"), std::string::npos) << ok.message;

  f.rejected_new = 2;  // e.g. two forged submissions since the last report
  DiagnosticStatusWrapper refused;
  describeFederation(f, refused);
  EXPECT_EQ(refused.level, DiagnosticStatus::WARN) << refused.message;
  f.rejected_new = 0;
  f.status.fetch_unknown_rsu = 1;
  DiagnosticStatusWrapper unknown;
  describeFederation(f, unknown);
  EXPECT_EQ(unknown.level, DiagnosticStatus::WARN) << unknown.message;

  f.status.failed_aggregations = 1;
  DiagnosticStatusWrapper failed;
  describeFederation(f, failed);
  EXPECT_EQ(failed.level, DiagnosticStatus::ERROR) << failed.message;
  bool listed = false;
  for (const auto& kv : failed.values) listed |= kv.key == "refused: forged";
  EXPECT_TRUE(listed) << "every refusal reason is listed";
}
