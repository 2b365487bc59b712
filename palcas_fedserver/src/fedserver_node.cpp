#include "palcas_fedserver/fedserver_node.h"

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <palcas_msgs/FederationStatus.h>
#include <std_msgs/UInt32.h>

#include <palcas_core/learning/pdqn_agent.h>
#include <palcas_core/state/state_layout.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

#include <palcas_common/bridge_road.h>
#include <palcas_common/message_auth.h>
#include <palcas_common/model_weights.h>
#include "palcas_fedserver/topics.h"

namespace palcas::fedserver {

FedServerNode::FedServerNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), private_nh_(private_nh), options_(loadFedServerOptions(private_nh_)),
      server_(options_.federation), auth_key_(common::loadMessageKey(options_.auth_key_file)) {
  if (options_.learning.state_size == 0) takeStateSizeFromTheRoad();
  initializeModel();
  status_pub_ = nh_.advertise<palcas_msgs::FederationStatus>(FEDERATION_STATUS_TOPIC, 1, true);
  version_pub_ = nh_.advertise<std_msgs::UInt32>(GLOBAL_MODEL_VERSION_TOPIC, 1, true);
  submit_srv_ = nh_.advertiseService(SUBMIT_WEIGHTS_SERVICE, &FedServerNode::onSubmit, this);
  fetch_srv_ = nh_.advertiseService(FETCH_GLOBAL_MODEL_SERVICE, &FedServerNode::onFetch, this);
  poll_timer_ = nh_.createTimer(ros::Duration(options_.poll_period_s), &FedServerNode::onTimer, this);
  std_msgs::UInt32 version;
  version.data = server_.globalVersion();
  version_pub_.publish(version);
  publishStatus();
  round_opened_s_ = nowS();
  diagnostics_.setHardwareID("palcas_fedserver");
  diagnostics_.add("federation", this, &FedServerNode::diagnose);
  const FederationOptions& f = options_.federation;
  ROS_INFO_NAMED("startup", "palcas fedserver: round %u, global version %u (%zu values, layout %s), %zu RSU(s) "
           "expected, quorum %zu, deadline %.1f s, liveness %.1f s, checkpoints %s",
           server_.round(), server_.globalVersion(), server_.globalModel()->values.size(),
           server_.globalModel()->layout_id.c_str(), f.expected_rsus.size(), f.effectiveQuorum(),
           f.round_deadline_s, f.liveness_timeout_s,
           options_.checkpoint_dir.empty() ? "off" : options_.checkpoint_dir.c_str());
  if (auth_key_)
    ROS_INFO_NAMED("startup", "palcas fedserver: submissions authenticated with key %s (fingerprint %s)",
             options_.auth_key_file.c_str(), auth_key_->fingerprint().c_str());
  else
    ROS_WARN_NAMED("startup", "palcas fedserver: ~auth_key_file not set: submissions are NOT authenticated");
}

void FedServerNode::takeStateSizeFromTheRoad() {
  // ~learning/state_size 0: 40 + the lane count of the bridge's road, as every RSU does.
  const auto road = common::waitForBridgeRoad(nh_, options_.road_wait_s);
  if (!road)
    throw std::runtime_error(std::string("~learning/state_size is 0 (from the road) but the bridge published no ") +
                             common::ROAD_LANES_PARAM + " within ~road_wait_s = " +
                             std::to_string(options_.road_wait_s) + " s");
  options_.learning.state_size = StateLayout(road->num_lanes).size();
  ROS_INFO_NAMED("startup", "palcas fedserver: state size %d (%d + the road's %d lanes)", options_.learning.state_size,
           LANE_INDEPENDENT_FEATURE_COUNT, road->num_lanes);
}

void FedServerNode::initializeModel() {
  // The agent is built only for its weights and layout: every RSU builds the same agent
  // from the same learning config and seed, so all start from this model.
  const PdqnAgent agent(options_.learning);
  const bool have_checkpoint =
      std::ifstream(options_.checkpoint_dir + "/" + FederationServer::STATE_FILE).good();
  if (!options_.resume || !have_checkpoint) {
    // A training that stopped before the first round closed has nothing to resume: start
    // from the initial model (the RSUs do the same), and say so.
    if (options_.resume)
      ROS_INFO_NAMED("checkpoint", "palcas fedserver: no checkpoint in %s yet; starting afresh",
               options_.checkpoint_dir.c_str());
    server_.initialize(agent.exportModel());
    return;
  }
  server_.loadCheckpoint(options_.checkpoint_dir);
  if (server_.globalModel()->layout_id != agent.layoutId())
    throw std::runtime_error("checkpoint " + options_.checkpoint_dir + " holds layout '" +
                             server_.globalModel()->layout_id + "', ~learning/* gives '" +
                             agent.layoutId() + "'");
  ROS_INFO_NAMED("checkpoint", "palcas fedserver: resumed from %s", options_.checkpoint_dir.c_str());
}

bool FedServerNode::onSubmit(palcas_msgs::SubmitWeights::Request& req,
                             palcas_msgs::SubmitWeights::Response& res) {
  const palcas_msgs::ModelWeights& w = req.weights;
  const auth::Verdict verdict = common::verifyMessage(w, auth_key_.get());
  const SubmitResult r =
      verdict != auth::Verdict::kAuthentic
          ? server_.refuse(Rejection::kUnauthenticated,
                           std::string(auth::verdictName(verdict)) + " on a model naming '" +
                               w.rsu_id + "'")
          : server_.submit(w.rsu_id, w.round, w.model_version, common::toModelBlob(w),
                           w.sample_count, nowS());
  ROS_DEBUG_NAMED("submissions", "palcas fedserver: submission from '%s': round %u, model v%u, %zu values, n_k %lu, "
                  "%s: %s", w.rsu_id.c_str(), w.round, w.model_version, w.values.size(),
                  static_cast<unsigned long>(w.sample_count), auth::verdictName(verdict), r.accepted ? "accepted" : r.reason.c_str());
  if (r.accepted) {
    ROS_INFO_NAMED("rounds", "palcas fedserver: round %u: model from '%s' (n_k %lu)", w.round, w.rsu_id.c_str(),
             static_cast<unsigned long>(w.sample_count));
    pollAndReport();  // the last live RSU closes the round at once, not at the next tick
  } else {
    ROS_WARN_NAMED("rounds", "palcas fedserver: refused a model from '%s': %s", w.rsu_id.c_str(), r.reason.c_str());
  }
  res.accepted = r.accepted;
  res.reason = r.reason;
  res.round = server_.round();
  res.global_version = server_.globalVersion();
  publishStatus();
  return true;
}

bool FedServerNode::onFetch(palcas_msgs::FetchGlobalModel::Request& req,
                            palcas_msgs::FetchGlobalModel::Response& res) {
  const uint64_t unknown_before = server_.status().fetch_unknown_rsu;
  const FetchResult r = server_.fetch(req.rsu_id, req.min_version, nowS());
  res.available = r.available;
  res.reason = r.reason;
  // The core keeps the global model finite (validated at start, after every average and
  // on resume), so what is served here is finite.
  if (r.available) {
    res.weights = common::toWeightsMsg(*r.model, SERVER_ID, r.round, r.global_version, 0);
    common::signMessage(res.weights, auth_key_.get());
  }
  const std::string answer =
      r.available ? "global v" + std::to_string(r.global_version) + " of round " + std::to_string(r.round) : r.reason;
  ROS_DEBUG_NAMED("fetches", "palcas fedserver: fetch by '%s' (wants v%u): %s", req.rsu_id.c_str(), req.min_version,
                  answer.c_str());
  if (server_.status().fetch_unknown_rsu != unknown_before) {
    ROS_WARN_NAMED("rounds", "palcas fedserver: %s", r.reason.c_str());
    publishStatus();
  }
  return true;
}

void FedServerNode::onTimer(const ros::TimerEvent&) {
  pollAndReport();
  diagnostics_.update();
}

void FedServerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& s) {
  FederationFacts f;
  f.status = server_.status();
  f.expected_rsus = options_.federation.expected_rsus.size();
  f.open_round_age_s = nowS() - round_opened_s_;
  std::uint64_t rejected = 0;
  for (const auto& [reason, n] : f.status.rejected_by_reason) rejected += n;
  f.rejected_new = rejected >= rejected_reported_ ? rejected - rejected_reported_ : rejected;
  rejected_reported_ = rejected;
  describeFederation(f, s);
}

void describeFederation(const FederationFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s) {
  using diagnostic_msgs::DiagnosticStatus;
  const FederationStatus& st = f.status;
  if (st.failed_aggregations > 0)
    s.summaryf(DiagnosticStatus::ERROR, "%lu round(s) averaged to a non-finite model (global model kept)",
               static_cast<unsigned long>(st.failed_aggregations));
  else if (f.rejected_new > 0)
    s.summaryf(DiagnosticStatus::WARN, "%lu submission(s) refused since the last report",
               static_cast<unsigned long>(f.rejected_new));
  else if (st.fetch_unknown_rsu > 0)
    s.summaryf(DiagnosticStatus::WARN, "%lu fetch(es) from RSUs not expected",
               static_cast<unsigned long>(st.fetch_unknown_rsu));
  else
    s.summaryf(DiagnosticStatus::OK, "round %u open %.0f s, %zu of %zu submitted; global version %u", st.round,
               f.open_round_age_s, st.submitted.size(), f.expected_rsus, st.global_version);
  s.add("round", st.round);
  s.addf("open round age [s]", "%.1f", f.open_round_age_s);
  std::string submitted;
  for (const std::string& id : st.submitted) submitted += (submitted.empty() ? "" : ", ") + id;
  s.add("submitted this round", submitted.empty() ? std::string("none") : submitted);
  s.add("global version", st.global_version);
  s.add("rounds closed", st.rounds_closed);
  s.addf("last round [s]", "%.2f", st.last_round_s);
  s.add("failed aggregations", st.failed_aggregations);
  for (const auto& [reason, n] : st.rejected_by_reason) s.add("refused: " + reason, n);
  s.add("fetches from unknown RSUs", st.fetch_unknown_rsu);
}

void FedServerNode::pollAndReport() {
  if (!server_.poll(nowS())) return;
  const RoundReport& rr = server_.lastRound();
  std::ostringstream counts;
  for (const auto& [id, n] : rr.sample_counts) counts << ' ' << id << '=' << n;
  if (rr.aggregated)
    ROS_INFO_NAMED("rounds", "palcas fedserver: round %u closed (%s): global version %u, n_k:%s, %.2f s, %lu bytes in",
             rr.round, rr.on_deadline ? "deadline with quorum" : "every live RSU submitted",
             rr.global_version, counts.str().c_str(), rr.duration_s,
             static_cast<unsigned long>(rr.bytes_in));
  else
    ROS_ERROR_NAMED("rounds", "palcas fedserver: round %u closed but its average is not finite: global version "
              "%u kept, n_k:%s", rr.round, rr.global_version, counts.str().c_str());
  if (!options_.checkpoint_dir.empty()) {
    try {
      server_.saveCheckpoint(options_.checkpoint_dir);
    } catch (const std::runtime_error& e) {  // keep federating; the next round retries
      ROS_ERROR_NAMED("checkpoint", "palcas fedserver: checkpoint failed: %s", e.what());
    }
  }
  std_msgs::UInt32 version;
  version.data = server_.globalVersion();
  version_pub_.publish(version);
  publishStatus();
  round_opened_s_ = nowS();
}

void FedServerNode::publishStatus() {
  const FederationStatus s = server_.status();
  palcas_msgs::FederationStatus msg;
  msg.header.stamp = ros::Time::now();
  msg.round = s.round;
  msg.global_version = s.global_version;
  msg.submitted = s.submitted;
  for (const auto& [reason, count] : s.rejected_by_reason) {
    msg.rejection_reasons.push_back(reason);
    msg.rejections.push_back(count);
  }
  msg.fetch_unknown_rsu = s.fetch_unknown_rsu;
  msg.accepted_total = s.accepted_total;
  msg.rounds_closed = s.rounds_closed;
  msg.failed_aggregations = s.failed_aggregations;
  msg.last_round_s = s.last_round_s;
  msg.bytes_in_round = s.bytes_in_round;
  msg.bytes_in_last_round = s.bytes_in_last_round;
  status_pub_.publish(msg);
}

}  // namespace palcas::fedserver
