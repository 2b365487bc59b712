#include "palcas_sumo_bridge/inprocess_rsus.h"

#include <palcas_msgs/ClusterState.h>
#include <palcas_msgs/ModelWeights.h>
#include <palcas_msgs/RsuStatus.h>
#include <palcas_rsu/federation_transport.h>
#include <palcas_rsu/rsu_options.h>
#include <palcas_rsu/topics.h>
#include <std_msgs/UInt32.h>

#include <stdexcept>

namespace palcas::bridge {

InProcessRsus::InProcessRsus(ros::NodeHandle nh, const std::vector<std::string>& rsu_ids,
                             const std::vector<double>& zones_m, int num_lanes, const auth::MessageKey* key) {
  if (rsu_ids.empty()) throw std::invalid_argument("~inprocess_rsus is true but ~expected_rsus lists no RSU");
  ros::NodeHandle fedserver(nh, "fedserver");
  for (const std::string& id : rsu_ids) {
    Rsu r;
    rsu::RsuNodeOptions o;
    try {
      o = rsu::loadRsuNodeOptions(ros::NodeHandle(nh, id + "/rsu"));
      if (o.controller.rsu_id != id)
        throw std::invalid_argument("rsu/rsu_id is '" + o.controller.rsu_id + "', not '" + id + "'");
      if (rsu::takesFromBridgeRoad(o)) rsu::adoptBridgeRoad(o, zones_m, num_lanes);
      else rsu::checkAgainstRoad(o, zones_m, num_lanes);
      r.decider = std::make_unique<rsu::RsuDecider>(o);
    } catch (const std::exception& e) {
      throw std::runtime_error("in-process RSU '" + id + "' (parameters under " + nh.resolveName(id + "/rsu") +
                               "): " + e.what());
    }
    ros::NodeHandle own(nh, id);
    r.status_pub = own.advertise<palcas_msgs::RsuStatus>(rsu::RSU_STATUS_TOPIC, 10);
    r.cluster_pub = nh.advertise<palcas_msgs::ClusterState>(rsu::CLUSTER_STATES_TOPIC, 10);
    r.submitted_pub = own.advertise<palcas_msgs::ModelWeights>(rsu::SUBMITTED_WEIGHTS_TOPIC, 1, true);
    r.model_pub = own.advertise<palcas_msgs::ModelWeights>(rsu::MODEL_TOPIC, 1, true);
    if (r.decider->wantsFederation()) {
      const bool reachable = ros::service::waitForService(fedserver.resolveName(rsu::FETCH_MODEL_SERVICE),
                                                          ros::Duration(o.federation_wait_s));
      if (!reachable)
        ROS_WARN_NAMED("federation", "%s (in process): federation server not reachable after %.0f s: starting from "
                       "local weights; will join when it answers", id.c_str(), o.federation_wait_s);
      ros::Publisher model_pub = r.model_pub;
      r.decider->startFederation(
          std::make_unique<rsu::RosFederationTransport>(fedserver, key, r.submitted_pub), reachable,
          [](FederationEvent e, const std::string& message) { rsu::logFederationEvent("in process: ", e, message); },
          [model_pub](const palcas_msgs::ModelWeights& m) { model_pub.publish(m); });
    }
    const rsu::RsuControllerOptions& c = r.decider->options().controller;
    ROS_INFO_NAMED("startup", "%s (in process): cluster %d [%.0f, %.0f) m, %s, decides every %d step(s), "
                   "federation %s, I2I %s", id.c_str(), c.cluster_index, c.x_start_m, c.x_end_m,
                   c.train ? "train" : "eval", o.decision_period_steps, o.federation ? "on" : "off",
                   o.i2i ? "on" : "off");
    rsus_.push_back(std::move(r));
  }
  // A waiting RSU fetches when the server says a newer model is there, not every decision
  // (callbacks run in the bridge's receive(), every step).
  version_sub_ = fedserver.subscribe<std_msgs::UInt32>(
      rsu::GLOBAL_MODEL_VERSION_TOPIC, 1, [this](const std_msgs::UInt32::ConstPtr& v) {
        for (Rsu& r : rsus_) r.decider->announceGlobalVersion(v->data);
      });
}

std::vector<std::pair<std::string, int>> InProcessRsus::decisionPeriods() const {
  std::vector<std::pair<std::string, int>> out;
  for (const Rsu& r : rsus_) out.emplace_back(r.decider->rsuId(), r.decider->options().decision_period_steps);
  return out;
}

std::vector<palcas_msgs::AdvisoryArray> InProcessRsus::step(const palcas_msgs::VehicleStateArray& states,
                                                             const palcas_msgs::VehicleEventArray* events) {
  std::vector<palcas_msgs::AdvisoryArray> answers;
  std::vector<std::pair<Rsu*, rsu::RsuDecision>> decided;
  for (Rsu& r : rsus_) {
    const auto received = rsu::RsuDecider::Clock::now();
    if (events) r.decider->onEvents(*events);
    bool decision_step = false;
    try {
      decision_step = r.decider->onStates(states);
    } catch (const std::invalid_argument& e) {
      ROS_ERROR_THROTTLE_NAMED(5.0, "decision", "%s (in process): step %lu not observed: %s", r.decider->rsuId().c_str(),
                               static_cast<unsigned long>(states.step), e.what());
    }
    if (!decision_step) continue;
    rsu::RsuDecision d = r.decider->decide(states, received);
    if (!d.decided)
      ROS_ERROR_THROTTLE_NAMED(5.0, "decision", "%s (in process): step %lu not decided: %s",
                               r.decider->rsuId().c_str(), static_cast<unsigned long>(states.step), d.error.c_str());
    decided.emplace_back(&r, std::move(d));
  }
  // The cluster states after every decision of the step, as over ROS: a decision at a step
  // uses its peers' states of earlier steps only, whatever the arrival order.
  for (const auto& [from, d] : decided) {
    if (!d.cluster_state) continue;
    from->cluster_pub.publish(*d.cluster_state);
    for (Rsu& to : rsus_) {
      if (&to == from || !to.decider->options().i2i) continue;
      std::string why;
      if (!to.decider->onClusterState(*d.cluster_state, &why) && !why.empty())
        ROS_WARN_THROTTLE_NAMED(5.0, "i2i", "%s (in process): ignored cluster state: %s", to.decider->rsuId().c_str(),
                                why.c_str());
    }
  }
  for (auto& [r, d] : decided) {
    if (d.decided) r->status_pub.publish(r->decider->afterPublished(states, d));
    answers.push_back(std::move(d.advisories));
  }
  return answers;
}

void InProcessRsus::shutdown() {
  for (Rsu& r : rsus_) {
    const std::string written = r.decider->shutdown();
    if (!written.empty())
      ROS_INFO_NAMED("checkpoint", "%s (in process): checkpoint written to %s", r.decider->rsuId().c_str(),
                     written.c_str());
  }
}

}  // namespace palcas::bridge
