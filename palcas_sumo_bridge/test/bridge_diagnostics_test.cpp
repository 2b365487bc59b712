// The bridge's /diagnostics levels from plain facts, without a ROS master.
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>

#include "palcas_sumo_bridge/bridge_diagnostics.h"

using diagnostic_msgs::DiagnosticStatus;
using diagnostic_updater::DiagnosticStatusWrapper;
using namespace palcas::bridge;

namespace {
std::string valueOf(const DiagnosticStatusWrapper& s, const std::string& key) {
  for (const auto& kv : s.values)
    if (kv.key == key) return kv.value;
  return "<missing " + key + ">";
}
}  // namespace

TEST(BridgeDiagnostics, LockstepIsOkWhileEveryRsuAnswersWarnsOnALossAndErrsWhenAllAreLost) {
  LockstepFacts f;
  f.expected = {"rsu_0", "rsu_1"};
  f.decisions = 100;
  f.decision_p99_ms = 2.5;
  DiagnosticStatusWrapper ok;
  describeLockstep(f, ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK) << ok.message;
  EXPECT_EQ(valueOf(ok, "decision p99 [ms]"), "2.50");

  f.late_steps = f.late_steps_new = 3;
  DiagnosticStatusWrapper late;
  describeLockstep(f, late);
  EXPECT_EQ(late.level, DiagnosticStatus::WARN);
  EXPECT_NE(late.message.find("3 late step"), std::string::npos) << late.message;
  f.late_steps_new = 0;  // late once, on time since: OK again
  DiagnosticStatusWrapper recovered;
  describeLockstep(f, recovered);
  EXPECT_EQ(recovered.level, DiagnosticStatus::OK) << recovered.message;

  f.lost = {"rsu_1"};
  DiagnosticStatusWrapper one_lost;
  describeLockstep(f, one_lost);
  EXPECT_EQ(one_lost.level, DiagnosticStatus::WARN);
  EXPECT_NE(one_lost.message.find("rsu_1"), std::string::npos) << one_lost.message;
  f.lost = {"rsu_0", "rsu_1"};
  DiagnosticStatusWrapper all_lost;
  describeLockstep(f, all_lost);
  EXPECT_EQ(all_lost.level, DiagnosticStatus::ERROR) << all_lost.message;

  LockstepFacts none;  // keep and sumo_native: no RSU
  DiagnosticStatusWrapper no_lockstep;
  describeLockstep(none, no_lockstep);
  EXPECT_EQ(no_lockstep.level, DiagnosticStatus::OK);
}

TEST(BridgeDiagnostics, SimulationWarnsWhenSumoLosesOrDropsVehicles) {
  SimulationFacts f;
  f.episode = 1;
  f.sim_s = 60.0;
  f.duration_s = 600.0;
  f.speed_mps = 27.5;
  DiagnosticStatusWrapper ok;
  describeSimulation(f, ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK) << ok.message;
  EXPECT_EQ(valueOf(ok, "mean speed [m/s]"), "27.50");
  f.insertion_dropped = 4;
  DiagnosticStatusWrapper dropped;
  describeSimulation(f, dropped);
  EXPECT_EQ(dropped.level, DiagnosticStatus::WARN);
  f.vanished_vehicles = 1;
  DiagnosticStatusWrapper vanished;
  describeSimulation(f, vanished);
  EXPECT_EQ(vanished.level, DiagnosticStatus::WARN);
  EXPECT_NE(vanished.message.find("lost track"), std::string::npos) << vanished.message;
}

TEST(BridgeDiagnostics, GuardWarnsOnlyWhileEveryZoneIsBusy) {
  GuardFacts f;
  f.advisory_control = true;
  f.busy_zones_on = true;
  f.zones = 3;
  f.busy_zones = {1};
  f.handed_back_now = 12;
  DiagnosticStatusWrapper some;
  describeGuard(f, some);
  EXPECT_EQ(some.level, DiagnosticStatus::OK) << some.message;
  EXPECT_EQ(valueOf(some, "busy zones"), "1");
  EXPECT_EQ(valueOf(some, "CAVs handed back now"), "12");
  f.busy_zones = {0, 1, 2};
  DiagnosticStatusWrapper all;
  describeGuard(f, all);
  EXPECT_EQ(all.level, DiagnosticStatus::WARN) << all.message;
}

TEST(BridgeDiagnostics, RecentPercentileIsTheNearestRankOfTheTail) {
  std::vector<float> ms;
  for (int i = 1; i <= 200; ++i) ms.push_back(static_cast<float>(i));
  EXPECT_FLOAT_EQ(recentPercentile(ms, 100, 50.0), 150.0f);  // the last 100: 101..200
  EXPECT_FLOAT_EQ(recentPercentile(ms, 100, 99.0), 199.0f);
  EXPECT_FLOAT_EQ(recentPercentile(ms, 1000, 100.0), 200.0f);
  EXPECT_FLOAT_EQ(recentPercentile(ms, 1000, 0.0), 1.0f);
  EXPECT_EQ(recentPercentile({}, 100, 99.0), 0.0);
}
