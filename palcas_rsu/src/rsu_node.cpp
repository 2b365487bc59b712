#include "palcas_rsu/rsu_node.h"

#include <ros/master.h>

#include <palcas_common/bridge_road.h>
#include <palcas_common/message_auth.h>
#include <palcas_common/model_weights.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/RegisterRsu.h>
#include <palcas_msgs/RsuStatus.h>
#include <std_msgs/UInt32.h>


#include "palcas_rsu/federation_transport.h"
#include "palcas_rsu/msg_conversion.h"
#include "palcas_rsu/topics.h"

namespace palcas::rsu {

namespace {

/// Subscribers of `topic` the master knows of. A publisher's own count covers only the
/// links already made, so a wait for "every subscriber connected" needs this too: counting
/// links alone, a recorder's could stand in for one still being made.
uint32_t subscribersKnownToMaster(const std::string& topic) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", request, response, payload, false) || payload.size() < 2) return 0;
  const XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i)
    if (static_cast<std::string>(subscribers[i][0]) == topic) return static_cast<uint32_t>(subscribers[i][1].size());
  return 0;
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
    : nh_(nh), private_nh_(private_nh),
      decider_(std::make_unique<RsuDecider>(loadOptionsOnTheRoad(nh_, private_nh_))),
      options_(decider_->options()),
      auth_key_(common::loadMessageKey(options_.auth_key_file)),
      inputs_(decisionInputsOf(options_)) {
  const RsuControllerOptions& c = options_.controller;
  // Federation traffic, latched and once per round: what this RSU sent and what it holds
  // after loading the global model (for tests, bags and debugging).
  submitted_pub_ = nh_.advertise<palcas_msgs::ModelWeights>(SUBMITTED_WEIGHTS_TOPIC, 1, true);
  model_pub_ = nh_.advertise<palcas_msgs::ModelWeights>(MODEL_TOPIC, 1, true);
  if (decider_->wantsFederation()) startFederation();
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

void RsuNode::startFederation() {
  const bool reachable =
      ros::service::waitForService(nh_.resolveName(FETCH_MODEL_SERVICE), ros::Duration(options_.federation_wait_s));
  if (!reachable)
    ROS_WARN_NAMED("federation", "%s: federation server not reachable after %.0f s: starting from local weights; "
             "will join when it answers", options_.controller.rsu_id.c_str(), options_.federation_wait_s);
  decider_->startFederation(
      std::make_unique<RosFederationTransport>(nh_, auth_key_.get(), submitted_pub_), reachable,
      [this](FederationEvent e, const std::string& message) { logFederationEvent("", e, message); },
      [this](const palcas_msgs::ModelWeights& model) { model_pub_.publish(model); });
  // A waiting RSU fetches when the server says a newer model is there, not every decision.
  version_sub_ = nh_.subscribe<std_msgs::UInt32>(
      GLOBAL_MODEL_VERSION_TOPIC, 1, [this](const std_msgs::UInt32::ConstPtr& v) { decider_->announceGlobalVersion(v->data); });
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
  // to this RSU's publisher, or a peer whose link is still being made misses the first
  // cluster states.
  while (ros::ok() && ros::WallTime::now() < deadline &&
         (cluster_pub_.getNumSubscribers() < std::max(links, subscribersKnownToMaster(cluster_pub_.getTopic())) ||
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
  // And our answers must reach the bridge: one published before its link to us is made is
  // lost, and the bridge waits out its lockstep deadline for it (the journal, 2026-11-29).
  auto answers_connected = [this] {
    return advisories_pub_.getNumSubscribers() >= std::max(1u, subscribersKnownToMaster(advisories_pub_.getTopic()));
  };
  while (ros::ok() && (states_sub_.getNumPublishers() == 0 || events_sub_.getNumPublishers() == 0 ||
                       !answers_connected()) &&
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
  decider_->onEvents(*msg);
  inputs_.eventsArrived(msg->step);
  decideHeldIfReady();
}

void RsuNode::onClusterState(const palcas_msgs::ClusterState::ConstPtr& msg) {
  if (msg->rsu_id == options_.controller.rsu_id) return;
  // It arrived, whatever the channel makes of it: a lost one is not waited for.
  inputs_.clusterStateArrived(msg->cluster_index, msg->step);
  std::string why;
  if (!decider_->onClusterState(*msg, &why))
    ROS_WARN_THROTTLE_NAMED(5.0, "i2i", "%s: ignored cluster state: %s", options_.controller.rsu_id.c_str(), why.c_str());
  decideHeldIfReady();
}

void RsuNode::onStates(const palcas_msgs::VehicleStateArray::ConstPtr& msg) {
  const RsuDecider::Clock::time_point received = RsuDecider::Clock::now();
  if (held_state_) decideHeldAnyway("the bridge sent a later step");  // it did not wait for us
  bool decision_step = false;
  try {
    decision_step = decider_->onStates(*msg);
  } catch (const std::invalid_argument& e) {
    ROS_ERROR_THROTTLE_NAMED(5.0, "decision", "%s: step %lu not observed: %s", options_.controller.rsu_id.c_str(),
                       static_cast<unsigned long>(msg->step), e.what());
  } catch (const std::runtime_error& e) {
    ROS_FATAL_NAMED("startup", "%s", e.what());  // a road this RSU cannot serve
    ros::shutdown();
    return;
  }
  if (decision_step) {
    decideWhenReady(msg, received);
    return;
  }
  // Unregistered, the bridge does not know our period and waits for every step.
  if (!answer_decision_steps_only_) answerEmpty(*msg, received);
}

void RsuNode::answerEmpty(const palcas_msgs::VehicleStateArray& msg, RsuDecider::Clock::time_point received) {
  palcas_msgs::AdvisoryArray out = decider_->emptyAnswer(msg, received);
  publishAdvisories(out);
}

void RsuNode::publishAdvisories(palcas_msgs::AdvisoryArray& out) {
  common::signMessage(out, auth_key_.get());
  advisories_pub_.publish(out);
}

void RsuNode::decideWhenReady(const palcas_msgs::VehicleStateArray::ConstPtr& msg,
                              RsuDecider::Clock::time_point received) {
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

void RsuNode::decide(const palcas_msgs::VehicleStateArray& msg, RsuDecider::Clock::time_point received) {
  RsuDecision decision = decider_->decide(msg, received);
  if (!decision.decided)
    ROS_ERROR_THROTTLE_NAMED(5.0, "decision", "%s: step %lu not decided: %s", options_.controller.rsu_id.c_str(),
                       static_cast<unsigned long>(msg.step), decision.error.c_str());
  // The cluster state first: the peers then have it before the bridge, released by our
  // answer, runs the steps to the next decision.
  if (decision.cluster_state) cluster_pub_.publish(*decision.cluster_state);
  publishAdvisories(decision.advisories);
  if (!decision.decided) return;
  ROS_DEBUG_NAMED("decision", "%s", describeDecision(decision, decider_->controller().stats().member_count).c_str());
  last_status_ = decider_->afterPublished(msg, decision);
  status_pub_.publish(last_status_);
  recent_decision_ms_.add(decision.advisories.decision_ms);
  diagnostics_.update();
}

void RsuNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& s) {
  RsuHealthFacts f;
  f.last = last_status_;
  f.decided = decider_->schedule().decisions() > 0;
  f.policy = decider_->policyFile();
  f.i2i = options_.i2i && !options_.whole_road;
  f.federation = options_.federation;
  f.decision_p99_ms = recent_decision_ms_.percentile(99.0);
  describeRsu(f, s);
  s.add("decisions held for their events / neighbours' cluster states", decisions_held_);
  s.add("decisions taken without them (wait ran out)", decisions_without_inputs_);
  std::string down;
  for (int k : inputs_.presumedDown()) down += (down.empty() ? "" : " ") + std::to_string(k);
  s.add("neighbours presumed down (not waited for)", down.empty() ? "none" : down);
  addChannelCounts(*decider_, s);
}

void RsuNode::shutdown() {
  const std::string written = decider_->shutdown();
  if (!written.empty())
    ROS_INFO_NAMED("checkpoint", "%s: checkpoint written to %s", options_.controller.rsu_id.c_str(), written.c_str());
}

}  // namespace palcas::rsu
