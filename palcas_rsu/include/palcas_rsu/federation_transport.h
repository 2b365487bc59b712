#pragma once
// The federation client's way to the server over ROS: the fedserver's SubmitWeights and
// FetchGlobalModel services, with HMAC tags on what goes out and checks on what comes in.
// A call that fails drops its persistent connection, so the next one connects afresh to a
// restarted server.

#include <palcas_core/common/message_auth.h>
#include <palcas_core/federation/federation_client.h>
#include <ros/ros.h>

namespace palcas::rsu {

class RosFederationTransport : public FederationTransport {
 public:
  /// key: null = nothing signed or checked. Accepted submissions are republished, latched,
  /// on submitted_pub (for tests, bags and debugging).
  RosFederationTransport(ros::NodeHandle nh, const auth::MessageKey* key, ros::Publisher submitted_pub);
  FetchReply fetch(const std::string& rsu_id, uint32_t min_version) override;
  SubmitReply submit(const Submission& submission) override;

 private:
  ros::NodeHandle nh_;
  const auth::MessageKey* key_;
  ros::Publisher submitted_pub_;
  ros::ServiceClient submit_client_, fetch_client_;
};

}  // namespace palcas::rsu
