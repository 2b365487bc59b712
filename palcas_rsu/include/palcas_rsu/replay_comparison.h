#pragma once
// replay_policy's parts that need neither a bag nor a master (tested in
// test/replay_comparison_test.cpp): its command line, and the comparison of a replayed
// decision with the recorded one (agreement by RSU and by recorded action, every
// disagreement as a CSV row, the first divergence in words).

#include <palcas_msgs/AdvisoryArray.h>

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace palcas::rsu {

/// Two ACCELERATE advisories agree when their accelerations differ by at most this [m/s^2].
/// Both are float64 end to end, so an identical decision agrees exactly; the tolerance only
/// absorbs a policy file rewritten with rounding, and is far below anything a CAV would feel.
inline constexpr double DEFAULT_ACCEL_TOLERANCE = 1e-3;

/// A bad command line (replay_policy exits 2).
struct ReplayUsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct ReplayArgs {
  std::string bag;
  std::string policy;
  std::string csv;  ///< default: the bag's path without .bag, + .replay.csv
  double accel_tolerance = DEFAULT_ACCEL_TOLERANCE;
  bool help = false;  ///< -h / --help: print the usage, nothing else
};
extern const char* const REPLAY_USAGE;
/// @throws ReplayUsageError naming the bad or missing argument.
ReplayArgs parseReplayArgs(const std::vector<std::string>& argv);

/// Counts of agreement for one group (all, an RSU, a recorded action).
struct Agreement {
  std::uint64_t compared = 0, agreed = 0;
  std::string percent() const;  ///< "97.50 %", or "n/a" with nothing compared
};

class ReplayComparison {
 public:
  explicit ReplayComparison(double accel_tolerance) : tolerance_(accel_tolerance) {}
  /// One decision: every vehicle advised in either array is one comparison (no advisory on
  /// one side is "none"); disagreements become CSV rows.
  void compare(std::uint64_t step, double time_s, const std::string& rsu_id, const palcas_msgs::AdvisoryArray& recorded,
               const palcas_msgs::AdvisoryArray& replayed);

  const Agreement& total() const { return total_; }
  /// By RSU id; by recorded action (palcas_msgs::Advisory codes, -1 = none recorded).
  const std::map<std::string, Agreement>& byRsu() const { return by_rsu_; }
  const std::map<int, Agreement>& byRecordedAction() const { return by_action_; }
  /// "step S (t = T s), RSU, vehicle V: recorded A, replayed B"; "" while none.
  const std::string& firstDivergence() const { return first_divergence_; }
  /// step,time_s,rsu,vehicle,recorded_action,recorded_accel_mps2,replayed_action,replayed_accel_mps2
  static const char* const CSV_HEADER;
  const std::vector<std::string>& disagreementRows() const { return rows_; }

 private:
  double tolerance_;
  Agreement total_;
  std::map<std::string, Agreement> by_rsu_;
  std::map<int, Agreement> by_action_;
  std::string first_divergence_;
  std::vector<std::string> rows_;
};

/// "LANE_LEFT", …, "KEEP"; "none" for -1; "UNKNOWN" for another code.
const char* replayActionName(int action);

}  // namespace palcas::rsu
