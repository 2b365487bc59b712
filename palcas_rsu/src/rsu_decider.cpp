#include "palcas_rsu/rsu_decider.h"

#include <palcas_common/model_weights.h>
#include <ros/console.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "palcas_rsu/msg_conversion.h"

namespace palcas::rsu {
namespace fs = std::filesystem;

namespace {

RsuScheduleOptions scheduleOf(const RsuNodeOptions& o) {
  RsuScheduleOptions s;
  s.decision_period_steps = o.decision_period_steps;
  s.train = o.controller.train;
  s.reward_over_period = o.controller.reward_over_period;
  s.learner_thread = o.learner_thread;
  s.checkpoint_every_decisions = o.checkpoint_every_decisions;
  s.checkpoint_dir_set = !o.checkpoint_dir.empty();
  // In training the federation client exists exactly when federation is on; in eval the
  // schedule never ticks it.
  s.federation = o.federation;
  return s;
}

double msSince(RsuDecider::Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(RsuDecider::Clock::now() - t).count();
}

}  // namespace

void logFederationEvent(const std::string& who, FederationEvent event, const std::string& message) {
  switch (event) {
    case FederationEvent::kUnreachable:
      ROS_WARN_THROTTLE_NAMED(10.0, "federation", "%s%s", who.c_str(), message.c_str());
      break;
    case FederationEvent::kModelRefused:
      ROS_ERROR_THROTTLE_NAMED(10.0, "federation", "%s%s", who.c_str(), message.c_str());
      break;
    case FederationEvent::kSubmitRefused:
      ROS_WARN_THROTTLE_NAMED(10.0, "federation", "%s%s", who.c_str(), message.c_str());
      break;
    case FederationEvent::kSubmitted:
    case FederationEvent::kLoaded:
      ROS_INFO_NAMED("federation", "%s%s", who.c_str(), message.c_str());
      break;
  }
}

std::string describeDecision(const RsuDecision& decision, std::uint32_t members) {
  const palcas_msgs::AdvisoryArray& a = decision.advisories;
  std::string advice;
  for (const palcas_msgs::Advisory& adv : a.advisories) {
    advice += " " + adv.vehicle_id + ":" + actionName(static_cast<Action>(adv.action));
    if (static_cast<Action>(adv.action) == Action::kAccelerate) {
      char accel[16];
      std::snprintf(accel, sizeof accel, "(%+.2f)", adv.accel_mps2);
      advice += accel;
    }
  }
  char head[200];
  std::snprintf(head, sizeof head, "%s: step %lu: %u members, density %.1f veh/km (I2I up %.1f, down %.1f), %.2f ms;",
                a.rsu_id.c_str(), static_cast<unsigned long>(a.step), members,
                decision.cluster_state ? decision.cluster_state->density_veh_per_km : std::nan(""),
                a.i2i_upstream_density_veh_per_km, a.i2i_downstream_density_veh_per_km, a.decision_ms);
  return head + advice;
}

RsuDecider::RsuDecider(RsuNodeOptions options)
    : options_(std::move(options)),
      controller_(std::make_unique<RsuController>(options_.controller)),
      schedule_(scheduleOf(options_)),
      peers_(options_.controller.cluster_index, options_.i2i_stale_after_s),
      learning_log_(options_.checkpoint_dir.empty() ? "" : (fs::path(checkpointDir()) / "learning.csv").string(),
                    options_.controller.rsu_id, options_.controller.train ? "train" : "eval") {
  requireEvalWeights(options_);
  const RsuControllerOptions& c = options_.controller;
  if (options_.resume && !fs::exists(fs::path(checkpointDir()) / "agent.ckpt")) {
    // A new training, or one that stopped before this RSU wrote anything: start afresh.
    ROS_INFO_NAMED("checkpoint", "%s: no checkpoint in %s yet; starting afresh", c.rsu_id.c_str(),
                   checkpointDir().c_str());
  } else if (options_.resume) {
    controller_->loadCheckpoint(checkpointDir());
    ROS_INFO_NAMED("checkpoint", "%s: resumed from %s (gradient steps %lu, model version %u)", c.rsu_id.c_str(),
                   checkpointDir().c_str(), static_cast<unsigned long>(controller_->agent().gradientSteps()),
                   controller_->modelVersion());
  }
  loadInitialModel();
}

RsuDecider::~RsuDecider() = default;

std::string RsuDecider::checkpointDir() const {
  return (fs::path(options_.checkpoint_dir) / options_.controller.rsu_id).string();
}

void RsuDecider::loadInitialModel() {
  const RsuControllerOptions& c = options_.controller;
  if (c.advice_source == AdviceSource::kRules) {
    ROS_INFO_NAMED("startup", "%s: advice from the rule (exit %.0f m per lane + %.0f m, through traffic out of "
                   "lanes 1..%d, merge advice %s); no weights loaded",
                   c.rsu_id.c_str(), c.rules.exit_distance_per_lane_m, c.rules.exit_margin_m,
                   c.rules.through_keep_out_lanes, c.rules.advise_merge ? "on" : "off");
    return;
  }
  if (c.train) return;
  if (options_.policy_dir == RANDOM_POLICY) {
    ROS_WARN_NAMED("startup", "%s: evaluating an UNTRAINED network (policy_dir:=%s): its advice is random",
                   c.rsu_id.c_str(), RANDOM_POLICY);
    return;
  }
  const fs::path file = policyFileIn(options_.policy_dir, c.rsu_id, options_.policy_model);
  controller_->loadPolicy(file.string());
  policy_file_ = file.string();
  ROS_INFO_NAMED("startup", "%s: evaluating policy %s", c.rsu_id.c_str(), file.c_str());
}

bool RsuDecider::wantsFederation() const {
  return options_.controller.train && options_.federation &&
         options_.controller.advice_source != AdviceSource::kRules;
}

void RsuDecider::startFederation(std::unique_ptr<FederationTransport> transport, bool server_reachable,
                                 FederationLog log, ModelLoaded loaded) {
  if (!wantsFederation()) throw std::logic_error(rsuId() + ": startFederation without a training with federation");
  if (federation_) throw std::logic_error(rsuId() + ": startFederation called twice");
  federated_model_ = std::make_unique<ControllerModel>(*controller_);
  transport_ = std::move(transport);
  federation_log_ = std::move(log);
  model_loaded_ = std::move(loaded);
  FederationClientOptions client;
  client.rsu_id = rsuId();
  client.heartbeat_s = options_.federation_heartbeat_s;
  federation_ = std::make_unique<FederationClient>(
      client, *federated_model_, *transport_, [this](FederationEvent e, const std::string& message) {
        if (e == FederationEvent::kLoaded && model_loaded_)
          model_loaded_(common::toWeightsMsg(controller_->exportModel(), rsuId(), federation_->openRound(),
                                             controller_->modelVersion(), 0));
        if (federation_log_) federation_log_(e, message);
      });
  if (server_reachable) federation_->join();
}

void RsuDecider::announceGlobalVersion(uint32_t version) {
  if (federation_) federation_->announceVersion(version);
}

void RsuDecider::onEvents(const palcas_msgs::VehicleEventArray& events) { addOutcomes(events, outcomes_); }

bool RsuDecider::onClusterState(const palcas_msgs::ClusterState& state, std::string* why) {
  if (state.rsu_id == rsuId()) return false;
  if (channel_) {
    // I2I over the channel: lost, or held until the step it arrives at (decide() takes it).
    ++i2i_received_;
    const v2x::Delivery d = channel_->transmit(v2x::MessageClass::CLUSTER_STATE, state.rsu_id, rsuId(), state.step);
    if (d.lost) ++i2i_lost_;
    else i2i_in_flight_.push(state.step + d.delay_steps, state);
    return true;
  }
  try {
    peers_.update(state.cluster_index, state.rsu_id, state.density_veh_per_km, state.header.stamp.toSec());
  } catch (const std::invalid_argument& e) {
    if (why) *why = e.what();
    return false;
  }
  return true;
}

bool RsuDecider::onStates(const palcas_msgs::VehicleStateArray& states) {
  const RsuControllerOptions& c = options_.controller;
  if (first_state_ && states.num_lanes != c.num_lanes)
    throw std::runtime_error(rsuId() + ": the road has " + std::to_string(states.num_lanes) +
                             " lanes but rsu/num_lanes is " + std::to_string(c.num_lanes) +
                             " (the state size depends on it)");
  if (first_state_ && options_.v2x.enabled) {
    // The centralized baseline is one agent over the whole road, not a radio: no range.
    const double x_m = options_.whole_road ? 0.0 : 0.5 * (c.x_start_m + c.x_end_m);
    v2x::ChannelParams p = options_.v2x;
    if (options_.whole_road) p.rsu_range_m = std::numeric_limits<double>::infinity();
    channel_ = std::make_unique<v2x::Channel>(p, states.step_length_s);
    uplink_ = std::make_unique<v2x::UplinkView>(*channel_, c.rsu_id, x_m);
    ROS_INFO_NAMED("v2x", "%s: V2X channel on (seed %lu): states %.3f s + U(0, %.3f) s, lost %.1f %%; cluster states "
                   "%.3f s + U(0, %.3f) s, lost %.1f %%; range %.1f m from x = %.0f m; states forgotten after %.2f s",
                   c.rsu_id.c_str(), static_cast<unsigned long>(p.seed), p.vehicle_state.latency_s,
                   p.vehicle_state.jitter_s, 100.0 * p.vehicle_state.loss_probability, p.cluster_state.latency_s,
                   p.cluster_state.jitter_s, 100.0 * p.cluster_state.loss_probability, p.rsu_range_m, x_m,
                   p.max_state_age_s);
  }
  first_state_ = false;
  if (uplink_ && last_state_step_ && states.step <= *last_state_step_) {
    uplink_->clear();  // a new episode: nothing heard yet, nothing in flight
    i2i_in_flight_.clear();
  }
  last_state_step_ = states.step;
  if (schedule_.decidesAt(states.step)) return true;
  const bool observe = schedule_.observesBetweenDecisions();
  if (observe || uplink_) {
    const RoadSnapshot road = heard(states);       // the uplink hears every step
    if (observe) controller_->observeStep(road);  // never touches the agent: no join
  }
  return false;
}

RsuDecision RsuDecider::decide(const palcas_msgs::VehicleStateArray& states, Clock::time_point received,
                               const GlobalDensities* used_densities) {
  const RsuControllerOptions& c = options_.controller;
  const double now_s = states.header.stamp.toSec();
  schedule_.finishLearning();  // rethrows what learn() threw; the controller is ours again
  RsuDecision out;
  out.time_s = now_s;
  GlobalDensities global;
  DecisionOutput decision;
  try {
    const RoadSnapshot snapshot = heard(states);
    for (const palcas_msgs::ClusterState& m : i2i_in_flight_.release(states.step)) {
      try {
        peers_.update(m.cluster_index, m.rsu_id, m.density_veh_per_km, m.header.stamp.toSec());
      } catch (const std::invalid_argument& e) {
        ROS_WARN_THROTTLE_NAMED(5.0, "i2i", "%s: ignored cluster state: %s", c.rsu_id.c_str(), e.what());
      }
    }
    // The own density is not known before deciding; the state builder takes the global
    // densities as given, so use the peers' view with the last own density.
    const double unknown = std::numeric_limits<double>::quiet_NaN();
    global = options_.i2i ? peers_.global(last_own_density_, now_s) : GlobalDensities{unknown, unknown, unknown};
    out.from_peers = global;
    if (options_.i2i && used_densities) {
      global.upstream = used_densities->upstream;
      global.downstream = used_densities->downstream;
      global.own = used_densities->own;
    }
    // Evaluating, membership comes from the states alone (the bridge drops a removed vehicle
    // from the states of the step that removes it; over the V2X channel the events would race
    // the delayed states). Training keeps them: they close its transitions.
    const VehicleOutcomes none;
    decision = controller_->advise(snapshot, states.step, now_s, global, c.train ? outcomes_ : none);
    outcomes_.clear();
    last_own_density_ = decision.cluster.density_veh_per_km;
  } catch (const std::invalid_argument& e) {
    // A malformed state: answer empty (CAVs keep their commands), say why, keep going.
    out.advisories = emptyAnswer(states, received);
    out.error = e.what();
    return out;
  }
  out.decided = true;
  palcas_msgs::AdvisoryArray& a = out.advisories;
  a.header = states.header;
  a.step = states.step;
  a.rsu_id = c.rsu_id;
  a.i2i_upstream_density_veh_per_km = global.upstream;
  a.i2i_downstream_density_veh_per_km = global.downstream;
  for (const CavAdvisory& adv : decision.advisories) a.advisories.push_back(toMsg(adv, decision.model_version));
  if (options_.i2i) out.cluster_state = toMsg(decision.cluster, c, states.step, decision.time_s);
  a.decision_ms = static_cast<float>(msSince(received));
  return out;
}

palcas_msgs::RsuStatus RsuDecider::afterPublished(const palcas_msgs::VehicleStateArray& states,
                                                  const RsuDecision& decision) {
  const RsuControllerOptions& c = options_.controller;
  const AfterDecision after = schedule_.decided();
  if (after.learn_inline) controller_->learn();
  try {
    learning_log_.addDecision(states.step, controller_->stats(), decision.advisories.decision_ms);
  } catch (const std::runtime_error& e) {
    ROS_ERROR_THROTTLE_NAMED(60.0, "learning", "%s: %s", c.rsu_id.c_str(), e.what());
  }
  if (after.federation_tick && federation_) federation_->onDecision(decision.time_s);
  if (after.checkpoint) {
    try {
      checkpoint();
    } catch (const std::exception& e) {
      ROS_ERROR_NAMED("checkpoint", "%s: checkpoint failed: %s", c.rsu_id.c_str(), e.what());
    }
  }
  StatusContext context;
  context.header = states.header;
  context.step = states.step;
  context.rsu_id = c.rsu_id;
  context.train = c.train;
  context.decision_ms = decision.advisories.decision_ms;
  context.stale_peers = static_cast<uint32_t>(peers_.stalePeers(decision.time_s).size());
  context.federation_reachable = federationReachable();
  palcas_msgs::RsuStatus status = toStatusMsg(controller_->stats(), context);
  // Last: federation and checkpoints above saw the model as the decision used it.
  if (after.learn_on_thread) schedule_.startLearning([this] { controller_->learn(); });
  return status;
}

palcas_msgs::AdvisoryArray RsuDecider::emptyAnswer(const palcas_msgs::VehicleStateArray& states,
                                                   Clock::time_point received) const {
  palcas_msgs::AdvisoryArray out;
  out.header = states.header;
  out.step = states.step;
  out.rsu_id = rsuId();
  out.i2i_upstream_density_veh_per_km = std::numeric_limits<double>::quiet_NaN();
  out.i2i_downstream_density_veh_per_km = std::numeric_limits<double>::quiet_NaN();
  out.decision_ms = static_cast<float>(msSince(received));
  return out;
}

void RsuDecider::checkpoint() {
  controller_->saveCheckpoint(checkpointDir());
  controller_->agent().saveModel((fs::path(checkpointDir()) / "model.palcas").string());
}

std::string RsuDecider::shutdown() {
  schedule_.finishLearning();
  try {
    learning_log_.endEpisode(controller_->stats());
  } catch (const std::runtime_error& e) {
    ROS_ERROR_NAMED("learning", "%s: %s", rsuId().c_str(), e.what());
  }
  if (!options_.controller.train || options_.checkpoint_dir.empty()) return "";
  try {
    checkpoint();
  } catch (const std::exception& e) {
    ROS_ERROR_NAMED("checkpoint", "%s: checkpoint failed: %s", rsuId().c_str(), e.what());
    return "";
  }
  return checkpointDir();
}

RoadSnapshot RsuDecider::heard(const palcas_msgs::VehicleStateArray& states) {
  RoadSnapshot truth = toSnapshot(states);
  if (!uplink_) return truth;
  return uplink_->receive(truth, states.step);
}

}  // namespace palcas::rsu
