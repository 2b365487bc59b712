// RsuController: options, membership, decisions, the states and rewards of the transitions
// its TransitionBook closes (transition_book.cpp), storing them, gradient steps.
// Checkpoints and federation: rsu_controller_io.cpp. Reasons: src/doc/rsu.md.
#include "palcas_core/rsu/rsu_controller.h"

#include <cmath>
#include <map>
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

void requireTime(double time_s, const char* call) {
  if (!std::isfinite(time_s) || time_s < 0.0)
    throw std::invalid_argument(std::string("RsuController::") + call + ": time_s = " + std::to_string(time_s) +
                                " must be finite and >= 0");
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
  require(advice_source == AdviceSource::kNetwork || !train, "train", "true",
          "is not possible with advice_source rules (a rule learns nothing)");
  require(advice_source == AdviceSource::kNetwork || !rule_residual, "rule_residual", "true",
          "needs advice_source network (the rule alone departs from nothing)");
  require(std::isfinite(residual_margin) && residual_margin >= 0.0, "residual_margin", residual_margin,
          "must be finite and >= 0");
  require(std::isfinite(no_left_for_exit_within_m) && no_left_for_exit_within_m >= 0.0, "no_left_for_exit_within_m",
          no_left_for_exit_within_m, "must be finite and >= 0 (0 = off)");
  require(std::isfinite(lane_change_dwell_s) && lane_change_dwell_s >= 0.0, "lane_change_dwell_s",
          lane_change_dwell_s, "must be finite and >= 0 (0 = off)");
  require(std::isfinite(exit_rule_below_density_veh_per_km) && exit_rule_below_density_veh_per_km >= 0.0,
          "exit_rule_below_density_veh_per_km", exit_rule_below_density_veh_per_km,
          "must be finite and >= 0 (0 = at any density)");
  require(std::isfinite(exit_rule_density_window_s) && exit_rule_density_window_s >= 0.0,
          "exit_rule_density_window_s", exit_rule_density_window_s, "must be finite and >= 0 (0 = no window)");
  require(exit_rule_density_window_s == 0.0 || exit_rule_below_density_veh_per_km > 0.0,
          "exit_rule_density_window_s", exit_rule_density_window_s,
          "needs exit_rule_below_density_veh_per_km > 0 (a window of a density no limit reads does nothing)");
  require(std::isfinite(exit_rule_below_inflow_veh_per_h_per_lane) && exit_rule_below_inflow_veh_per_h_per_lane >= 0.0,
          "exit_rule_below_inflow_veh_per_h_per_lane", exit_rule_below_inflow_veh_per_h_per_lane,
          "must be finite and >= 0 (0 = any inflow)");
  require(std::isfinite(exit_rule_inflow_window_s) && exit_rule_inflow_window_s > 0.0, "exit_rule_inflow_window_s",
          exit_rule_inflow_window_s, "must be finite and > 0");
  require(std::isfinite(lane_change_cost) && lane_change_cost >= 0.0, "lane_change_cost", lane_change_cost,
          "must be finite and >= 0 (it is subtracted; 0 = off)");
  nested("rules", [&] { rules.validate(); });
  nested("terminal", [&] { validateTerminalRewards(terminal); });
  nested("reward", [&] { validateRewardParams(reward); });
  nested("scales", [&] { validateScales(scales); });
  nested("pdqn", [&] { pdqn.validate(); });
  const int needed = StateLayout(num_lanes).size();
  require(pdqn.state_size == needed, "pdqn.state_size", pdqn.state_size,
          "must be " + std::to_string(LANE_INDEPENDENT_FEATURE_COUNT) +
              " + num_lanes = " + std::to_string(needed));
}

struct RsuController::Observation {
  ClusterSummary cluster;
  std::vector<std::string> member_ids;
  std::vector<int> member_lanes;       // paper lane of each member (0 = acceleration lane)
  std::vector<const VehicleSnapshot*> member_vehicles;  // into the snapshot being advised
  nn::Matrix member_states;            // state_size x members
  std::vector<double> member_rewards;  // train mode only
  std::vector<double> member_exit_m;   // distance to exit of each member (train mode)
  Closings closings;                   // train mode only: closures in id order, to limbo
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
      agent_(options.pdqn) {
  try {
    personal_head_ = agent_.headSpans(options.personal_head_layers);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("RsuControllerOptions: personal_head_layers " +
                                std::to_string(options.personal_head_layers) + ": " + e.what());
  }
}

bool RsuController::isMember(const VehicleSnapshot& v) const {
  // Zone [x_start, x_end); ramp / off-ramp vehicles (lane 0, not on the acceleration lane)
  // cannot take lane-change advisories, so they are not members; nor is a CAV driving
  // itself (the bridge's guard drops its advice while its zone is busy).
  return v.is_cav && !v.driving_itself && v.x_m >= options_.x_start_m && v.x_m < options_.x_end_m &&
         (v.lane >= 1 || v.on_accel_lane);
}

bool RsuController::federationDue() const {
  const uint64_t steps = agent_.gradientSteps();
  return options_.federation_interval_steps > 0 && steps >= counters_.grad_steps_at_round &&
         steps - counters_.grad_steps_at_round >= options_.federation_interval_steps;
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

// s', its valid actions and the reward now of each pending CAV still on the road: the
// members' as decided, the others' (handed over, mostly) in one more batch, all with this
// zone's statistics (src/doc/rsu.md, "whose statistics for a CAV outside the zone").
std::unordered_map<std::string, StateNow> RsuController::statesNow(
    const Observation& obs, const MemberColumns& columns, const PendingFates& fates,
    const RoadIndex& road, const NeighbourFinder& finder, const ClusterStats& stats,
    const GlobalDensities& global, double time_s) const {
  std::unordered_map<std::string, StateNow> now;
  for (const std::string& id : fates.members) {
    const size_t col = columns.at(id);
    now[id] = StateNow{obs.member_states.col(static_cast<nn::Index>(col)),
                       allowedFor(*obs.member_vehicles[col], time_s),
                       obs.member_rewards[col]};
  }
  if (fates.outside_zone.empty()) return now;
  const nn::Matrix states = builder_.buildStates(finder, fates.outside_zone, stats, global);
  const std::vector<double> rewards = rewardsOf(finder, fates.outside_zone, stats, options_.reward);
  for (size_t i = 0; i < fates.outside_zone.size(); ++i) {
    const std::string& id = fates.outside_zone[i];
    now[id] = StateNow{states.col(static_cast<nn::Index>(i)),
                       allowedFor(*road.at(id), time_s), rewards[i]};
  }
  return now;
}

RsuController::Observation RsuController::observe(const RoadSnapshot& snapshot, double time_s,
                                                  const GlobalDensities& global,
                                                  const VehicleOutcomes& outcomes) const {
  const NeighbourFinder finder(snapshot);  // validates every vehicle, names the bad one
  Observation obs;
  obs.cluster = computeClusterSummary(snapshot, options_.x_start_m, options_.x_end_m,
                                      options_.reward.v_bar_max);
  const ClusterStats stats = obs.cluster.toClusterStats();
  const EventSets events(outcomes);
  RoadIndex road;
  for (const VehicleSnapshot& v : snapshot.vehicles) {
    road.emplace(v.id, &v);
    // Vehicles named by a removal event are gone even if this snapshot still lists them.
    if (isMember(v) && events.removed.count(v.id) == 0) {
      obs.member_ids.push_back(v.id);
      obs.member_lanes.push_back(v.lane);
      obs.member_vehicles.push_back(&v);
      obs.member_exit_m.push_back(v.distance_to_exit_m);
    }
  }
  if (!obs.member_ids.empty() && options_.advice_source == AdviceSource::kNetwork)
    obs.member_states = builder_.buildStates(finder, obs.member_ids, stats, global);
  if (!options_.train) return obs;
  obs.member_rewards = rewardsOf(finder, obs.member_ids, stats, options_.reward);

  MemberColumns columns;
  for (size_t i = 0; i < obs.member_ids.size(); ++i) columns.emplace(obs.member_ids[i], i);
  const PendingFates fates = book_.sort(road, columns, events);
  const auto now = statesNow(obs, columns, fates, road, finder, stats, global, time_s);
  obs.closings =
      book_.close(fates, road, now, events, options_.terminal, options_.reward_over_period);
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

ActionMask allowedActions(const VehicleSnapshot& vehicle, int num_lanes, double no_left_for_exit_within_m) {
  ActionMask allowed = possibleActions(vehicle.lane, num_lanes);
  // Not on the acceleration lane (lane 0): there a left change is the merge itself.
  if (no_left_for_exit_within_m > 0.0 && vehicle.lane >= 1 && std::isfinite(vehicle.distance_to_exit_m) &&
      vehicle.distance_to_exit_m < no_left_for_exit_within_m)
    allowed &= ~actionBit(Action::kLaneLeft);
  return allowed;
}

bool servesRoute(const VehicleSnapshot& vehicle, Action action) {
  if (action == Action::kLaneLeft) return vehicle.lane < 1;
  if (action == Action::kLaneRight) return std::isfinite(vehicle.distance_to_exit_m);
  return true;
}

ActionMask dwellAllowedActions(const VehicleSnapshot& vehicle, double since_lane_change_s, double dwell_s) {
  if (!(dwell_s > 0.0) || !(since_lane_change_s < dwell_s) || vehicle.lane < 1) return ALL_ACTIONS;
  ActionMask allowed = ALL_ACTIONS;
  for (const Action change : {Action::kLaneLeft, Action::kLaneRight})
    if (!servesRoute(vehicle, change)) allowed &= ~actionBit(change);
  return allowed;
}

ActionMask RsuController::allowedFor(const VehicleSnapshot& vehicle, double time_s) const {
  return allowedActions(vehicle, options_.num_lanes, options_.no_left_for_exit_within_m) &
         dwellAllowedActions(vehicle, sinceLaneChange(vehicle, time_s), options_.lane_change_dwell_s);
}

double RsuController::sinceLaneChange(const VehicleSnapshot& vehicle, double time_s) const {
  constexpr double NEVER = std::numeric_limits<double>::infinity();
  if (options_.lane_change_dwell_s <= 0.0) return NEVER;
  const auto seen = lanes_seen_.find(vehicle.id);
  if (seen == lanes_seen_.end()) return NEVER;
  if (seen->second.lane != vehicle.lane) return 0.0;
  return time_s - seen->second.changed_s;  // +inf when never seen to change
}

void RsuController::rememberLanes(const RoadSnapshot& snapshot, double time_s) {
  if (options_.lane_change_dwell_s <= 0.0) return;
  // Rebuilt from the snapshot, so vehicles that left are forgotten.
  std::unordered_map<std::string, LaneSeen> now;
  now.reserve(snapshot.vehicles.size());
  for (const VehicleSnapshot& v : snapshot.vehicles) {
    LaneSeen& entry = now[v.id] = LaneSeen{v.lane};
    const auto seen = lanes_seen_.find(v.id);
    if (seen != lanes_seen_.end()) entry.changed_s = seen->second.lane != v.lane ? time_s : seen->second.changed_s;
  }
  lanes_seen_ = std::move(now);
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

DecisionView RsuController::preview(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                                    const GlobalDensities& global, const VehicleOutcomes& outcomes) const {
  if (snapshot.num_lanes != options_.num_lanes)
    throw std::invalid_argument("RsuController::preview: snapshot num_lanes = " +
                                std::to_string(snapshot.num_lanes) + ", this RSU has " +
                                std::to_string(options_.num_lanes));
  requireTime(time_s, "preview");
  Observation obs = observe(snapshot, time_s, global, outcomes);
  DecisionView view;
  view.member_ids = std::move(obs.member_ids);
  view.member_lanes = std::move(obs.member_lanes);
  // The rule arm builds no states; an outside learner needs them.
  view.states = obs.member_states.cols() == static_cast<nn::Index>(view.member_ids.size())
                    ? std::move(obs.member_states)
                    : builder_.buildStates(NeighbourFinder(snapshot), view.member_ids,
                                           obs.cluster.toClusterStats(), global);
  // As advise() would: a step not after the previous one starts an episode and closes nothing.
  if (!(have_last_step_ && step <= last_step_)) view.closures = std::move(obs.closings.closures);
  return view;
}

DecisionOutput RsuController::advise(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                                     const GlobalDensities& global,
                                     const VehicleOutcomes& outcomes) {
  return adviseImpl(snapshot, step, time_s, global, outcomes, nullptr);
}

DecisionOutput RsuController::adviseWith(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                                         const GlobalDensities& global, const VehicleOutcomes& outcomes,
                                         const std::vector<Decision>& decisions) {
  return adviseImpl(snapshot, step, time_s, global, outcomes, &decisions);
}

DecisionOutput RsuController::adviseImpl(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                                         const GlobalDensities& global, const VehicleOutcomes& outcomes,
                                         const std::vector<Decision>* given) {
  requireTime(time_s, "advise");
  if (snapshot.num_lanes != options_.num_lanes)
    throw std::invalid_argument("RsuController::decide: snapshot num_lanes = " +
                                std::to_string(snapshot.num_lanes) + ", this RSU has " +
                                std::to_string(options_.num_lanes));
  Observation obs = observe(snapshot, time_s, global, outcomes);  // may throw; nothing changed
  if (given && given->size() != obs.member_ids.size())
    throw std::invalid_argument("RsuController::adviseWith: " + std::to_string(given->size()) +
                                " decisions for " + std::to_string(obs.member_ids.size()) + " members");
  if (given && obs.member_states.cols() != static_cast<nn::Index>(obs.member_ids.size()))
    obs.member_states = builder_.buildStates(NeighbourFinder(snapshot), obs.member_ids,
                                             obs.cluster.toClusterStats(), global);

  // ---- commit: nothing below throws on validated input ----
  if (have_last_step_ && step <= last_step_) {  // the bridge restarted: a new episode
    endEpisode();
    obs.closings = Closings{};
  }
  have_last_step_ = true;
  last_step_ = step;

  DecisionOutput out;
  out.step = step;
  out.time_s = time_s;
  out.model_version = counters_.model_version;
  out.cluster = obs.cluster;
  std::vector<Decision> decisions;
  const auto ruleDecisions = [&] {
    std::vector<Decision> rule;
    rule.reserve(obs.member_vehicles.size());
    for (const VehicleSnapshot* v : obs.member_vehicles)
      rule.push_back(ruleDecision(*v, options_.num_lanes, options_.rules));
    return rule;
  };
  if (given) {
    decisions = *given;  // from outside (adviseWith): neither the rule nor the network is asked
  } else if (options_.advice_source == AdviceSource::kRules) {
    decisions = ruleDecisions();
  } else if (options_.rule_residual && !obs.member_ids.empty()) {
    // The network departs from a default: the rule's advice, or KEEP for every member.
    const std::vector<Decision> defaults =
        options_.residual_default == ResidualDefault::kRule
            ? ruleDecisions()
            : std::vector<Decision>(obs.member_vehicles.size(), Decision{Action::kKeep, 0.0f});
    agent_.actOverDefaults(obs.member_states, options_.train, defaults, static_cast<float>(options_.residual_margin),
                           decisions);
  } else if (!obs.member_ids.empty()) {
    agent_.act(obs.member_states, options_.train, decisions);
  }
  const double lane_density_veh_per_km = obs.cluster.density_veh_per_km / options_.num_lanes;
  // Both gates see every decision, so each keeps its own window whatever the other says.
  const bool exit_rule_acts = options_.exit_rule_override &&
                              (exitRuleLightTraffic(lane_density_veh_per_km, time_s) &
                               exitRuleLowInflow(snapshot, time_s));
  std::vector<ActionMask> allowed(decisions.size());
  for (size_t i = 0; i < decisions.size(); ++i) {
    // The rule advises RIGHT only for an exit-bound CAV's exit, which every mask allows.
    if (exit_rule_acts &&
        ruleDecision(*obs.member_vehicles[i], options_.num_lanes, options_.rules).action == Action::kLaneRight)
      decisions[i] = Decision{Action::kLaneRight, 0.0f};
    allowed[i] = allowedFor(*obs.member_vehicles[i], time_s);
    if ((allowed[i] & actionBit(decisions[i].action)) == 0) decisions[i].action = Action::kKeep;
  }
  rememberLanes(snapshot, time_s);

  counters_.decisions++;
  stats_.member_count = static_cast<uint32_t>(obs.member_ids.size());
  stats_.action_counts.fill(0);
  out.advisories.reserve(decisions.size());
  for (size_t i = 0; i < decisions.size(); ++i) {
    out.advisories.push_back(CavAdvisory{obs.member_ids[i], decisions[i]});
    stats_.action_counts[static_cast<size_t>(decisions[i].action)]++;
  }
  if (options_.train) {
    storeClosures(obs.closings.closures);
    std::map<std::string, PendingDecision> decided;
    for (size_t i = 0; i < decisions.size(); ++i) {
      PendingDecision& p = decided[obs.member_ids[i]];
      p.state = obs.member_states.col(static_cast<nn::Index>(i));
      p.valid_actions = allowed[i];
      p.decision = decisions[i];
      p.reward = obs.member_rewards[i];
      p.distance_to_exit_m = obs.member_exit_m[i];
      p.cost = servesRoute(*obs.member_vehicles[i], decisions[i].action) ? 0.0 : options_.lane_change_cost;
    }
    book_.advance(obs.closings.vanished, std::move(decided));
  }
  return out;
}

void RsuController::storeClosures(const std::vector<Closure>& closures) {
  double sum = 0.0;
  for (const Closure& c : closures) {
    const PendingDecision& p = book_.decisionOf(c.id);
    agent_.remember(p.state, p.decision, static_cast<float>(c.reward), c.next_state,
                    c.next_valid_actions, c.done);
    sum += c.reward;
  }
  // R_k = sum over the CAVs of the per-CAV reward (paper "Reward Function").
  stats_.transitions_closed = static_cast<uint32_t>(closures.size());
  stats_.sum_reward = sum;
  stats_.mean_reward = closures.empty() ? std::nan("") : sum / closures.size();
  counters_.transitions_stored += closures.size();
  counters_.samples_since_federation += closures.size();
}

void RsuController::runGradientSteps() {
  // Credit is earned only while the replay holds a batch, so a long warm-up does not
  // turn into a burst of updates later.
  if (!agent_.canUpdate()) return;
  counters_.gradient_credit += options_.gradient_steps_per_decision;
  while (counters_.gradient_credit >= 1.0 - CREDIT_EPSILON) {
    const UpdateStats u = agent_.update();
    stats_.q_loss = u.q_loss;
    stats_.param_loss = u.param_loss;
    counters_.gradient_credit -= 1.0;
  }
  if (counters_.gradient_credit < 0.0) counters_.gradient_credit = 0.0;  // absorb the tolerance
}

void RsuController::observeStep(const RoadSnapshot& snapshot) {
  if (!options_.train || !options_.reward_over_period || book_.empty()) return;
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
    if (book_.isPending(v.id) && (v.lane >= 1 || v.on_accel_lane)) ids.push_back(v.id);
  const std::vector<double> rewards = rewardsOf(finder, ids, stats, options_.reward);
  for (size_t i = 0; i < ids.size(); ++i) book_.addStepReward(ids[i], rewards[i]);
}

void RsuController::endEpisode() {
  stats_.pending_dropped += book_.dropAll();
  have_last_step_ = false;
  lanes_seen_.clear();
  resetDensityWindow();
  resetInflowWindow();
}

void RsuController::resetDensityWindow() {
  density_window_.clear();
  traffic_since_s_ = std::numeric_limits<double>::quiet_NaN();
}

bool RsuController::exitRuleLightTraffic(double lane_density_veh_per_km, double time_s) {
  const double limit = options_.exit_rule_below_density_veh_per_km;
  const double window_s = options_.exit_rule_density_window_s;
  if (limit <= 0.0) return true;
  if (window_s <= 0.0) return lane_density_veh_per_km < limit;
  if (lane_density_veh_per_km <= 0.0) {  // an empty zone: the wait starts again
    resetDensityWindow();
    return false;
  }
  if (std::isnan(traffic_since_s_)) traffic_since_s_ = time_s;
  density_window_.emplace_back(time_s, lane_density_veh_per_km);
  while (time_s - density_window_.front().first > window_s) density_window_.pop_front();
  if (time_s - traffic_since_s_ < window_s) return false;
  double sum = 0.0;
  for (const auto& sample : density_window_) sum += sample.second;
  return sum / static_cast<double>(density_window_.size()) < limit;
}

void RsuController::resetInflowWindow() {
  inflow_members_.clear();
  inflow_window_.clear();
  inflow_since_s_ = std::numeric_limits<double>::quiet_NaN();
}

bool RsuController::exitRuleLowInflow(const RoadSnapshot& snapshot, double time_s) {
  const double limit = options_.exit_rule_below_inflow_veh_per_h_per_lane;
  if (limit <= 0.0) return true;
  const double window_s = options_.exit_rule_inflow_window_s;
  std::unordered_set<std::string> members;
  uint32_t entered = 0;
  for (const VehicleSnapshot& v : snapshot.vehicles) {
    // The zone's mainline lanes, as its density counts them: a ramp vehicle enters on merging.
    if (v.lane < 1 || v.lane > options_.num_lanes || v.x_m < options_.x_start_m || v.x_m >= options_.x_end_m)
      continue;
    members.insert(v.id);
    if (inflow_members_.count(v.id) == 0) ++entered;
  }
  if (members.empty()) {  // an empty zone: the wait starts again
    resetInflowWindow();
    return false;
  }
  // The decision that first sees traffic starts the wait and counts nothing: its vehicles may
  // have arrived at any time before it.
  const bool first = std::isnan(inflow_since_s_);
  if (first) inflow_since_s_ = time_s;
  inflow_members_ = std::move(members);
  if (first) return false;
  inflow_window_.emplace_back(time_s, entered);
  while (time_s - inflow_window_.front().first >= window_s) inflow_window_.pop_front();
  if (time_s - inflow_since_s_ < window_s) return false;
  uint64_t count = 0;
  for (const auto& sample : inflow_window_) count += sample.second;
  const double per_h_per_lane = static_cast<double>(count) * 3600.0 / window_s / options_.num_lanes;
  return per_h_per_lane < limit;
}

RsuControllerStats RsuController::stats() const {
  RsuControllerStats s = stats_;
  s.epsilon = agent_.epsilon();
  s.gradient_steps = agent_.gradientSteps();
  s.decisions = counters_.decisions;
  s.samples_since_federation = counters_.samples_since_federation;
  s.transitions_stored = counters_.transitions_stored;
  s.model_version = counters_.model_version;
  s.federation_round = counters_.federation_round;
  return s;
}

}  // namespace palcas::rsu
