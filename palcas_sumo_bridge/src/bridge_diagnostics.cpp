#include "palcas_sumo_bridge/bridge_diagnostics.h"

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace palcas::bridge {
namespace {
using diagnostic_msgs::DiagnosticStatus;

std::string joined(const std::vector<std::string>& names) {
  std::ostringstream out;
  for (std::size_t i = 0; i < names.size(); ++i) out << (i ? ", " : "") << names[i];
  return names.empty() ? "none" : out.str();
}
}  // namespace

void describeLockstep(const LockstepFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s) {
  if (f.expected.empty()) {
    s.summary(DiagnosticStatus::OK, "no lockstep: no RSU expected");
  } else if (!f.lost.empty() && f.lost.size() == f.expected.size()) {
    s.summary(DiagnosticStatus::ERROR, "every RSU lost (" + joined(f.lost) + "): the CAVs drive themselves");
  } else if (!f.lost.empty()) {
    s.summary(DiagnosticStatus::WARN, "RSU lost: " + joined(f.lost) + "; its CAVs drive themselves");
  } else if (f.late_steps_new > 0) {
    s.summaryf(DiagnosticStatus::WARN, "%lu late step(s) since the last report",
               static_cast<unsigned long>(f.late_steps_new));
  } else {
    s.summaryf(DiagnosticStatus::OK, "%zu RSU(s) answering in time", f.expected.size());
  }
  s.add("expected RSUs", joined(f.expected));
  s.add("lost RSUs", joined(f.lost));
  s.add("late steps (episode)", f.late_steps);
  for (const auto& [rsu, late] : f.late_by_rsu) s.add("late steps of " + rsu, late);
  s.add("decisions measured", f.decisions);
  s.addf("decision p50 [ms]", "%.2f", f.decision_p50_ms);
  s.addf("decision p99 [ms]", "%.2f", f.decision_p99_ms);
}

void describeSimulation(const SimulationFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s) {
  if (f.vanished_vehicles > 0)
    s.summaryf(DiagnosticStatus::WARN, "SUMO lost track of %lu vehicle(s)", static_cast<unsigned long>(f.vanished_vehicles));
  else if (f.insertion_dropped > 0)
    s.summaryf(DiagnosticStatus::WARN, "%lu vehicle(s) dropped at insertion: demand above what the road takes",
               static_cast<unsigned long>(f.insertion_dropped));
  else
    s.summaryf(DiagnosticStatus::OK, "episode %d/%d, t = %.0f of %.0f s", f.episode, f.episodes, f.sim_s, f.duration_s);
  s.addf("episode", "%d of %d", f.episode, f.episodes);
  s.addf("simulated [s]", "%.1f", f.sim_s);
  s.addf("real-time factor", "%.2f", f.real_time_factor);
  s.add("vehicles on road", f.on_road);
  s.addf("mean speed [m/s]", "%.2f", f.speed_mps);
  s.addf("CR [%]", "%.2f", f.cr_pct);
  s.addf("DSR [%]", "%.1f", f.dsr_pct);
  s.addf("MSR [%]", "%.1f", f.msr_pct);
  s.add("collisions", f.collisions);
  s.add("teleports", f.teleports);
  s.add("vanished vehicles", f.vanished_vehicles);
  s.add("route changes refused", f.route_changes_failed);
  s.add("dropped at insertion", f.insertion_dropped);
}

void describeGuard(const GuardFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s) {
  std::ostringstream busy;
  for (std::size_t i = 0; i < f.busy_zones.size(); ++i) busy << (i ? ", " : "") << f.busy_zones[i];
  if (!f.advisory_control) {
    s.summary(DiagnosticStatus::OK, "no advisory control (SUMO drives every vehicle)");
  } else if (f.busy_zones_on && f.zones > 0 && static_cast<int>(f.busy_zones.size()) == f.zones) {
    s.summaryf(DiagnosticStatus::WARN, "every zone busy: %zu CAV(s) drive themselves, no advice runs",
               f.handed_back_now);
  } else {
    s.summaryf(DiagnosticStatus::OK, "%zu of %d zone(s) busy, %zu CAV(s) handed back", f.busy_zones.size(), f.zones,
               f.handed_back_now);
  }
  s.add("busy zones", f.busy_zones.empty() ? std::string("none") : busy.str());
  s.add("CAVs handed back now", f.handed_back_now);
  s.add("hand-backs (episode)", f.handbacks);
  s.add("advisories dropped (handed back)", f.advice_dropped);
  s.add("lane changes refused (busy)", f.lane_changes_busy_refused);
  s.addf("ACCELERATE time guarded [%]", "%.1f", f.accelerate_guarded_pct);
}

double recentPercentile(const std::vector<float>& values, std::size_t recent, double p) {
  if (values.empty() || recent == 0) return 0.0;
  const std::size_t n = std::min(recent, values.size());
  std::vector<float> tail(values.end() - static_cast<std::ptrdiff_t>(n), values.end());
  const std::size_t k = std::min(n - 1, static_cast<std::size_t>(std::ceil(p / 100.0 * n)) - (p > 0 ? 1 : 0));
  std::nth_element(tail.begin(), tail.begin() + static_cast<std::ptrdiff_t>(k), tail.end());
  return tail[k];
}

}  // namespace palcas::bridge
