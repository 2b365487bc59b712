#pragma once
// An RSU's /diagnostics status (diagnostic_updater, rqt_robot_monitor): its decisions, I2I
// peers and federation, from the last RsuStatus and the recent decision times. The level
// rules are plain functions, tested without a ROS master (rsu_diagnostics_test).

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <palcas_msgs/RsuStatus.h>

#include <cstddef>
#include <deque>
#include <string>

namespace palcas::rsu {

struct RsuHealthFacts {
  palcas_msgs::RsuStatus last;     ///< the status of the last decision (empty: none yet)
  bool decided = false;            ///< at least one decision made
  std::string policy;              ///< the model file evaluated ("" in training)
  bool i2i = false, federation = false;
  double decision_p99_ms = 0.0;    ///< over the recent decisions
};
/// OK while it decides with fresh peers and a reachable server; WARN with stale peers (I2I
/// on) or an unreachable federation server (federation on, training); WARN before the first
/// decision (waiting for the bridge).
void describeRsu(const RsuHealthFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s);

class RsuDecider;
/// The V2X channel's counts of an RSU as /diagnostics key-values (nothing when it is off).
void addChannelCounts(const RsuDecider& rsu, diagnostic_updater::DiagnosticStatusWrapper& s);

/// The last `capacity` decision times and their nearest-rank percentile.
class RecentTimes {
 public:
  explicit RecentTimes(std::size_t capacity) : capacity_(capacity) {}
  void add(double ms);
  double percentile(double p) const;  ///< 0 when empty
 private:
  std::size_t capacity_;
  std::deque<double> values_;
};

}  // namespace palcas::rsu
