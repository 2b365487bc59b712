#include "palcas_rsu/rsu_node.h"

#include <ros/master.h>

#include <palcas_common/bridge_road.h>
#include <palcas_common/message_auth.h>
#include <palcas_common/model_weights.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/RegisterRsu.h>
#include <palcas_msgs/RsuStatus.h>

#include <cstdio>
#include <filesystem>
#include <limits>

#include "palcas_rsu/msg_conversion.h"
#include "palcas_rsu/topics.h"

namespace palcas::rsu {
namespace fs = std::filesystem;

namespace {

/// policy_dir's value for an evaluation of an untrained network, asked for on purpose.
constexpr const char* RANDOM_POLICY = "random";

/// An evaluation runs trained weights: refused before anything waits for the bridge.
void requireEvalWeights(const RsuNodeOptions& o) {
  if (o.controller.train || o.policy_dir == RANDOM_POLICY) return;
  if (o.controller.advice_source == AdviceSource::kRules) return;  // the rule needs no weights
  if (o.policy_dir.empty())
    throw std::runtime_error(
        "mode eval needs trained weights and policy_dir is not set: give policy_dir:=DIR (a training's "
        "checkpoints/ folder; system.launch's default 'shipped' is policies/<arm>/checkpoints; "
        "./palcas train makes new ones), or policy_dir:=random to evaluate an untrained network on "
        "purpose. Only mode train starts from random weights");
  if (!fs::is_directory(o.policy_dir))
    throw std::runtime_error("policy_dir '" + o.policy_dir + "' is not a folder (eval needs a training's "
                             "checkpoints/ folder, e.g. policies/palcas/checkpoints)");
}

/// When the node decides, learns, ticks the federation client and checkpoints.
RsuScheduleOptions scheduleOf(const RsuNodeOptions& o) {
  RsuScheduleOptions s;
  s.decision_period_steps = o.decision_period_steps;
  s.train = o.controller.train;
  s.reward_over_period = o.controller.reward_over_period;
  s.learner_thread = o.learner_thread;
  s.checkpoint_every_decisions = o.checkpoint_every_decisions;
  s.checkpoint_dir_set = !o.checkpoint_dir.empty();
  // In training the federation client exists exactly when federation is on
  // (loadInitialModel); in eval the schedule never ticks it.
  s.federation = o.federation;
  return s;
}

/// The node's options with what they leave to the bridge's road filled in from it (the
/// bridge sets it before opening registration; an RSU may start first, so wait for it).
RsuNodeOptions loadOptionsOnTheRoad(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh) {
  RsuNodeOptions o = loadRsuNodeOptions(private_nh);
  requireEvalWeights(o);
  if (!takesFromBridgeRoad(o)) return o;  // all set here: checked at registration
  const auto road = common::waitForBridgeRoad(nh, o.register_timeout_s);
  if (!road)
    throw std::runtime_error(std::string("no road from the bridge (") + common::ROAD_ZONES_PARAM + ", " +
                             common::ROAD_LANES_PARAM + ") after " + std::to_string(o.register_timeout_s) +
                             " s; without a bridge set ~zones_m, ~rsu/num_lanes and ~learning/state_size");
  adoptBridgeRoad(o, road->zones_m, road->num_lanes);
  return o;
}

/// The decision inputs to wait for: training, the step's events, and with I2I between zones
/// the neighbours' cluster states (the whole-road RSU has no neighbour).
DecisionInputs decisionInputsOf(const RsuNodeOptions& o) {
  const int zones = std::max(static_cast<int>(o.zones_m.size()) - 1, o.controller.cluster_index + 1);
  return DecisionInputs(o.controller.cluster_index, zones, o.i2i && !o.whole_road,
                        static_cast<std::uint64_t>(o.decision_period_steps), o.controller.train);
}

}  // namespace

RsuNode::RsuNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), private_nh_(private_nh), options_(loadOptionsOnTheRoad(nh_, private_nh_)),
      controller_(std::make_unique<RsuController>(options_.controller)),
      auth_key_(common::loadMessageKey(options_.auth_key_file)),
      schedule_(scheduleOf(options_)),
      peers_(options_.controller.cluster_index, options_.i2i_stale_after_s),
      learning_log_(options_.checkpoint_dir.empty() ? "" : (fs::path(checkpointDir()) / "learning.csv").string(),
                    options_.controller.rsu_id, options_.controller.train ? "train" : "eval"),
      inputs_(decisionInputsOf(options_)) {
  const RsuControllerOptions& c = options_.controller;
  if (options_.resume && !fs::exists(fs::path(checkpointDir()) / "agent.ckpt")) {
    // A new training, or one that stopped before this RSU wrote anything: start afresh.
    ROS_INFO_NAMED("checkpoint", "%s: no checkpoint in %s yet; starting afresh", c.rsu_id.c_str(), checkpointDir().c_str());
  } else if (options_.resume) {
    controller_->loadCheckpoint(checkpointDir());
    ROS_INFO_NAMED("checkpoint", "%s: resumed from %s (gradient steps %lu, model version %u)", c.rsu_id.c_str(),
             checkpointDir().c_str(), static_cast<unsigned long>(controller_->agent().gradientSteps()),
             controller_->modelVersion());
  }
  // Federation traffic, latched and once per round: what this RSU sent and what it holds
  // after loading the global model (for tests, bags and debugging).
  submitted_pub_ = nh_.advertise<palcas_msgs::ModelWeights>(SUBMITTED_WEIGHTS_TOPIC, 1, true);
  model_pub_ = nh_.advertise<palcas_msgs::ModelWeights>(MODEL_TOPIC, 1, true);
  loadInitialModel();
  advisories_pub_ = nh_.advertise<palcas_msgs::AdvisoryArray>(ADVISORIES_TOPIC, 10);
  cluster_pub_ = nh_.advertise<palcas_msgs::ClusterState>(CLUSTER_STATES_TOPIC, 10);
  status_pub_ = nh_.advertise<palcas_msgs::RsuStatus>(RSU_STATUS_TOPIC, 10);
  // Room for the steps between two decisions and more: the bridge waits only for decisions.
  states_sub_ = nh_.subscribe(VEHICLE_STATES_TOPIC, 1000, &RsuNode::onStates, this,
                              ros::TransportHints().tcpNoDelay());
  events_sub_ = nh_.subscribe(VEHICLE_EVENTS_TOPIC, 1000, &RsuNode::onEvents, this,
                              ros::TransportHints().tcpNoDelay());
  if (options_.i2i)
    cluster_sub_ = nh_.subscribe(CLUSTER_STATES_TOPIC, 20, &RsuNode::onClusterState, this);
  held_timer_ = nh_.createWallTimer(
      ros::WallDuration(std::max(options_.decision_inputs_wait_s, 1e-6)),
      [this](const ros::WallTimerEvent&) { decideHeldAnyway("the wait ran out"); }, true, false);
  diagnostics_.setHardwareID(c.rsu_id);
  diagnostics_.add("decisions", this, &RsuNode::diagnose);
  waitForPeers();
  registerWithBridge();
  ROS_INFO_NAMED("startup", "%s: cluster %d [%.0f, %.0f) m, %s, decides every %d step(s), federation %s, I2I %s",
           c.rsu_id.c_str(), c.cluster_index, c.x_start_m, c.x_end_m, c.train ? "train" : "eval",
           options_.decision_period_steps, options_.federation ? "on" : "off", options_.i2i ? "on" : "off");
}

std::string RsuNode::checkpointDir() const {
  return (fs::path(options_.checkpoint_dir) / options_.controller.rsu_id).string();
}

void RsuNode::loadInitialModel() {
  const RsuControllerOptions& c = options_.controller;
  if (c.advice_source == AdviceSource::kRules) {
    ROS_INFO_NAMED("startup", "%s: advice from the rule (exit %.0f m per lane + %.0f m, through traffic out of "
                   "lanes 1..%d, merge advice %s); no weights loaded",
                   c.rsu_id.c_str(), c.rules.exit_distance_per_lane_m, c.rules.exit_margin_m,
                   c.rules.through_keep_out_lanes, c.rules.advise_merge ? "on" : "off");
    return;
  }
  if (!c.train && options_.policy_dir == RANDOM_POLICY)
    ROS_WARN_NAMED("startup", "%s: evaluating an UNTRAINED network (policy_dir:=%s): its advice is random", c.rsu_id.c_str(),
             RANDOM_POLICY);
  if (!c.train && options_.policy_dir != RANDOM_POLICY) {
    // A federated policy is the server's global model; an independent one is per RSU; an RSU
    // with no model of its own (a zone the training did not have) starts from the policy's
    // default model, which tools/ship_policy.py ships beside per-RSU models.
    const fs::path dir(options_.policy_dir);
    const fs::path candidates[] = {dir / "fedserver" / "global_model.palcas", dir / c.rsu_id / "model.palcas",
                                   dir / "default" / "model.palcas"};
    const fs::path* found = nullptr;
    for (const fs::path& f : candidates)
      if (!found && fs::exists(f)) found = &f;
    if (!found)
      throw std::runtime_error("policy_dir '" + options_.policy_dir + "' holds none of " + candidates[0].string() +
                               ", " + candidates[1].string() + ", " + candidates[2].string());
    const fs::path file = *found;
    controller_->loadPolicy(file.string());
    policy_file_ = file.string();
    ROS_INFO_NAMED("startup", "%s: evaluating policy %s", c.rsu_id.c_str(), file.c_str());
    return;
  }
  if (!options_.federation) return;
  federated_model_ = std::make_unique<ControllerModel>(*controller_);
  transport_ = std::make_unique<RosFederationTransport>(nh_, auth_key_.get(), submitted_pub_);
  FederationClientOptions client;
  client.rsu_id = c.rsu_id;
  client.heartbeat_s = options_.federation_heartbeat_s;
  federation_ = std::make_unique<FederationClient>(
      client, *federated_model_, *transport_,
      [this](FederationEvent e, const std::string& message) { onFederationEvent(e, message); });
  if (!ros::service::waitForService(nh_.resolveName(FETCH_MODEL_SERVICE),
                                    ros::Duration(options_.federation_wait_s))) {
    ROS_WARN_NAMED("federation", "%s: federation server not reachable after %.0f s: starting from local weights; "
             "will join when it answers", c.rsu_id.c_str(), options_.federation_wait_s);
    return;
  }
  federation_->join();
}

void RsuNode::waitForPeers() {
  // I2I messages sent before a peer's connection exists are lost; the bridge starts once
  // every RSU registered, so connect to every peer first (up to register_timeout_s).
  const int zones = static_cast<int>(options_.zones_m.size()) - 1;
  if (!options_.i2i || options_.whole_road || zones < 2) return;
  const uint32_t peers = static_cast<uint32_t>(zones - 1);
  // The RSU also hears itself (an intra-process link on the shared topic): peers + 1.
  const uint32_t links = peers + 1;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(options_.register_timeout_s);
  // Every subscriber the master knows of (peers, and a recorder if any) must have connected
  // to this RSU's publisher: counting peers alone, a recorder's link could stand in for a
  // peer's that is still being made, and that peer would miss the first cluster states.
  const std::string topic = cluster_pub_.getTopic();
  auto known_subscribers = [&topic]() -> uint32_t {
    XmlRpc::XmlRpcValue request, response, payload;
    request[0] = ros::this_node::getName();
    if (!ros::master::execute("getSystemState", request, response, payload, false) || payload.size() < 2)
      return 0;
    const XmlRpc::XmlRpcValue& subscribers = payload[1];
    for (int i = 0; i < subscribers.size(); ++i)
      if (static_cast<std::string>(subscribers[i][0]) == topic) return static_cast<uint32_t>(subscribers[i][1].size());
    return 0;
  };
  while (ros::ok() && ros::WallTime::now() < deadline &&
         (cluster_pub_.getNumSubscribers() < std::max(links, known_subscribers()) ||
          cluster_sub_.getNumPublishers() < links))
    ros::WallDuration(0.02).sleep();
  if (cluster_pub_.getNumSubscribers() < links || cluster_sub_.getNumPublishers() < links)
    ROS_WARN_NAMED("i2i", "%s: I2I: %u of %u peers connected after %.0f s; starting anyway (their states "
             "count as unknown until they arrive)", options_.controller.rsu_id.c_str(),
             std::min(cluster_pub_.getNumSubscribers(), cluster_sub_.getNumPublishers()) - 1, peers,
             options_.register_timeout_s);
}

void RsuNode::registerWithBridge() {
  ros::ServiceClient client = nh_.serviceClient<palcas_msgs::RegisterRsu>(REGISTER_RSU_SERVICE);
  if (!client.waitForExistence(ros::Duration(options_.register_timeout_s))) {
    ROS_WARN_NAMED("startup", "%s: bridge's %s not available after %.0f s; answering states as they come",
             options_.controller.rsu_id.c_str(), nh_.resolveName(REGISTER_RSU_SERVICE).c_str(),
             options_.register_timeout_s);
    return;
  }
  // The bridge published its road before opening registration: refuse a zone or lane
  // count that is not on it, naming both (the node ends; its supervisor reports it).
  if (const auto road = common::bridgeRoad(nh_)) checkAgainstRoad(options_, road->zones_m, road->num_lanes);
  // Registering starts the bridge's step 0: make sure its states reach us first.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(options_.register_timeout_s);
  // Its events too: a decision waits for its step's event array (DecisionInputs).
  while (ros::ok() && (states_sub_.getNumPublishers() == 0 || events_sub_.getNumPublishers() == 0) &&
         ros::WallTime::now() < deadline)
    ros::WallDuration(0.02).sleep();
  palcas_msgs::RegisterRsu srv;
  srv.request.rsu_id = options_.controller.rsu_id;
  // Answering only decision steps spares the bridge a round trip on the steps between them
  // (the states still come every step, in order, and are observed).
  srv.request.answer_period_steps = static_cast<std::uint32_t>(options_.decision_period_steps);
  if (!client.call(srv) || !srv.response.accepted) {
    ROS_WARN_NAMED("startup", "%s: registration refused: %s", options_.controller.rsu_id.c_str(),
             srv.response.reason.c_str());
    return;
  }
  answer_decision_steps_only_ = true;
}

void RsuNode::onEvents(const palcas_msgs::VehicleEventArray::ConstPtr& msg) {
  addOutcomes(*msg, outcomes_);
  inputs_.eventsArrived(msg->step);
  decideHeldIfReady();
}

void RsuNode::onClusterState(const palcas_msgs::ClusterState::ConstPtr& msg) {
  if (msg->rsu_id == options_.controller.rsu_id) return;
  // It arrived, whatever the channel makes of it: a lost one is not waited for.
  inputs_.clusterStateArrived(msg->cluster_index, msg->step);
  receiveClusterState(msg);
  decideHeldIfReady();
}

void RsuNode::receiveClusterState(const palcas_msgs::ClusterState::ConstPtr& msg) {
  if (channel_) {
    // I2I over the channel: lost, or held until the step it arrives at (decide() takes it).
    ++i2i_received_;
    const v2x::Delivery d =
        channel_->transmit(v2x::MessageClass::CLUSTER_STATE, msg->rsu_id, options_.controller.rsu_id, msg->step);
    if (d.lost) ++i2i_lost_;
    else i2i_in_flight_.push(msg->step + d.delay_steps, *msg);
    return;
  }
  try {
    peers_.update(msg->cluster_index, msg->rsu_id, msg->density_veh_per_km, msg->header.stamp.toSec());
  } catch (const std::invalid_argument& e) {
    ROS_WARN_THROTTLE_NAMED(5.0, "i2i", "%s: ignored cluster state: %s", options_.controller.rsu_id.c_str(), e.what());
  }
}

void RsuNode::onStates(const palcas_msgs::VehicleStateArray::ConstPtr& msg) {
  const ros::WallTime received = ros::WallTime::now();
  if (first_state_ && msg->num_lanes != options_.controller.num_lanes) {
    ROS_FATAL_NAMED("startup", "%s: the road has %u lanes but rsu/num_lanes is %d (the state size depends on it)",
              options_.controller.rsu_id.c_str(), msg->num_lanes, options_.controller.num_lanes);
    ros::shutdown();
    return;
  }
  if (first_state_ && options_.v2x.enabled) {
    const RsuControllerOptions& c = options_.controller;
    // The centralized baseline is one agent over the whole road, not a radio: no range.
    const double x_m = options_.whole_road ? 0.0 : 0.5 * (c.x_start_m + c.x_end_m);
    v2x::ChannelParams p = options_.v2x;
    if (options_.whole_road) p.rsu_range_m = std::numeric_limits<double>::infinity();
    channel_ = std::make_unique<v2x::Channel>(p, msg->step_length_s);
    uplink_ = std::make_unique<v2x::UplinkView>(*channel_, c.rsu_id, x_m);
    ROS_INFO_NAMED("v2x", "%s: V2X channel on (seed %lu): states %.3f s + U(0, %.3f) s, lost %.1f %%; cluster states %.3f s + "
             "U(0, %.3f) s, lost %.1f %%; range %.1f m from x = %.0f m; states forgotten after %.2f s",
             c.rsu_id.c_str(), static_cast<unsigned long>(p.seed), p.vehicle_state.latency_s, p.vehicle_state.jitter_s,
             100.0 * p.vehicle_state.loss_probability, p.cluster_state.latency_s, p.cluster_state.jitter_s,
             100.0 * p.cluster_state.loss_probability, p.rsu_range_m, x_m, p.max_state_age_s);
  }
  first_state_ = false;
  if (uplink_ && last_state_step_ && msg->step <= *last_state_step_) {
    uplink_->clear();  // a new episode: nothing heard yet, nothing in flight
    i2i_in_flight_.clear();
  }
  last_state_step_ = msg->step;
  if (held_state_) decideHeldAnyway("the bridge sent a later step");  // it did not wait for us
  if (schedule_.decidesAt(msg->step)) {
    decideWhenReady(msg, received);
    return;
  }
  // Unregistered, the bridge does not know our period and waits for every step.
  if (!answer_decision_steps_only_) answerEmpty(*msg, received);
  const bool observe = schedule_.observesBetweenDecisions();
  if (observe || uplink_) {
    try {
      const RoadSnapshot road = heard(*msg);  // the uplink hears every step
      if (observe) controller_->observeStep(road);  // never touches the agent: no join
    } catch (const std::invalid_argument& e) {
      ROS_ERROR_THROTTLE_NAMED(5.0, "decision", "%s: step %lu not observed: %s", options_.controller.rsu_id.c_str(),
                         static_cast<unsigned long>(msg->step), e.what());
    }
  }
}

void RsuNode::answerEmpty(const palcas_msgs::VehicleStateArray& msg, const ros::WallTime& received) {
  palcas_msgs::AdvisoryArray out;
  out.header = msg.header;
  out.step = msg.step;
  out.rsu_id = options_.controller.rsu_id;
  out.i2i_upstream_density_veh_per_km = std::numeric_limits<double>::quiet_NaN();
  out.i2i_downstream_density_veh_per_km = std::numeric_limits<double>::quiet_NaN();
  out.decision_ms = static_cast<float>((ros::WallTime::now() - received).toSec() * 1e3);
  publishAdvisories(out);
}

void RsuNode::publishAdvisories(palcas_msgs::AdvisoryArray& out) {
  common::signMessage(out, auth_key_.get());
  advisories_pub_.publish(out);
}

void RsuNode::decideWhenReady(const palcas_msgs::VehicleStateArray::ConstPtr& msg, const ros::WallTime& received) {
  if (inputs_.ready(msg->step)) {
    decide(*msg, received);
    return;
  }
  ++decisions_held_;
  held_state_ = msg;
  held_received_ = received;
  held_timer_.stop();
  held_timer_.setPeriod(ros::WallDuration(std::max(options_.decision_inputs_wait_s, 1e-6)));
  held_timer_.start();
}

void RsuNode::decideHeldIfReady() {
  if (!held_state_ || !inputs_.ready(held_state_->step)) return;
  held_timer_.stop();
  const palcas_msgs::VehicleStateArray::ConstPtr msg = std::move(held_state_);
  held_state_.reset();
  decide(*msg, held_received_);
}

void RsuNode::decideHeldAnyway(const char* why) {
  if (!held_state_) return;
  held_timer_.stop();
  const palcas_msgs::VehicleStateArray::ConstPtr msg = std::move(held_state_);
  held_state_.reset();
  std::string missing;
  for (const std::string& m : inputs_.missing(msg->step)) missing += (missing.empty() ? "" : ", ") + m;
  ++decisions_without_inputs_;
  std::string down;
  for (int k : inputs_.gaveUp(msg->step)) down += " " + std::to_string(k);
  ROS_WARN_THROTTLE_NAMED(10.0, "decision", "%s: step %lu decided without %s (%s)%s", options_.controller.rsu_id.c_str(),
                          static_cast<unsigned long>(msg->step), missing.c_str(), why,
                          down.empty() ? "" : ("; not waiting again for cluster(s)" + down + " until heard").c_str());
  decide(*msg, held_received_);
}

void RsuNode::decide(const palcas_msgs::VehicleStateArray& msg, const ros::WallTime& received) {
  const double now_s = msg.header.stamp.toSec();
  schedule_.finishLearning();  // rethrows what learn() threw; the controller is ours again
  GlobalDensities global;
  DecisionOutput decision;
  try {
    decision = advise(msg, now_s, global);
  } catch (const std::invalid_argument& e) {
    // A malformed state: answer empty (CAVs keep their commands), say why, keep going.
    ROS_ERROR_THROTTLE_NAMED(5.0, "decision", "%s: step %lu not decided: %s", options_.controller.rsu_id.c_str(),
                       static_cast<unsigned long>(msg.step), e.what());
    answerEmpty(msg, received);
    return;
  }
  const float decision_ms = publishDecision(msg, decision, global, received);
  logDecisionDetail(msg.step, decision, global, decision_ms);
  const AfterDecision after = schedule_.decided();
  if (after.learn_inline) controller_->learn();  // after publishing: the bridge need not wait
  logDecision(msg.step, decision_ms);
  if (after.federation_tick && federation_) federation_->onDecision(now_s);
  if (after.checkpoint) checkpoint();
  publishStatus(msg, now_s, decision_ms);
  // Last: federation and checkpoints above saw the model as the decision used it.
  if (after.learn_on_thread) schedule_.startLearning([this] { controller_->learn(); });
}

DecisionOutput RsuNode::advise(const palcas_msgs::VehicleStateArray& msg, double now_s, GlobalDensities& global) {
  const RsuControllerOptions& c = options_.controller;
  const RoadSnapshot snapshot = heard(msg);
  for (const palcas_msgs::ClusterState& m : i2i_in_flight_.release(msg.step)) {
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
  // Evaluating, membership comes from the states alone, so a decision need not wait for its
  // step's events (DecisionInputs): the bridge drops a removed vehicle from the states of the
  // step that removes it, and over the V2X channel the events would race the delayed states
  // and decide a stale vehicle's membership by arrival order. Training keeps them: they close
  // its transitions with their terminal rewards.
  const VehicleOutcomes none;
  DecisionOutput decision = controller_->advise(snapshot, msg.step, now_s, global, c.train ? outcomes_ : none);
  outcomes_.clear();
  last_own_density_ = decision.cluster.density_veh_per_km;
  return decision;
}

float RsuNode::publishDecision(const palcas_msgs::VehicleStateArray& msg, const DecisionOutput& decision,
                               const GlobalDensities& global, const ros::WallTime& received) {
  palcas_msgs::AdvisoryArray out;
  out.header = msg.header;
  out.step = msg.step;
  out.rsu_id = options_.controller.rsu_id;
  out.i2i_upstream_density_veh_per_km = global.upstream;
  out.i2i_downstream_density_veh_per_km = global.downstream;
  for (const CavAdvisory& a : decision.advisories) out.advisories.push_back(toMsg(a, decision.model_version));
  out.decision_ms = static_cast<float>((ros::WallTime::now() - received).toSec() * 1e3);
  // The cluster state first: the peers then have it before the bridge, released by our
  // answer, runs the steps to the next decision.
  if (options_.i2i) cluster_pub_.publish(toMsg(decision.cluster, options_.controller, msg.step, decision.time_s));
  publishAdvisories(out);
  return out.decision_ms;
}

void RsuNode::logDecisionDetail(std::uint64_t step, const DecisionOutput& decision, const GlobalDensities& global,
                                float decision_ms) const {
  const RsuControllerStats stats = controller_->stats();
  std::string advice;
  for (const CavAdvisory& a : decision.advisories) {
    advice += " " + a.vehicle_id + ":" + actionName(a.decision.action);
    if (a.decision.action == Action::kAccelerate) {
      char accel[16];
      std::snprintf(accel, sizeof accel, "(%+.2f)", a.decision.accel_mps2);
      advice += accel;
    }
  }
  ROS_DEBUG_NAMED("decision", "%s: step %lu: %u members, density %.1f veh/km (I2I up %.1f, down %.1f), model v%u, "
                  "%.2f ms;%s", options_.controller.rsu_id.c_str(), static_cast<unsigned long>(step), stats.member_count,
                  decision.cluster.density_veh_per_km, global.upstream, global.downstream, decision.model_version,
                  decision_ms, advice.c_str());
}

void RsuNode::logDecision(std::uint64_t step, float decision_ms) {
  try {
    learning_log_.addDecision(step, controller_->stats(), decision_ms);
  } catch (const std::runtime_error& e) {
    ROS_ERROR_THROTTLE_NAMED(60.0, "learning", "%s: %s", options_.controller.rsu_id.c_str(), e.what());
  }
}

void RsuNode::publishStatus(const palcas_msgs::VehicleStateArray& msg, double now_s, float decision_ms) {
  const RsuControllerOptions& c = options_.controller;
  StatusContext context;
  context.header = msg.header;
  context.step = msg.step;
  context.rsu_id = c.rsu_id;
  context.train = c.train;
  context.decision_ms = decision_ms;
  context.stale_peers = static_cast<uint32_t>(peers_.stalePeers(now_s).size());
  context.federation_reachable = federation_ && federation_->reachable();
  const palcas_msgs::RsuStatus status = toStatusMsg(controller_->stats(), context);
  status_pub_.publish(status);
  last_status_ = status;
  recent_decision_ms_.add(decision_ms);
  diagnostics_.update();
}

void RsuNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& s) {
  RsuHealthFacts f;
  f.last = last_status_;
  f.decided = schedule_.decisions() > 0;
  f.policy = policy_file_;
  f.i2i = options_.i2i && !options_.whole_road;
  f.federation = options_.federation;
  f.decision_p99_ms = recent_decision_ms_.percentile(99.0);
  describeRsu(f, s);
  s.add("decisions held for their events / neighbours' cluster states", decisions_held_);
  s.add("decisions taken without them (wait ran out)", decisions_without_inputs_);
  std::string down;
  for (int k : inputs_.presumedDown()) down += (down.empty() ? "" : " ") + std::to_string(k);
  s.add("neighbours presumed down (not waited for)", down.empty() ? "none" : down);
  addChannelCounts(s);
}

void RsuNode::onFederationEvent(FederationEvent event, const std::string& message) {
  // One log call per kind, so each kind is throttled on its own.
  switch (event) {
    case FederationEvent::kUnreachable: ROS_WARN_THROTTLE_NAMED(10.0, "federation", "%s", message.c_str()); break;
    case FederationEvent::kModelRefused: ROS_ERROR_THROTTLE_NAMED(10.0, "federation", "%s", message.c_str()); break;
    case FederationEvent::kSubmitRefused: ROS_WARN_THROTTLE_NAMED(10.0, "federation", "%s", message.c_str()); break;
    case FederationEvent::kSubmitted: ROS_INFO_NAMED("federation", "%s", message.c_str()); break;
    case FederationEvent::kLoaded:
      model_pub_.publish(common::toWeightsMsg(controller_->exportModel(), options_.controller.rsu_id,
                                              federation_->openRound(), controller_->modelVersion(), 0));
      ROS_INFO_NAMED("federation", "%s", message.c_str());
      break;
  }
}

void RsuNode::checkpoint() {
  try {
    controller_->saveCheckpoint(checkpointDir());
    controller_->agent().saveModel((fs::path(checkpointDir()) / "model.palcas").string());
  } catch (const std::exception& e) {
    ROS_ERROR_NAMED("checkpoint", "%s: checkpoint failed: %s", options_.controller.rsu_id.c_str(), e.what());
  }
}

void RsuNode::endEpisodeLog() {
  try {
    learning_log_.endEpisode(controller_->stats());
  } catch (const std::runtime_error& e) {
    ROS_ERROR_NAMED("learning", "%s: %s", options_.controller.rsu_id.c_str(), e.what());
  }
}

RoadSnapshot RsuNode::heard(const palcas_msgs::VehicleStateArray& msg) {
  RoadSnapshot truth = toSnapshot(msg);
  if (!uplink_) return truth;
  return uplink_->receive(truth, msg.step);
}

void RsuNode::addChannelCounts(diagnostic_updater::DiagnosticStatusWrapper& s) const {
  if (!uplink_) return;
  const v2x::UplinkCounts& n = uplink_->counts();
  s.add("V2X vehicle states sent", n.sent);
  s.add("V2X vehicle states lost", n.lost);
  s.add("V2X vehicle states out of range", n.out_of_range);
  s.add("V2X vehicles forgotten (state too old)", n.forgotten);
  s.add("V2X mean age of the states used [s]", n.used ? n.used_age_sum_s / static_cast<double>(n.used) : 0.0);
  s.add("V2X cluster states lost", i2i_lost_);
  s.add("V2X cluster states received", i2i_received_);
}

void RsuNode::shutdown() {
  schedule_.finishLearning();
  endEpisodeLog();
  if (options_.controller.train && !options_.checkpoint_dir.empty()) {
    checkpoint();
    ROS_INFO_NAMED("checkpoint", "%s: checkpoint written to %s", options_.controller.rsu_id.c_str(), checkpointDir().c_str());
  }
}

}  // namespace palcas::rsu
