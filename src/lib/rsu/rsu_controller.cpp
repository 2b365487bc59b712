// RsuController: options, membership, decisions, transitions and gradient steps.
// Checkpoints and federation: rsu_controller_io.cpp. Reasons: src/doc/rsu.md.
#include "palcas_core/rsu/rsu_controller.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "palcas_core/common/checks.h"
#include "palcas_core/state/neighbours.h"

namespace palcas::rsu {

namespace {

template <typename T>
void require(bool ok, const std::string& field, T value, const std::string& rule) {
  common::require(ok, "RsuControllerOptions: ", field, " = ", value, " ", rule);
}

// Runs a nested validator and prefixes its message with the nested struct's name.
template <typename F>
void nested(const std::string& prefix, F&& check) {
  try {
    check();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("RsuControllerOptions: " + prefix + ": " + e.what());
  }
}

// Tolerance of the gradient credit: 10 x 0.1 adds up to 0.99999999999999989.
constexpr double CREDIT_EPSILON = 1e-9;

}  // namespace

void RsuControllerOptions::validate() const {
  require(!rsu_id.empty(), "rsu_id", "''", "must not be empty");
  require(cluster_index >= 0, "cluster_index", cluster_index, "must be >= 0");
  require(std::isfinite(x_start_m), "x_start_m", x_start_m, "must be finite");
  require(std::isfinite(x_end_m) && x_end_m > x_start_m, "x_end_m", x_end_m,
          "must be finite and > x_start_m = " + std::to_string(x_start_m));
  require(num_lanes >= 1, "num_lanes", num_lanes, "must be >= 1");
  require(std::isfinite(gradient_steps_per_decision) && gradient_steps_per_decision >= 0.0,
          "gradient_steps_per_decision", gradient_steps_per_decision, "must be finite and >= 0");
  nested("terminal", [&] { validateTerminalRewards(terminal); });
  nested("reward", [&] { validateRewardParams(reward); });
  nested("scales", [&] { validateScales(scales); });
  nested("pdqn", [&] { pdqn.validate(); });
  const int needed = StateLayout(num_lanes).size();
  require(pdqn.state_size == needed, "pdqn.state_size", pdqn.state_size,
          "must be " + std::to_string(LANE_INDEPENDENT_FEATURE_COUNT) +
              " + num_lanes = " + std::to_string(needed));
}

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

/// One transition to store: (pending s, a) -> (reward, s', done).
struct Closure {
  std::string id;
  nn::Vector next_state;
  ActionMask next_valid_actions = ALL_ACTIONS;  ///< possibleActions of the CAV in s'
  double reward = 0.0;
  bool done = false;
};

struct RsuController::Observation {
  ClusterSummary cluster;
  std::vector<std::string> member_ids;
  std::vector<int> member_lanes;       // paper lane of each member (0 = acceleration lane)
  nn::Matrix member_states;            // state_size x members
  std::vector<double> member_rewards;  // train mode only
  std::vector<Closure> closures;       // train mode only, ordered by id
  std::vector<std::string> vanished;   // pending CAVs gone without an event (to limbo)
  std::vector<double> member_exit_m;   // distance to exit of each member (train mode)
};

namespace {

const RsuControllerOptions& validated(const RsuControllerOptions& options) {
  options.validate();
  return options;
}

}  // namespace

RsuController::RsuController(const RsuControllerOptions& options)
    : options_(validated(options)),
      builder_(options.num_lanes, options.scales),
      agent_(options.pdqn) {}

bool RsuController::isMember(const VehicleSnapshot& v) const {
  // Zone [x_start, x_end); ramp / off-ramp vehicles (lane 0, not on the acceleration lane)
  // cannot take lane-change advisories, so they are not members; nor is a CAV driving
  // itself (the bridge's guard drops its advice while its zone is busy).
  return v.is_cav && !v.driving_itself && v.x_m >= options_.x_start_m && v.x_m < options_.x_end_m &&
         (v.lane >= 1 || v.on_accel_lane);
}

bool RsuController::federationDue() const {
  const uint64_t steps = agent_.gradientSteps();
  return options_.federation_interval_steps > 0 && steps >= grad_steps_at_round_ &&
         steps - grad_steps_at_round_ >= options_.federation_interval_steps;
}

namespace {

// The paper's per-CAV reward iota r_e + zeta r_s + xi r_c + lambda r_lc + psi r_d
// (paper "Reward Function") of every id, in order.
std::vector<double> rewardsOf(const NeighbourFinder& finder, const std::vector<std::string>& ids,
                              const ClusterStats& cluster, const RewardParams& params) {
  std::vector<double> out;
  out.reserve(ids.size());
  for (const std::string& id : ids) {
    double r = 0.0;
    try {
      r = computeReward(situationFromSnapshot(finder, id, cluster), params).total;
    } catch (const std::invalid_argument& e) {  // name the vehicle, not just the key
      throw std::invalid_argument("vehicle '" + id + "': " + e.what());
    }
    if (!std::isfinite(r))
      throw std::invalid_argument("reward of vehicle '" + id + "' is not finite");
    out.push_back(r);
  }
  return out;
}

}  // namespace

RsuController::Observation RsuController::observe(const RoadSnapshot& snapshot,
                                                  const GlobalDensities& global,
                                                  const VehicleOutcomes& outcomes) const {
  const NeighbourFinder finder(snapshot);  // validates every vehicle, names the bad one
  Observation obs;
  obs.cluster = computeClusterSummary(snapshot, options_.x_start_m, options_.x_end_m,
                                      options_.reward.v_bar_max);
  const ClusterStats stats = obs.cluster.toClusterStats();

  // Vehicles named by a removal event are gone even if this snapshot still lists them.
  std::set<std::string> removed, penalised;
  for (const auto* list : {&outcomes.collided, &outcomes.teleported}) {
    removed.insert(list->begin(), list->end());
    penalised.insert(list->begin(), list->end());
  }
  for (const auto* list : {&outcomes.arrived, &outcomes.exited})
    removed.insert(list->begin(), list->end());

  std::unordered_map<std::string, const VehicleSnapshot*> on_road;
  for (const VehicleSnapshot& v : snapshot.vehicles) {
    on_road.emplace(v.id, &v);
    if (isMember(v) && removed.count(v.id) == 0) {
      obs.member_ids.push_back(v.id);
      obs.member_lanes.push_back(v.lane);
      obs.member_exit_m.push_back(v.distance_to_exit_m);
    }
  }
  if (!obs.member_ids.empty())
    obs.member_states = builder_.buildStates(finder, obs.member_ids, stats, global);
  if (!options_.train) return obs;
  obs.member_rewards = rewardsOf(finder, obs.member_ids, stats, options_.reward);

  std::unordered_map<std::string, int> member_column;
  for (size_t i = 0; i < obs.member_ids.size(); ++i)
    member_column.emplace(obs.member_ids[i], static_cast<int>(i));
  const std::set<std::string> exited(outcomes.exited.begin(), outcomes.exited.end());
  const std::set<std::string> missed(outcomes.exit_missed.begin(), outcomes.exit_missed.end());
  const std::set<std::string> merge_failed(outcomes.merge_failed.begin(), outcomes.merge_failed.end());
  const bool over_period = options_.reward_over_period;

  // Terminal outcomes read from the road itself, so a transition does not depend on
  // whether the event of the same step arrived before the states (separate topics).
  auto passedExit = [&](const Pending& p, const VehicleSnapshot& v) {
    return missed.count(v.id) > 0 ||
           (std::isfinite(p.distance_to_exit_m) && std::isinf(v.distance_to_exit_m) && v.lane >= 1);
  };
  auto onOffRamp = [](const VehicleSnapshot& v) { return v.lane == 0 && !v.on_accel_lane; };
  auto applyOutcomePenalties = [&](Closure& c, const Pending& p, const VehicleSnapshot& v) {
    TransitionOutcome o;
    o.merge_failed = merge_failed.count(c.id) > 0;
    o.exit_missed = passedExit(p, v);
    const TransitionReward r = stillOnTheRoad(c.reward, c.done, o, options_.terminal);
    c.reward = r.reward;
    c.done = r.done;
  };
  // Closes a pending CAV that left the road: collision / teleport pay, an exit earns.
  // Terminal: s' = s, so the mask is that of s (done zeroes the bootstrap; the mask of s'
  // anyway keeps every target what it was when the agent decoded it, bit for bit).
  auto closeRemoved = [&](const std::string& id, const Pending& p) {
    TransitionOutcome o;
    o.collided = penalised.count(id) > 0;
    o.exit_taken = exited.count(id) > 0;
    o.merge_failed = merge_failed.count(id) > 0;
    const TransitionReward r = leftTheRoad(p.lastReward(), o, options_.terminal);
    return Closure{id, p.state, p.valid_actions, r.reward, r.done};
  };

  // Last decision's vanished CAVs: their events have arrived by now.
  for (const auto& [id, p] : limbo_) obs.closures.push_back(closeRemoved(id, p));

  std::vector<std::string> elsewhere;  // pending CAVs on the road but not members now
  for (const auto& [id, pending] : pending_) {
    const auto member = member_column.find(id);
    const auto road = on_road.find(id);
    if (removed.count(id) > 0) {
      obs.closures.push_back(closeRemoved(id, pending));
    } else if (member != member_column.end()) {
      const size_t col = static_cast<size_t>(member->second);
      Closure c{id, obs.member_states.col(member->second),
                possibleActions(obs.member_lanes[col], options_.num_lanes),
                pending.periodReward(obs.member_rewards[col], over_period), false};
      applyOutcomePenalties(c, pending, *road->second);
      obs.closures.push_back(std::move(c));
    } else if (road != on_road.end() && onOffRamp(*road->second)) {
      // On an off-ramp: a controlled CAV only ever leaves by its own (the bridge commits
      // the exit from lane 1), so this is the exit taken.
      TransitionOutcome exit;
      exit.exit_taken = true;
      const TransitionReward r = leftTheRoad(pending.lastReward(), exit, options_.terminal);
      obs.closures.push_back(Closure{id, pending.state, pending.valid_actions, r.reward, r.done});
    } else if (road != on_road.end()) {
      elsewhere.push_back(id);  // filled below in one batch
    } else {
      obs.vanished.push_back(id);  // no event yet: closed at the next decision
    }
  }
  if (!elsewhere.empty()) {
    // Handed over (eligible, outside the zone): the value continues under the next RSU,
    // which shares the federated model -> done = false. Reward and s' use this cluster's
    // statistics.
    const nn::Matrix states = builder_.buildStates(finder, elsewhere, stats, global);
    const std::vector<double> rewards = rewardsOf(finder, elsewhere, stats, options_.reward);
    for (size_t i = 0; i < elsewhere.size(); ++i) {
      const VehicleSnapshot& v = *on_road.at(elsewhere[i]);
      const Pending& p = pending_.at(elsewhere[i]);
      const bool handed_over = v.is_cav && (v.lane >= 1 || v.on_accel_lane);
      Closure c{elsewhere[i], states.col(static_cast<nn::Index>(i)),
                possibleActions(v.lane, options_.num_lanes),
                p.periodReward(rewards[i], over_period), !handed_over};
      applyOutcomePenalties(c, p, v);
      obs.closures.push_back(std::move(c));
    }
  }
  // Keep the id order so the replay order does not depend on the case mix.
  std::sort(obs.closures.begin(), obs.closures.end(),
            [](const Closure& a, const Closure& b) { return a.id < b.id; });
  return obs;
}

ActionMask possibleActions(int lane, int num_lanes) {
  ActionMask possible = ALL_ACTIONS;
  if (lane >= num_lanes) possible &= ~actionBit(Action::kLaneLeft);
  if (lane <= 1) possible &= ~actionBit(Action::kLaneRight);
  return possible;
}

Decision maskImpossibleLaneChange(Decision decision, int lane, int num_lanes) {
  if ((possibleActions(lane, num_lanes) & actionBit(decision.action)) == 0)
    decision.action = Action::kKeep;
  return decision;
}

DecisionOutput RsuController::decide(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                                     const GlobalDensities& global,
                                     const VehicleOutcomes& outcomes) {
  DecisionOutput out = advise(snapshot, step, time_s, global, outcomes);
  learn();
  return out;
}

void RsuController::learn() {
  if (options_.train) runGradientSteps();
}

DecisionOutput RsuController::advise(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                                     const GlobalDensities& global,
                                     const VehicleOutcomes& outcomes) {
  if (!std::isfinite(time_s) || time_s < 0.0)
    throw std::invalid_argument("RsuController::advise: time_s = " + std::to_string(time_s) +
                                " must be finite and >= 0");
  if (snapshot.num_lanes != options_.num_lanes)
    throw std::invalid_argument("RsuController::decide: snapshot num_lanes = " +
                                std::to_string(snapshot.num_lanes) + ", this RSU has " +
                                std::to_string(options_.num_lanes));
  Observation obs = observe(snapshot, global, outcomes);  // may throw; nothing changed

  // ---- commit: nothing below throws on validated input ----
  if (have_last_step_ && step <= last_step_) {  // the bridge restarted: a new episode
    endEpisode();
    obs.closures.clear();
    obs.vanished.clear();
  }
  have_last_step_ = true;
  last_step_ = step;

  DecisionOutput out;
  out.step = step;
  out.time_s = time_s;
  out.model_version = model_version_;
  out.cluster = obs.cluster;
  std::vector<Decision> decisions;
  if (!obs.member_ids.empty()) agent_.act(obs.member_states, options_.train, decisions);
  for (size_t i = 0; i < decisions.size(); ++i)
    decisions[i] = maskImpossibleLaneChange(decisions[i], obs.member_lanes[i], options_.num_lanes);

  stats_.decisions++;
  stats_.member_count = static_cast<uint32_t>(obs.member_ids.size());
  stats_.action_counts.fill(0);
  out.advisories.reserve(decisions.size());
  for (size_t i = 0; i < decisions.size(); ++i) {
    out.advisories.push_back(CavAdvisory{obs.member_ids[i], decisions[i]});
    stats_.action_counts[static_cast<size_t>(decisions[i].action)]++;
  }
  if (options_.train) {
    closePending(obs);
    limbo_.clear();
    for (const std::string& id : obs.vanished) limbo_[id] = pending_.at(id);
    pending_.clear();
    for (size_t i = 0; i < decisions.size(); ++i) {
      Pending p;
      p.state = obs.member_states.col(static_cast<nn::Index>(i));
      p.valid_actions = possibleActions(obs.member_lanes[i], options_.num_lanes);
      p.decision = decisions[i];
      p.reward = obs.member_rewards[i];
      p.distance_to_exit_m = obs.member_exit_m[i];
      pending_[obs.member_ids[i]] = std::move(p);
    }
  }
  return out;
}

void RsuController::closePending(const Observation& obs) {
  double sum = 0.0;
  for (const Closure& c : obs.closures) {
    const auto in_limbo = limbo_.find(c.id);
    const Pending& p = in_limbo != limbo_.end() ? in_limbo->second : pending_.at(c.id);
    agent_.remember(p.state, p.decision, static_cast<float>(c.reward), c.next_state,
                    c.next_valid_actions, c.done);
    sum += c.reward;
  }
  // R_k = sum over the CAVs of the per-CAV reward (paper "Reward Function").
  stats_.transitions_closed = static_cast<uint32_t>(obs.closures.size());
  stats_.sum_reward = sum;
  stats_.mean_reward = obs.closures.empty() ? std::nan("") : sum / obs.closures.size();
  stats_.transitions_stored += obs.closures.size();
  samples_since_federation_ += obs.closures.size();
}

void RsuController::runGradientSteps() {
  // Credit is earned only while the replay holds a batch, so a long warm-up does not
  // turn into a burst of updates later.
  if (!agent_.canUpdate()) return;
  gradient_credit_ += options_.gradient_steps_per_decision;
  while (gradient_credit_ >= 1.0 - CREDIT_EPSILON) {
    const UpdateStats u = agent_.update();
    stats_.q_loss = u.q_loss;
    stats_.param_loss = u.param_loss;
    gradient_credit_ -= 1.0;
  }
  if (gradient_credit_ < 0.0) gradient_credit_ = 0.0;  // absorb the tolerance
}

void RsuController::observeStep(const RoadSnapshot& snapshot) {
  if (!options_.train || !options_.reward_over_period || pending_.empty()) return;
  if (snapshot.num_lanes != options_.num_lanes)
    throw std::invalid_argument("RsuController::observeStep: snapshot num_lanes = " +
                                std::to_string(snapshot.num_lanes) + ", this RSU has " +
                                std::to_string(options_.num_lanes));
  const NeighbourFinder finder(snapshot);  // validates; throws before anything changes
  const ClusterStats stats = computeClusterSummary(snapshot, options_.x_start_m, options_.x_end_m,
                                                   options_.reward.v_bar_max)
                                 .toClusterStats();
  std::vector<std::string> ids;
  for (const VehicleSnapshot& v : snapshot.vehicles)
    if (pending_.count(v.id) > 0 && (v.lane >= 1 || v.on_accel_lane)) ids.push_back(v.id);
  const std::vector<double> rewards = rewardsOf(finder, ids, stats, options_.reward);
  for (size_t i = 0; i < ids.size(); ++i) {
    Pending& p = pending_.at(ids[i]);
    p.period_reward_sum += rewards[i];
    p.period_steps++;
  }
}

void RsuController::endEpisode() {
  stats_.pending_dropped += pending_.size() + limbo_.size();
  pending_.clear();
  limbo_.clear();
  have_last_step_ = false;
}

RsuControllerStats RsuController::stats() const {
  RsuControllerStats s = stats_;
  s.epsilon = agent_.epsilon();
  s.gradient_steps = agent_.gradientSteps();
  s.samples_since_federation = samples_since_federation_;
  s.model_version = model_version_;
  s.federation_round = federation_round_;
  return s;
}

}  // namespace palcas::rsu
