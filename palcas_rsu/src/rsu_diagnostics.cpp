#include "palcas_rsu/rsu_diagnostics.h"

#include "palcas_rsu/rsu_decider.h"

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace palcas::rsu {

void describeRsu(const RsuHealthFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s) {
  using diagnostic_msgs::DiagnosticStatus;
  const palcas_msgs::RsuStatus& st = f.last;
  const bool training = st.mode == "train";
  if (!f.decided)
    s.summary(DiagnosticStatus::WARN, "no decision yet (waiting for the bridge's vehicle states)");
  else if (f.i2i && st.stale_peers > 0)
    s.summaryf(DiagnosticStatus::WARN, "%u peer RSU(s) stale: their zones' densities are old", st.stale_peers);
  else if (f.federation && training && !st.federation_reachable)
    s.summary(DiagnosticStatus::WARN, "federation server not reachable: learning on local weights");
  else
    s.summaryf(DiagnosticStatus::OK, "%s: step %lu, %u CAV(s) advised, %.2f ms", st.mode.c_str(),
               static_cast<unsigned long>(st.step), st.members, st.decision_ms);
  s.add("mode", st.mode.empty() ? std::string("unknown") : st.mode);
  s.add("policy", f.policy.empty() ? std::string(training ? "training" : "none") : f.policy);
  s.add("step", st.step);
  s.add("CAVs advised", st.members);
  s.addf("decision [ms]", "%.2f", st.decision_ms);
  s.addf("decision p99 [ms]", "%.2f", f.decision_p99_ms);
  s.add("stale peers", st.stale_peers);
  s.add("I2I", f.i2i ? "on" : "off");
  s.add("federation", f.federation ? (st.federation_reachable ? "reachable" : "not reachable") : "off");
  s.add("model version", st.model_version);
  s.add("gradient steps", st.gradient_steps);
  s.addf("epsilon", "%.3f", st.epsilon);
}

void RecentTimes::add(double ms) {
  values_.push_back(ms);
  if (values_.size() > capacity_) values_.pop_front();
}

double RecentTimes::percentile(double p) const {
  if (values_.empty()) return 0.0;
  std::vector<double> v(values_.begin(), values_.end());
  const std::size_t rank = static_cast<std::size_t>(std::ceil(p / 100.0 * v.size()));
  const std::size_t k = std::min(v.size() - 1, rank > 0 ? rank - 1 : 0);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

void addChannelCounts(const RsuDecider& rsu, diagnostic_updater::DiagnosticStatusWrapper& s) {
  const v2x::UplinkCounts* n = rsu.uplinkCounts();
  if (!n) return;
  s.add("V2X vehicle states sent", n->sent);
  s.add("V2X vehicle states lost", n->lost);
  s.add("V2X vehicle states out of range", n->out_of_range);
  s.add("V2X vehicles forgotten (state too old)", n->forgotten);
  s.add("V2X mean age of the states used [s]", n->used ? n->used_age_sum_s / static_cast<double>(n->used) : 0.0);
  s.add("V2X cluster states lost", rsu.i2iLost());
  s.add("V2X cluster states received", rsu.i2iReceived());
}

}  // namespace palcas::rsu
