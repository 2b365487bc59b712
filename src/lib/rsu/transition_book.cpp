// TransitionBook: which way each pending transition closes, and with what. Reasons:
// src/doc/rsu.md ("Closing a pending transition").
#include "palcas_core/rsu/transition_book.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "palcas_core/common/checks.h"

namespace palcas::rsu {

void VehicleOutcomes::add(metrics::VehicleEventKind kind, const std::string& id) {
  using K = metrics::VehicleEventKind;
  switch (kind) {
    case K::kCollision: collided.push_back(id); break;
    case K::kTeleport: teleported.push_back(id); break;
    case K::kArrived: arrived.push_back(id); break;
    case K::kExitOk: exited.push_back(id); break;
    case K::kExitMissed: exit_missed.push_back(id); break;
    case K::kMergeFailed: merge_failed.push_back(id); break;
    default: break;  // departed / merge-ok events end nothing
  }
}

void VehicleOutcomes::clear() {
  collided.clear();
  teleported.clear();
  arrived.clear();
  exited.clear();
  exit_missed.clear();
  merge_failed.clear();
}

EventSets::EventSets(const VehicleOutcomes& outcomes)
    : exited(outcomes.exited.begin(), outcomes.exited.end()),
      exit_missed(outcomes.exit_missed.begin(), outcomes.exit_missed.end()),
      merge_failed(outcomes.merge_failed.begin(), outcomes.merge_failed.end()) {
  for (const auto* list : {&outcomes.collided, &outcomes.teleported}) {
    removed.insert(list->begin(), list->end());
    collided.insert(list->begin(), list->end());
  }
  for (const auto* list : {&outcomes.arrived, &outcomes.exited})
    removed.insert(list->begin(), list->end());
}

PendingFates TransitionBook::sort(const RoadIndex& road, const MemberColumns& members,
                                  const EventSets& events) const {
  PendingFates fates;
  for (const auto& entry : pending_) {
    const std::string& id = entry.first;
    const auto on_road = road.find(id);
    if (events.removed.count(id) > 0) {
      fates.removed.push_back(id);
    } else if (members.count(id) > 0) {
      fates.members.push_back(id);
    } else if (on_road != road.end() && on_road->second->lane == 0 &&
               !on_road->second->on_accel_lane) {
      // On an off-ramp: a controlled CAV only ever leaves by its own (the bridge commits
      // the exit from lane 1), so this is the exit taken.
      fates.exit_taken.push_back(id);
    } else if (on_road != road.end()) {
      fates.outside_zone.push_back(id);
    } else {
      fates.vanished.push_back(id);  // no event yet: closed at the next decision
    }
  }
  return fates;
}

namespace {

// Terminal: s' = s, so the mask is that of s (done zeroes the bootstrap; the mask of s'
// anyway keeps every target what it was when the agent decoded it, bit for bit).
Closure leftTheRoad(const std::string& id, const PendingDecision& p,
                    const TransitionOutcome& outcome, const TerminalRewards& terminal) {
  const TransitionReward r = palcas::leftTheRoad(p.lastReward(), outcome, terminal);
  return Closure{id, p.state, p.valid_actions, r.reward - p.cost, r.done};
}

// A CAV removed by an event (now or, from the limbo, since the last decision): collision /
// teleport pay, an exit earns.
TransitionOutcome removedOutcome(const std::string& id, const EventSets& events) {
  TransitionOutcome o;
  o.collided = events.collided.count(id) > 0;
  o.exit_taken = events.exited.count(id) > 0;
  o.merge_failed = events.merge_failed.count(id) > 0;
  return o;
}

// Terminal outcomes read from the road itself, so a transition does not depend on whether
// the event of the same step arrived before the states (separate topics).
TransitionOutcome onRoadOutcome(const PendingDecision& p, const VehicleSnapshot& v,
                                const EventSets& events) {
  TransitionOutcome o;
  o.merge_failed = events.merge_failed.count(v.id) > 0;
  o.exit_missed = events.exit_missed.count(v.id) > 0 ||
                  (std::isfinite(p.distance_to_exit_m) && std::isinf(v.distance_to_exit_m) &&
                   v.lane >= 1);
  return o;
}

const StateNow& stateNowOf(const std::unordered_map<std::string, StateNow>& now,
                           const std::string& id) {
  const auto it = now.find(id);
  common::require(it != now.end(), "TransitionBook::close: no state now of pending CAV '", id, "'");
  return it->second;
}

}  // namespace

Closings TransitionBook::close(const PendingFates& fates, const RoadIndex& road,
                               const std::unordered_map<std::string, StateNow>& now,
                               const EventSets& events, const TerminalRewards& terminal,
                               bool over_period) const {
  Closings out;
  // A CAV on the road continues: s' = its state now, the period's reward; done only when
  // it is no longer a CAV on a lane the RSUs advise, or by its outcome.
  const auto stillOnTheRoad = [&](const std::string& id, bool done) {
    const PendingDecision& p = pending_.at(id);
    const VehicleSnapshot& v = *road.at(id);
    const StateNow& s = stateNowOf(now, id);
    const TransitionReward r = palcas::stillOnTheRoad(p.periodReward(s.reward, over_period), done,
                                                      onRoadOutcome(p, v, events), terminal);
    out.closures.push_back(Closure{id, s.state, s.valid_actions, r.reward - p.cost, r.done});
  };
  // Last decision's vanished CAVs: their events have arrived by now.
  for (const auto& [id, p] : limbo_)
    out.closures.push_back(leftTheRoad(id, p, removedOutcome(id, events), terminal));
  for (const std::string& id : fates.removed)
    out.closures.push_back(leftTheRoad(id, pending_.at(id), removedOutcome(id, events), terminal));
  for (const std::string& id : fates.exit_taken) {
    TransitionOutcome exit;  // a MERGE_FAILED of the same period is not charged here
    exit.exit_taken = true;
    out.closures.push_back(leftTheRoad(id, pending_.at(id), exit, terminal));
  }
  for (const std::string& id : fates.members) stillOnTheRoad(id, false);
  for (const std::string& id : fates.outside_zone) {
    // Handed over (eligible, outside the zone): the value continues under the next RSU,
    // which shares the federated model -> done = false.
    const VehicleSnapshot& v = *road.at(id);
    const bool handed_over = v.is_cav && (v.lane >= 1 || v.on_accel_lane);
    stillOnTheRoad(id, !handed_over);
  }
  // Keep the id order so the replay order does not depend on the case mix.
  std::sort(out.closures.begin(), out.closures.end(),
            [](const Closure& a, const Closure& b) { return a.id < b.id; });
  out.vanished = fates.vanished;
  return out;
}

const PendingDecision& TransitionBook::decisionOf(const std::string& id) const {
  const auto in_limbo = limbo_.find(id);
  if (in_limbo != limbo_.end()) return in_limbo->second;
  const auto pending = pending_.find(id);
  if (pending == pending_.end())
    throw std::out_of_range("TransitionBook: no pending decision of '" + id + "'");
  return pending->second;
}

void TransitionBook::advance(const std::vector<std::string>& vanished,
                             std::map<std::string, PendingDecision> decided) {
  std::map<std::string, PendingDecision> limbo;
  for (const std::string& id : vanished) {
    const auto it = pending_.find(id);
    if (it == pending_.end())
      throw std::invalid_argument("TransitionBook::advance: vanished '" + id + "' is not pending");
    limbo[id] = it->second;
  }
  limbo_ = std::move(limbo);
  pending_ = std::move(decided);
}

void TransitionBook::addStepReward(const std::string& id, double reward) {
  common::require(std::isfinite(reward), "TransitionBook::addStepReward: reward of '", id,
                  "' = ", reward, " must be finite");
  const auto it = pending_.find(id);
  if (it == pending_.end()) return;
  it->second.period_reward_sum += reward;
  it->second.period_steps++;
}

size_t TransitionBook::dropAll() {
  const size_t dropped = pending_.size() + limbo_.size();
  pending_.clear();
  limbo_.clear();
  return dropped;
}

}  // namespace palcas::rsu
