#pragma once
// The bridge's advisory-hold policy, without ROS or SUMO: an advised CAV holds its
// command for hold_steps bridge steps after the advisory, unless a newer advisory
// replaces it; if the RSU that advised it is late at a step (or lost), the command ends
// at once and the CAV's own driving takes over (bridge README, "What a CAV does").

#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace palcas::sim {

class AdvisoryHolds {
 public:
  /// `keep_steps`: how much longer a command marked keepable holds while no newer advisory
  /// comes (over an impaired channel: v2x keep_advice_s).
  /// @throws std::invalid_argument if hold_steps < 1.
  explicit AdvisoryHolds(std::uint64_t hold_steps, std::uint64_t keep_steps = 0);

  /// `rsu_id` advised `vehicle_id` to take `action` at bridge step `step` (replaces its
  /// previous hold); a `keepable` one holds keep_steps longer.
  void advised(const std::string& vehicle_id, const std::string& rsu_id, std::uint64_t step, int action,
               bool keepable = true);

  /// The vehicles whose command ends at `step`: not advised at this step, and either their
  /// hold ran out (step >= advised step + hold_steps, + keep_steps if keepable) or their RSU
  /// is in `late_rsus`.
  /// They stay known (their command is ended again at later steps until a new advisory:
  /// ending a command is idempotent in the session) until `on_road` says they left, then
  /// they are forgotten.
  std::vector<std::string> ending(std::uint64_t step, const std::unordered_set<std::string>& late_rsus,
                                  const std::function<bool(const std::string&)>& on_road);

  /// (vehicle, action) of every command still in force (not ended), sorted by vehicle:
  /// what rviz draws as advisory arrows.
  std::vector<std::pair<std::string, int>> inForce() const;

  void clear() { holds_.clear(); }
  std::size_t size() const { return holds_.size(); }
  std::uint64_t holdSteps() const { return hold_steps_; }

 private:
  struct Hold {
    std::string rsu_id;
    std::uint64_t step = 0;
    int action = -1;  ///< -1 once the command ended and the CAV's own driving took over
    bool keepable = true;
  };
  std::uint64_t hold_steps_;
  std::uint64_t keep_steps_;
  std::unordered_map<std::string, Hold> holds_;
};

}  // namespace palcas::sim
