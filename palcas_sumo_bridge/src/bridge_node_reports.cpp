// BridgeNode's reports on the running episode: /diagnostics (lockstep, simulation, advice
// guard; bridge_diagnostics.h) and the periodic metrics message with its progress line.
#include <palcas_msgs/EpisodeMetrics.h>

#include "palcas_sumo_bridge/bridge_diagnostics.h"
#include "palcas_sumo_bridge/bridge_node.h"
#include "palcas_sumo_bridge/msg_conversion.h"

namespace palcas::bridge {

void BridgeNode::setUpDiagnostics() {
  diagnostics_.setHardwareID("palcas_sumo_bridge");
  diagnostics_.add("lockstep", this, &BridgeNode::diagnoseLockstep);
  diagnostics_.add("simulation", this, &BridgeNode::diagnoseSimulation);
  diagnostics_.add("advice guard", this, &BridgeNode::diagnoseGuard);
}

void BridgeNode::diagnoseLockstep(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const sim::Lockstep& lockstep = runner_->lockstep();
  LockstepFacts f;
  f.expected = options_.expected_rsus;
  f.lost = lockstep.lostRsus();
  f.late_steps = lockstep.lateSteps();
  f.late_steps_new = f.late_steps >= late_steps_reported_ ? f.late_steps - late_steps_reported_ : f.late_steps;
  late_steps_reported_ = f.late_steps;
  f.late_by_rsu = runner_->lateByRsu();
  const std::vector<float>& decision_ms = runner_->decisionMs();
  f.decisions = decision_ms.size();
  constexpr std::size_t RECENT = 2000;  // decisions: about the last 10 simulated minutes of 3 RSUs
  f.decision_p50_ms = recentPercentile(decision_ms, RECENT, 50.0);
  f.decision_p99_ms = recentPercentile(decision_ms, RECENT, 99.0);
  describeLockstep(f, s);
}

void BridgeNode::diagnoseSimulation(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const metrics::EpisodeMetrics m = measure_->metrics().snapshot();
  SimulationFacts f;
  f.episode = episode_ + 1;
  f.episodes = options_.first_episode + options_.episodes;
  f.sim_s = session().timeS();
  f.duration_s = options_.scenario.duration_s;
  const double wall_s = runner_->wallSeconds();
  f.real_time_factor = wall_s > 0.0 ? f.sim_s / wall_s : 0.0;
  f.on_road = m.vehicles_on_road;
  f.speed_mps = m.efficiency_all_mps;
  f.cr_pct = m.collision_rate_pct;
  f.dsr_pct = m.dsr_pct;
  f.msr_pct = m.msr_pct;
  f.collisions = m.collisions;
  f.teleports = m.teleports;
  f.vanished_vehicles = session().vanishedVehicles();
  f.route_changes_failed = session().routeChangesFailed();
  f.insertion_dropped = session().insertionDropped();
  describeSimulation(f, s);
}

void BridgeNode::diagnoseGuard(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const sim::SessionOptions& o = options_.session;
  const sim::GuardCounters& g = session().guardCounters();
  GuardFacts f;
  f.advisory_control = o.advisory_control;
  f.busy_zones_on = o.guard.enabled && o.guard.busy_speed_share > 0.0;
  f.zones = static_cast<int>(session().road().clusters().size());
  for (int k = 0; k < f.zones; ++k)
    if (session().zoneBusy(k)) f.busy_zones.push_back(k);
  for (const sim::VehicleRecord& v : session().vehicles()) f.handed_back_now += v.guard.handed_back ? 1 : 0;
  f.handbacks = g.handbacks;
  f.advice_dropped = g.handback_advice_dropped;
  f.lane_changes_busy_refused = g.lane_changes_busy_refused;
  f.accelerate_guarded_pct = g.accelerate_steps > 0
      ? 100.0 * static_cast<double>(g.accelerate_floored_steps + g.accelerate_released_steps) / g.accelerate_steps
      : 0.0;
  describeGuard(f, s);
}

void BridgeNode::progress(const sim::SumoSession& session) {
  palcas_msgs::EpisodeMetrics msg = toMsg(measure_->metrics().snapshot(), runner_->wallSeconds());
  msg.header.stamp = ros::Time(session.timeS());
  msg.step = session.stepCount();
  msg.insertion_dropped = static_cast<std::uint32_t>(session.insertionDropped());
  metrics_pub_.publish(msg);
  // Time left over every remaining episode, at this episode's pace.
  const int episodes_left = options_.first_episode + options_.episodes - episode_;
  const double remaining_sim_s = options_.scenario.duration_s * episodes_left - msg.sim_seconds;
  const double left_s = msg.real_time_factor > 0.0 ? remaining_sim_s / msg.real_time_factor : 0.0;
  ROS_INFO_NAMED("episode", "palcas bridge: episode %d/%d  t=%6.0f/%.0f s  on road %4u  speed %5.2f m/s (CAV %5.2f)  CR %5.2f%%  "
           "DSR %5.1f%%  MSR %5.1f%%  RTF %5.1fx  ~%.0f s left",
           episode_ + 1, options_.first_episode + options_.episodes, msg.sim_seconds, options_.scenario.duration_s, msg.vehicles_on_road, msg.efficiency_all_mps,
           msg.efficiency_cav_mps, msg.collision_rate_pct, msg.dsr_pct, msg.msr_pct,
           msg.real_time_factor, left_s);
}

}  // namespace palcas::bridge
