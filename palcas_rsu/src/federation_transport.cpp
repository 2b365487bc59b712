#include "palcas_rsu/federation_transport.h"

#include <palcas_common/message_auth.h>
#include <palcas_common/model_weights.h>
#include <palcas_msgs/FetchGlobalModel.h>
#include <palcas_msgs/SubmitWeights.h>

#include "palcas_rsu/topics.h"

namespace palcas::rsu {

RosFederationTransport::RosFederationTransport(ros::NodeHandle nh, const auth::MessageKey* key,
                                               ros::Publisher submitted_pub)
    : nh_(nh), key_(key), submitted_pub_(submitted_pub) {}

FetchReply RosFederationTransport::fetch(const std::string& rsu_id, uint32_t min_version) {
  palcas_msgs::FetchGlobalModel srv;
  srv.request.rsu_id = rsu_id;
  srv.request.min_version = min_version;
  if (!fetch_client_.isValid())
    fetch_client_ = nh_.serviceClient<palcas_msgs::FetchGlobalModel>(FETCH_MODEL_SERVICE, true);
  FetchReply reply;
  reply.reachable = fetch_client_.call(srv);
  if (!reply.reachable) {
    // A persistent client keeps its broken link after the server died and fails on the
    // restarted one forever: drop it, the next call connects afresh.
    fetch_client_.shutdown();
    return reply;
  }
  reply.available = srv.response.available;
  if (!reply.available) return reply;
  const auth::Verdict verdict = common::verifyMessage(srv.response.weights, key_);
  if (verdict != auth::Verdict::kAuthentic) {
    reply.refused = auth::verdictName(verdict);
    return reply;
  }
  reply.model = common::toModelBlob(srv.response.weights);
  reply.model_version = srv.response.weights.model_version;
  reply.round = srv.response.weights.round;
  return reply;
}

SubmitReply RosFederationTransport::submit(const Submission& s) {
  palcas_msgs::SubmitWeights srv;
  srv.request.weights = common::toWeightsMsg(s.model, s.rsu_id, s.round, s.base_version, s.sample_count);
  common::signMessage(srv.request.weights, key_);
  if (!submit_client_.isValid())
    submit_client_ = nh_.serviceClient<palcas_msgs::SubmitWeights>(SUBMIT_WEIGHTS_SERVICE, true);
  SubmitReply reply;
  reply.reachable = submit_client_.call(srv);
  if (!reply.reachable) {
    submit_client_.shutdown();  // as in fetch: reconnect on the next call
    return reply;
  }
  reply.accepted = srv.response.accepted;
  reply.reason = srv.response.reason;
  reply.round = srv.response.round;
  reply.global_version = srv.response.global_version;
  if (reply.accepted) submitted_pub_.publish(srv.request.weights);
  return reply;
}

}  // namespace palcas::rsu
