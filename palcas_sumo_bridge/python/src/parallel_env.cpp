#include "parallel_env.h"

#include <ros/time.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <stdexcept>

#include "palcas_sumo_bridge/msg_conversion.h"
#include "palcas_rsu/msg_conversion.h"
#include "palcas_sumo_bridge/run_files.h"

namespace palcas::pyenv {
namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<float> column(const nn::Matrix& m, nn::Index j) {
  std::vector<float> out(static_cast<std::size_t>(m.rows()));
  for (nn::Index i = 0; i < m.rows(); ++i) out[static_cast<std::size_t>(i)] = m(i, j);
  return out;
}

std::vector<float> vectorOf(const nn::Vector& v) { return std::vector<float>(v.data(), v.data() + v.size()); }

std::string agentName(const std::string& rsu_id, const std::string& vehicle_id) { return rsu_id + "/" + vehicle_id; }

}  // namespace

std::pair<std::string, std::string> splitAgent(const std::string& agent) {
  const std::size_t slash = agent.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == agent.size())
    throw std::invalid_argument("agent '" + agent + "' is not '<rsu_id>/<vehicle_id>'");
  return {agent.substr(0, slash), agent.substr(slash + 1)};
}

namespace {
// libsumo holds one simulation per process: a second session would load over the first, and
// the first one's end would close the second's.
const ParallelEnvCore* live_env = nullptr;
}  // namespace

ParallelEnvCore::ParallelEnvCore(const EnvParams& params) {
  if (live_env)
    throw std::runtime_error("palcas_env: another ParallelEnv is open in this process; close() it first "
                             "(libsumo runs one simulation per process)");
  if (!params.tree) throw std::invalid_argument("palcas_env: no parameters");
  bridge_ = bridge::loadBridgeOptions(ros::NodeHandle(params.tree, params.bridge_ns));
  if (bridge_.v2x.enabled)
    throw std::invalid_argument("palcas_env: the V2X channel (v2x/enabled: true) is not supported; every message "
                                "arrives at once and always");
  if (bridge_.gui) throw std::invalid_argument("palcas_env: gui is not supported (SUMO runs in this process)");
  if (bridge_.out_dir.empty()) throw std::invalid_argument("palcas_env: out_dir is empty");
  fs::create_directories(bridge_.out_dir);
  sumocfg_ = bridge::prepareScenario(bridge_);
  runner_ = std::make_unique<sim::EpisodeRunner>(bridge::runnerOptions(bridge_), [this](int episode) {
    return std::make_unique<sim::SumoSession>(bridge::sessionOptionsFor(bridge_, sumocfg_, episode));
  });
  const sim::SumoSession& session = runner_->session();
  rules_ = bridge::measureRules(bridge_, session.road());
  bridge::completeManifest(bridge_, session.sumoVersion(), sim::SumoSession::apiName(), rules_);

  std::vector<double> zones;
  for (const sim::ClusterInfo& c : session.road().clusters()) {
    if (zones.empty()) zones.push_back(c.x_start_m);
    zones.push_back(c.x_end_m);
  }
  const int lanes = session.road().numMainLanes();
  for (const std::string& id : bridge_.expected_rsus) {
    Rsu r;
    try {
      r.options = rsu::loadRsuNodeOptions(ros::NodeHandle(params.tree, "/" + id + "/rsu"));
      if (r.options.controller.rsu_id != id)
        throw std::invalid_argument("rsu/rsu_id is '" + r.options.controller.rsu_id + "', not '" + id + "'");
      if (rsu::takesFromBridgeRoad(r.options)) rsu::adoptBridgeRoad(r.options, zones, lanes);
      else rsu::checkAgainstRoad(r.options, zones, lanes);
      if (r.options.v2x.enabled) throw std::invalid_argument("the V2X channel (v2x/enabled) is not supported");
      if (r.options.controller.advice_source != rsu::AdviceSource::kNetwork)
        throw std::invalid_argument("rsu/advice is not 'network': the caller gives the advice here");
    } catch (const std::exception& e) {
      throw std::invalid_argument("palcas_env: RSU '" + id + "' (parameters under /" + id + "/rsu): " + e.what());
    }
    rsus_.push_back(std::move(r));
  }
  if (!rsus_.empty()) {
    period_ = static_cast<std::uint64_t>(rsus_.front().options.decision_period_steps);
    for (const Rsu& r : rsus_)
      if (static_cast<std::uint64_t>(r.options.decision_period_steps) != period_)
        throw std::invalid_argument("palcas_env: RSUs '" + rsus_.front().options.controller.rsu_id + "' and '" +
                                    r.options.controller.rsu_id +
                                    "' decide at different periods (decision_period_steps); one step() is "
                                    "one decision of every RSU, so they must agree");
  }
  for (const Rsu& r : rsus_) {
    std::string reason;
    if (!runner_->lockstep().registerRsu(r.options.controller.rsu_id, &reason, static_cast<std::uint32_t>(period_)))
      throw std::runtime_error("palcas_env: RSU '" + r.options.controller.rsu_id + "' not registered: " + reason);
  }
  live_env = this;
}

ParallelEnvCore::~ParallelEnvCore() {
  if (live_env == this) live_env = nullptr;
}

int ParallelEnvCore::stateSize() const { return StateLayout(numLanes()).size(); }
int ParallelEnvCore::numLanes() const { return runner_->session().road().numMainLanes(); }

const rsu::RsuNodeOptions& ParallelEnvCore::rsuOptions(const std::string& rsu_id) const {
  for (const Rsu& r : rsus_)
    if (r.options.controller.rsu_id == rsu_id) return r.options;
  throw std::invalid_argument("no RSU '" + rsu_id + "' in this environment");
}

void ParallelEnvCore::makeControllers() {
  for (Rsu& r : rsus_) {
    const rsu::RsuNodeOptions& o = r.options;
    r.controller = std::make_unique<RsuController>(o.controller);
    r.rewards.reset();
    if (!o.controller.train) {
      RsuControllerOptions twin = o.controller;
      twin.train = true;
      r.rewards = std::make_unique<RsuController>(twin);
    }
    rsu::RsuScheduleOptions s;
    s.decision_period_steps = o.decision_period_steps;
    s.train = o.controller.train;
    s.reward_over_period = o.controller.reward_over_period;
    s.learner_thread = false;
    s.federation = false;
    r.schedule = std::make_unique<rsu::RsuSchedule>(s);
    r.peers = std::make_unique<rsu::PeerStates>(o.controller.cluster_index, o.i2i_stale_after_s);
    r.outcomes.clear();
    r.last_own_density = kNaN;
    r.due = false;
  }
}

StepResult ParallelEnvCore::reset(std::optional<unsigned> seed) {
  running_ = false;
  bool seed_changed = false;
  if (seed && *seed != bridge_.scenario.seed) {
    bridge_.scenario.seed = *seed;
    sumocfg_ = bridge::prepareScenario(bridge_);  // the traffic of the new seed
    bridge::completeManifest(bridge_, runner_->session().sumoVersion(), sim::SumoSession::apiName(), rules_);
    seed_changed = true;
  }
  const int next = seed ? 0 : episode_ + 1;
  // The runner loaded episode 0's SUMO when it was made; any other start loads anew.
  if (!(fresh_ && next == 0 && !seed_changed)) runner_->startEpisode(next);
  fresh_ = false;
  episode_ = next;
  measure_ = std::make_unique<bridge::EpisodeMeasure>(rules_);
  makeControllers();
  agents_.clear();
  last_observation_.clear();
  running_ = true;
  runner_->beginEpisode(episode_, *this);
  StepResult out;
  runToDecision(out);
  return out;
}

void ParallelEnvCore::publishStep(const sim::SumoSession& session) {
  // As BridgeNode::publishStep: the state goes out and is measured; then the RSUs see it.
  const ros::Time stamp(session.timeS());
  current_.header.stamp = stamp;
  current_.step = session.stepCount();
  current_.step_length_s = session.stepLengthS();
  current_.num_lanes = static_cast<uint8_t>(session.road().numMainLanes());
  current_.vehicles.clear();
  for (const sim::VehicleRecord& v : session.vehicles()) current_.vehicles.push_back(bridge::toMsg(v));
  const auto& sim_events = session.lastEvents();
  const std::vector<metrics::VehicleEvent> events =
      measure_->onStep(current_, {sim_events.collided, sim_events.teleported, sim_events.arrived});

  // As RsuDecider::onEvents / onStates / decide, up to the choice of the decisions.
  any_due_ = false;
  const std::uint64_t step = current_.step;
  const double now_s = current_.header.stamp.toSec();
  std::optional<RoadSnapshot> snapshot;
  for (Rsu& r : rsus_) {
    for (const metrics::VehicleEvent& e : events)
      if (static_cast<int>(e.kind) < metrics::VEHICLE_EVENT_KIND_COUNT) r.outcomes.add(e.kind, e.vehicle_id);
    r.due = r.schedule->decidesAt(step);
    const bool observe = r.schedule->observesBetweenDecisions() || (r.rewards && r.options.controller.reward_over_period);
    if (!r.due && !observe) continue;
    if (!snapshot) snapshot = rsu::toSnapshot(current_);
    if (!r.due) {
      if (r.schedule->observesBetweenDecisions()) r.controller->observeStep(*snapshot);
      if (r.rewards) r.rewards->observeStep(*snapshot);
      continue;
    }
    any_due_ = true;
    r.global = r.options.i2i ? r.peers->global(r.last_own_density, now_s) : GlobalDensities{kNaN, kNaN, kNaN};
    const rsu::VehicleOutcomes none;
    r.view = r.controller->preview(*snapshot, step, now_s, r.global, r.options.controller.train ? r.outcomes : none);
    if (r.rewards) r.reward_view = r.rewards->preview(*snapshot, step, now_s, r.global, r.outcomes);
  }
  decision_open_ = std::chrono::steady_clock::now();
}

void ParallelEnvCore::lockstepMissed(std::uint64_t, const std::vector<std::string>& late,
                                     const std::vector<std::string>&) {
  if (!late.empty()) measure_->metrics().addLateRsuStep();
}

void ParallelEnvCore::rejected(const std::string&, const std::string&, metrics::RejectionReason reason,
                               const std::string&) {
  measure_->metrics().addAdvisoryRejected(reason);
}

void ParallelEnvCore::applied(const std::string&) { measure_->metrics().addAdvisoriesApplied(); }

void ParallelEnvCore::runToDecision(StepResult& out) {
  const std::vector<std::string> previous = agents_;
  std::set<std::string> members;
  bool over = false;
  while (true) {
    if (!any_due_)
      while (true) {
        if (!runner_->advance(*this)) {
          over = true;
          break;
        }
        if (any_due_) break;
      }
    if (!over) over = runner_->session().timeS() >= bridge_.scenario.duration_s - 1e-9;
    members.clear();
    for (const Rsu& r : rsus_) {
      if (!r.due) continue;
      const std::string& id = r.options.controller.rsu_id;
      for (std::size_t i = 0; i < r.view.member_ids.size(); ++i) {
        const std::string agent = agentName(id, r.view.member_ids[i]);
        members.insert(agent);
        out.observations[agent] = column(r.view.states, static_cast<nn::Index>(i));
        out.rewards[agent] = 0.0;  // no transition of it closed yet
        out.terminations[agent] = false;
        out.truncations[agent] = false;
      }
      // The rewards of the transitions this decision closes (the RSU's own, or its training twin's).
      for (const Closure& c : (r.rewards ? r.reward_view : r.view).closures) {
        const std::string agent = agentName(id, c.id);
        out.rewards[agent] = c.reward;
        if (members.count(agent)) continue;
        // It left the zone (or the road): its last reward, then it is gone.
        out.observations[agent] = vectorOf(c.next_state);
        out.terminations[agent] = c.done;
        out.truncations[agent] = !c.done;
      }
    }
    if (over || !members.empty()) break;
    // Nobody to ask: the RSUs answer this decision step empty, as they would, and run on (what
    // the leaving agents got is kept for the step that returns).
    applyDecisions({});
  }
  if (over) {
    // The episode's end is not a terminal state: whoever is still there is truncated.
    for (const std::string& agent : previous)
      if (!out.terminations.count(agent) || (!out.terminations[agent] && !out.truncations[agent])) {
        if (!out.observations.count(agent)) out.observations[agent] = last_observation_[agent];
        out.rewards.emplace(agent, 0.0);
        out.terminations[agent] = false;
        out.truncations[agent] = true;
      }
    for (const std::string& agent : members) {
      out.terminations[agent] = false;
      out.truncations[agent] = true;
    }
    agents_.clear();
    endEpisode();
  } else {
    agents_.assign(members.begin(), members.end());
  }
  last_observation_.clear();
  for (const std::string& agent : agents_) last_observation_[agent] = out.observations[agent];
  out.agents = agents_;
  out.episode_over = over;
  out.step = runner_->session().stepCount();
  out.time_s = runner_->session().timeS();
}

StepResult ParallelEnvCore::step(const std::map<std::string, AgentAction>& actions) {
  if (!running_) throw std::logic_error("palcas_env: no episode under way: call reset() first");
  // Every check before anything is applied: a bad call leaves the environment as it was.
  for (const auto& [agent, action] : actions) {
    if (!std::binary_search(agents_.begin(), agents_.end(), agent))
      throw std::invalid_argument("unknown agent '" + agent + "': not acting at step " +
                                  std::to_string(current_.step) + " (see env.agents)");
    if (action.advisory < 0 || action.advisory >= ACTION_COUNT)
      throw std::invalid_argument("agent '" + agent + "': advisory index " + std::to_string(action.advisory) +
                                  " outside 0..3 (0 LEFT, 1 RIGHT, 2 ACCELERATE, 3 KEEP)");
    if (!std::isfinite(action.accel_mps2))
      throw std::invalid_argument("agent '" + agent + "': acceleration is not finite");
  }
  for (const std::string& agent : agents_)
    if (!actions.count(agent)) throw std::invalid_argument("no action for agent '" + agent + "'");

  applyDecisions(actions);
  StepResult out;
  runToDecision(out);
  return out;
}

void ParallelEnvCore::applyDecisions(const std::map<std::string, AgentAction>& actions) {
  const std::uint64_t step = current_.step;
  const double now_s = current_.header.stamp.toSec();
  const float decision_ms =
      static_cast<float>(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - decision_open_).count());
  const RoadSnapshot snapshot = rsu::toSnapshot(current_);
  struct Sent {
    const Rsu* from;
    double density;
    double time_s;
  };
  std::vector<Sent> cluster_states;
  for (Rsu& r : rsus_) {
    if (!r.due) continue;
    const std::string& id = r.options.controller.rsu_id;
    std::map<std::string, Decision> by_vehicle;
    std::vector<Decision> decisions;
    decisions.reserve(r.view.member_ids.size());
    for (const std::string& vehicle : r.view.member_ids) {
      const AgentAction& a = actions.at(agentName(id, vehicle));
      decisions.push_back(Decision{static_cast<Action>(a.advisory), static_cast<float>(a.accel_mps2)});
      by_vehicle[vehicle] = decisions.back();
    }
    const rsu::VehicleOutcomes none;
    const DecisionOutput d = r.controller->adviseWith(snapshot, step, now_s, r.global,
                                                      r.options.controller.train ? r.outcomes : none, decisions);
    if (r.rewards) {
      std::vector<Decision> twin;
      for (const std::string& vehicle : r.reward_view.member_ids) twin.push_back(by_vehicle.at(vehicle));
      r.rewards->adviseWith(snapshot, step, now_s, r.global, r.outcomes, twin);
    }
    r.outcomes.clear();
    r.last_own_density = d.cluster.density_veh_per_km;
    // The answer as the RSU sends it (palcas_rsu's toMsg, the bridge's toRequest).
    auto array = std::make_shared<sim::AdviceArray>();
    array->rsu_id = id;
    array->step = step;
    array->decision_ms = decision_ms;
    for (const CavAdvisory& adv : d.advisories) {
      metrics::AdvisoryRequest q;
      q.vehicle_id = adv.vehicle_id;
      q.action_code = static_cast<int>(adv.decision.action);
      q.accel_mps2 = adv.decision.action == Action::kAccelerate ? adv.decision.accel_mps2 : 0.0;
      q.answers_step = step;
      q.rsu_id = id;
      array->advisories.push_back(std::move(q));
    }
    runner_->onAnswer(std::move(array));
    if (r.options.i2i) cluster_states.push_back({&r, d.cluster.density_veh_per_km, ros::Time(d.time_s).toSec()});
    r.due = false;
  }
  // The cluster states after every decision of the step (as InProcessRsus::step).
  for (const Sent& s : cluster_states)
    for (Rsu& to : rsus_) {
      if (&to == s.from || !to.options.i2i) continue;
      try {
        to.peers->update(s.from->options.controller.cluster_index, s.from->options.controller.rsu_id, s.density,
                         s.time_s);
      } catch (const std::invalid_argument&) {
        // A malformed cluster state is ignored, as the RSU does.
      }
    }
  any_due_ = false;
}

void ParallelEnvCore::endEpisode() {
  running_ = false;
  const sim::EpisodeRun run = runner_->finishEpisode(*this);
  // As BridgeNode::writeEpisode.
  bridge::RunSummary summary;
  summary.episode = episode_;
  summary.metrics = measure_->metrics().snapshot();
  summary.exits = measure_->cavExits();
  summary.wall_seconds = run.wall_s;
  summary.steps = run.steps;
  summary.late_by_rsu = run.late_by_rsu;
  for (int k = 0; k < metrics::REJECTION_REASON_COUNT; ++k)
    summary.rejections_by_reason[metrics::rejectionReasonName(static_cast<metrics::RejectionReason>(k))] =
        measure_->metrics().rejections(static_cast<metrics::RejectionReason>(k));
  summary.timing = run.timing;
  summary.decision_ms = run.decision_ms;
  const sim::SumoSession& session = runner_->session();
  summary.lane_changes_done = session.laneChangesDone();
  summary.lane_changes_dropped = session.laneChangesDropped();
  summary.vanished_vehicles = session.vanishedVehicles();
  summary.route_changes_failed = session.routeChangesFailed();
  summary.guard = session.guardCounters();
  summary.insertion_dropped = session.insertionDropped();
  summary.insertion_waiting_end = session.insertionWaiting();
  summary.insertion_wait_veh_s = session.insertionWaitVehicleSeconds();
  summary.downlink = run.downlink;
  bridge::writeMetricsJson(bridge_, summary, episode_);
}

// ---- PolicyCore ----

namespace {

std::string checkpointsOf(const std::string& folder) {
  const fs::path dir(folder);
  if (!fs::is_directory(dir)) throw std::invalid_argument("policy folder '" + folder + "' does not exist");
  if (fs::is_regular_file(dir / "train.json") && fs::is_directory(dir / "checkpoints"))
    return (dir / "checkpoints").string();
  bool models = fs::exists(dir / "fedserver" / "global_model.palcas") || fs::exists(dir / "default" / "model.palcas");
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_directory() && fs::exists(entry.path() / "model.palcas")) models = true;
  if (!models)
    throw std::invalid_argument("'" + folder + "' is not a PALCAS policy folder: neither train.json with "
                                "checkpoints/ (as policies/palcas/) nor a checkpoints folder holding "
                                "fedserver/global_model.palcas, default/model.palcas or <rsu_id>/model.palcas");
  return dir.string();
}

}  // namespace

PolicyCore::PolicyCore(const std::string& folder, const ParallelEnvCore& env) {
  const std::string checkpoints = checkpointsOf(folder);
  for (const std::string& id : env.rsuIds()) {
    // With rsu/rule_residual the RSU decides the network over the rule (actOverDefaults), not
    // the greedy act() this class reproduces.
    if (env.rsuOptions(id).controller.rule_residual)
      throw std::invalid_argument("policy '" + folder + "': " + id +
                                  " runs with rsu/rule_residual, which Policy does not reproduce");
    const std::string file = rsu::policyFileIn(checkpoints, id);
    auto agent = std::make_unique<PdqnAgent>(env.rsuOptions(id).controller.pdqn);
    try {
      agent->loadModel(file);
    } catch (const std::exception& e) {
      throw std::runtime_error("policy '" + folder + "', " + id + ": " + e.what());
    }
    files_[id] = file;
    agents_[id] = std::move(agent);
  }
}

PdqnAgent& PolicyCore::agentOf(const std::string& rsu_id) {
  const auto it = agents_.find(rsu_id);
  if (it == agents_.end()) throw std::invalid_argument("the policy has no model for RSU '" + rsu_id + "'");
  return *it->second;
}

std::vector<std::string> PolicyCore::rsuIds() const {
  std::vector<std::string> out;
  for (const auto& entry : agents_) out.push_back(entry.first);
  return out;
}

const PdqnConfig& PolicyCore::config(const std::string& rsu_id) const {
  const auto it = agents_.find(rsu_id);
  if (it == agents_.end()) throw std::invalid_argument("the policy has no model for RSU '" + rsu_id + "'");
  return it->second->config();
}

ModelBlob PolicyCore::exportModel(const std::string& rsu_id) const {
  const auto it = agents_.find(rsu_id);
  if (it == agents_.end()) throw std::invalid_argument("the policy has no model for RSU '" + rsu_id + "'");
  return it->second->exportModel();
}

std::map<std::string, AgentAction> PolicyCore::act(const std::map<std::string, std::vector<float>>& observations) {
  // One batch per RSU, as the RSU decides its members (a column's decision does not depend
  // on the others in the batch).
  std::map<std::string, std::vector<std::string>> by_rsu;
  for (const auto& [agent, state] : observations) {
    const std::string rsu_id = splitAgent(agent).first;
    const int size = agentOf(rsu_id).config().state_size;
    if (static_cast<int>(state.size()) != size)
      throw std::invalid_argument("agent '" + agent + "': observation of " + std::to_string(state.size()) +
                                  " values, the policy's state has " + std::to_string(size));
    by_rsu[rsu_id].push_back(agent);
  }
  std::map<std::string, AgentAction> out;
  for (const auto& [rsu_id, agents] : by_rsu) {
    PdqnAgent& agent = agentOf(rsu_id);
    nn::Matrix states(agent.config().state_size, static_cast<nn::Index>(agents.size()));
    for (std::size_t j = 0; j < agents.size(); ++j) {
      const std::vector<float>& s = observations.at(agents[j]);
      for (std::size_t i = 0; i < s.size(); ++i) states(static_cast<nn::Index>(i), static_cast<nn::Index>(j)) = s[i];
    }
    const std::vector<Decision> decisions = agent.act(states, false);
    for (std::size_t j = 0; j < agents.size(); ++j)
      out[agents[j]] = AgentAction{static_cast<int>(decisions[j].action), decisions[j].accel_mps2};
  }
  return out;
}

void PolicyCore::evaluate(const std::string& rsu_id, const nn::Matrix& states, nn::Matrix& q, nn::Matrix& accel) {
  agentOf(rsu_id).evaluate(states, q, accel);
}

}  // namespace palcas::pyenv
