#pragma once
// What a decision of one RSU depends on besides its own state, and whether it has all
// arrived, without ROS. The bridge waits for an RSU only on its decision steps, so between
// two decisions states, vehicle events and the peers' cluster states stream in over separate
// connections, in no fixed order against each other. A decision at step s is taken only
// once this RSU holds
//   - when it trains, the bridge's events of step s (the bridge publishes an event array,
//     empty too, before the states of every step an RSU is due on; on one topic they arrive
//     in order, so the arrays of earlier steps with events are in too). The events close
//     transitions with their terminal rewards; an evaluating RSU decides on the states alone
//     (the bridge removes a vehicle from the states of the step that removes it, so the
//     events change no membership), and waiting for them cost it ~1 ms a decision, and
//   - each neighbour's cluster state of the previous decision round (stamped at or after
//     s - period: the newest a decision at s may use, PeerStates::global),
// so that the same seed gives the same decisions however the messages interleave. A
// neighbour that did not deliver within the RSU's wait is presumed down and not waited for
// again until a cluster state of it arrives (a dead peer costs one wait, not one per
// decision). A new episode needs no reset: an arrival from beyond the decision's step is
// another episode's and does not count, and this episode's arrivals replace it.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace palcas::rsu {

class DecisionInputs {
 public:
  /// @param own_cluster this RSU's cluster index (>= 0) among `zone_count` zones;
  /// @param i2i whether the RSU uses its neighbours' cluster states at all (false: no wait for
  ///        them, e.g. I2I off or the centralized whole-road RSU);
  /// @param decision_period_steps >= 1, the same for every RSU of the road;
  /// @param events whether a decision waits for its step's vehicle events (a training RSU:
  ///        they close its transitions; an evaluating one does not use them).
  /// @throws std::invalid_argument naming the bad value.
  DecisionInputs(int own_cluster, int zone_count, bool i2i, std::uint64_t decision_period_steps,
                 bool events = true);

  /// The bridge's event array of `step` arrived (possibly empty).
  void eventsArrived(std::uint64_t step);
  /// A cluster state of cluster `cluster_index` for decision step `step` arrived (before any
  /// V2X channel draw: a message the channel then loses still arrived). Non-neighbours are ignored.
  void clusterStateArrived(int cluster_index, std::uint64_t step);

  /// What a decision at `step` still lacks, as readable items ("events of step 120",
  /// "cluster state of cluster 2 for step 110"); empty = ready.
  std::vector<std::string> missing(std::uint64_t step) const;
  bool ready(std::uint64_t step) const { return missing(step).empty(); }
  /// The wait for a decision at `step` ended without all of it: the neighbours still missing
  /// are presumed down from now on. @return the clusters newly presumed down.
  std::vector<int> gaveUp(std::uint64_t step);
  /// Neighbours currently presumed down (for diagnostics).
  std::vector<int> presumedDown() const;

 private:
  bool neighbourDue(int cluster, std::uint64_t step) const;

  std::uint64_t period_;
  bool events_;
  std::vector<int> neighbours_;
  std::optional<std::uint64_t> events_step_;          ///< step of the newest event array
  std::map<int, std::uint64_t> cluster_step_;         ///< newest cluster state per neighbour
  std::map<int, bool> presumed_down_;
};

}  // namespace palcas::rsu
