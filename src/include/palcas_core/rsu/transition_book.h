#pragma once
// One RSU's open transitions and the rules that close them (src/doc/rsu.md, "Closing a
// pending transition"). A member's decision stays pending until the next decision tells
// what became of the CAV: still a member, handed over to the next zone, on its off-ramp
// (the exit taken), removed by an event, or gone without one (limbo: its event may still be
// on its way on another topic, so it is closed one decision later). RsuController builds
// the states and rewards of the CAVs still on the road and stores what is closed here.

#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "palcas_core/common/action.h"
#include "palcas_core/common/road_snapshot.h"
#include "palcas_core/learning/nn/types.h"
#include "palcas_core/learning/pdqn_agent.h"
#include "palcas_core/metrics/vehicle_event.h"
#include "palcas_core/reward/terminal_rewards.h"

namespace palcas::rsu {

/// Ids of vehicles that something happened to since the previous decide() call (from
/// palcas_msgs/VehicleEvent). Ids that this RSU does not know are ignored.
struct VehicleOutcomes {
  std::vector<std::string> collided;     ///< COLLISION: removed; terminal with penalty
  std::vector<std::string> teleported;   ///< TELEPORT: removed; terminal with penalty
  std::vector<std::string> arrived;      ///< ARRIVED: left at its route's end; terminal
  std::vector<std::string> exited;       ///< EXIT_OK: on its own off-ramp; terminal
  std::vector<std::string> exit_missed;  ///< EXIT_MISSED: still on the road
  std::vector<std::string> merge_failed; ///< MERGE_FAILED: penalised, not terminal

  /// Files `id` under the list of `kind`; DEPARTED, MERGE_OK and MERGE_FAILED are ignored
  /// (they end nothing). Never throws except std::bad_alloc.
  void add(metrics::VehicleEventKind kind, const std::string& id);
  void clear();
};

/// One decision's events as sets, looked up by id.
struct EventSets {
  explicit EventSets(const VehicleOutcomes& outcomes);
  /// Gone even if the snapshot still lists them (SUMO removes them this step): collided,
  /// teleported, arrived, exited.
  std::set<std::string> removed;
  std::set<std::string> collided;  ///< collided or teleported: the collision penalty
  std::set<std::string> exited, exit_missed, merge_failed;
};

/// A member's last decision, waiting for its outcome.
struct PendingDecision {
  nn::Vector state;
  ActionMask valid_actions = ALL_ACTIONS;  ///< in `state`: s' of a transition ending there
  Decision decision;
  double reward = 0.0;              ///< reward at that observation (for terminal transitions)
  double distance_to_exit_m = 0.0;  ///< at the decision; finite = its exit was ahead
  double cost = 0.0;                ///< subtracted from the transition's reward, however it closes
                                    ///< (RsuControllerOptions::lane_change_cost)
  double period_reward_sum = 0.0;   ///< rewards of the steps since (reward_over_period)
  int period_steps = 0;

  /// The reward the transition gets: the period mean including `now` when `over_period`,
  /// else `now`.
  double periodReward(double now, bool over_period) const {
    return over_period ? (period_reward_sum + now) / (period_steps + 1) : now;
  }
  /// Mean reward since the decision, or the decision's own when no step was seen.
  double lastReward() const { return period_steps > 0 ? period_reward_sum / period_steps : reward; }
};

/// One transition to store: (pending s, a) -> (reward, s', done).
struct Closure {
  std::string id;
  nn::Vector next_state;
  ActionMask next_valid_actions = ALL_ACTIONS;  ///< possible actions of the CAV in s'
  double reward = 0.0;
  bool done = false;
};

/// A pending CAV still on the road as the controller sees it now: its state, the actions
/// possible there and its reward at this decision (this zone's statistics).
struct StateNow {
  nn::Vector state;
  ActionMask valid_actions = ALL_ACTIONS;
  double reward = 0.0;
};

/// The vehicles of one snapshot by id.
using RoadIndex = std::unordered_map<std::string, const VehicleSnapshot*>;
/// The members of one decision by id: their column in the decision's state matrix.
using MemberColumns = std::unordered_map<std::string, size_t>;

/// The pending CAVs sorted by what became of them at this decision, each list in id order.
struct PendingFates {
  std::vector<std::string> removed;       ///< named by a removal event (listed or not)
  std::vector<std::string> members;       ///< still members
  std::vector<std::string> exit_taken;    ///< on an off-ramp
  std::vector<std::string> outside_zone;  ///< on the road elsewhere (handed over, mostly)
  std::vector<std::string> vanished;      ///< gone without an event: to limbo
};

/// What closePending() closes: the transitions in id order, and the ids going to limbo.
struct Closings {
  std::vector<Closure> closures;
  std::vector<std::string> vanished;
};

/// The pending decisions (one per member of the last decision) and the limbo (vanished
/// CAVs of the last decision). Ordered by id: transitions are stored in id order, so the
/// replay does not depend on hash order. Not thread-safe.
class TransitionBook {
 public:
  /// Where each pending CAV went (the limbo is closed regardless, see close()). `road`:
  /// this snapshot's vehicles; `members`: this decision's members; `events`: this
  /// decision's. Never throws except std::bad_alloc.
  PendingFates sort(const RoadIndex& road, const MemberColumns& members,
                    const EventSets& events) const;

  /// Closes the limbo and every pending transition by `fates` (from sort() on the same
  /// road). `now` must hold the state of every member and outside-zone CAV of `fates`
  /// (std::invalid_argument naming the id otherwise). Reward and done per
  /// src/doc/rsu.md: members and CAVs outside the zone continue (s' = their state now,
  /// period reward, done = false unless it is no longer an eligible CAV) with the
  /// on-the-road outcomes (merge failed, exit missed); the others end with s' = s and the
  /// reward since the decision with the off-the-road outcomes (reward/terminal_rewards.h).
  Closings close(const PendingFates& fates, const RoadIndex& road,
                 const std::unordered_map<std::string, StateNow>& now, const EventSets& events,
                 const TerminalRewards& terminal, bool over_period) const;

  /// The pending decision or, for a CAV in limbo, its limbo entry (a closure's s, a).
  /// Throws std::out_of_range naming the id when neither holds it.
  const PendingDecision& decisionOf(const std::string& id) const;

  /// After the closures are stored: the limbo becomes `vanished` (pending ids), and the
  /// pending decisions become `decided` (the members of this decision). Throws
  /// std::invalid_argument naming a vanished id that is not pending (nothing changed).
  void advance(const std::vector<std::string>& vanished,
               std::map<std::string, PendingDecision> decided);

  /// Adds one bridge step's reward to a pending CAV's period (reward_over_period); ids not
  /// pending are ignored. Throws std::invalid_argument naming the id on a non-finite reward.
  void addStepReward(const std::string& id, double reward);

  /// Drops pending and limbo; returns how many were dropped.
  size_t dropAll();
  /// Drops the pending decisions only (the limbo stays: loadCheckpoint's behaviour before
  /// the book existed, kept bit for bit).
  void dropPending() { pending_.clear(); }

  size_t pendingCount() const { return pending_.size(); }
  bool isPending(const std::string& id) const { return pending_.count(id) > 0; }
  bool empty() const { return pending_.empty(); }

 private:
  std::map<std::string, PendingDecision> pending_;
  std::map<std::string, PendingDecision> limbo_;
};

}  // namespace palcas::rsu
