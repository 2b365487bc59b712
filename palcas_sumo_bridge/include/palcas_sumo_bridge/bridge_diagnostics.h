#pragma once
// The bridge's /diagnostics (diagnostic_updater, shown by rqt_robot_monitor): the lockstep
// with its RSUs, the simulation, and the advice guard. Each status is built from plain facts
// so its level rules are unit-tested without a ROS master (bridge_diagnostics_test).

#include <diagnostic_updater/DiagnosticStatusWrapper.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace palcas::bridge {

struct LockstepFacts {
  std::vector<std::string> expected;  ///< RSUs the bridge waits for (empty: no lockstep)
  std::vector<std::string> lost;      ///< ... that stopped answering
  std::uint64_t late_steps = 0;       ///< steps some RSU was late, this episode
  std::uint64_t late_steps_new = 0;   ///< ... since the previous report
  std::map<std::string, std::uint64_t> late_by_rsu;
  std::size_t decisions = 0;          ///< RSU decisions measured this episode
  double decision_p50_ms = 0.0, decision_p99_ms = 0.0;  ///< over the recent ones
};
/// OK while every RSU answers in time; WARN when one is lost or some were late since the
/// last report; ERROR when every expected RSU is lost (the CAVs drive themselves).
void describeLockstep(const LockstepFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s);

struct SimulationFacts {
  int episode = 0, episodes = 1;  ///< 1-based episode of episodes
  double sim_s = 0.0, duration_s = 0.0, real_time_factor = 0.0;
  std::uint32_t on_road = 0;
  double speed_mps = 0.0, cr_pct = 0.0, dsr_pct = 0.0, msr_pct = 0.0;
  std::uint32_t collisions = 0, teleports = 0;
  std::uint64_t vanished_vehicles = 0, route_changes_failed = 0, insertion_dropped = 0;
};
/// OK; WARN when SUMO lost track of vehicles (vanished) or dropped some at insertion.
void describeSimulation(const SimulationFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s);

struct GuardFacts {
  bool advisory_control = false;
  bool busy_zones_on = false;
  std::vector<int> busy_zones;      ///< zones busy now
  int zones = 0;
  std::size_t handed_back_now = 0;  ///< CAVs driving themselves (busy zone) now
  std::uint64_t handbacks = 0, advice_dropped = 0, lane_changes_busy_refused = 0;
  double accelerate_guarded_pct = 0.0;  ///< of the CAV time under ACCELERATE, this episode
};
/// OK, with what the guard does now; WARN while every zone is busy (no advice runs at all).
void describeGuard(const GuardFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s);

/// The p-th percentile (0..100) of the last `recent` values (0 when there are none).
double recentPercentile(const std::vector<float>& values, std::size_t recent, double p);

}  // namespace palcas::bridge
