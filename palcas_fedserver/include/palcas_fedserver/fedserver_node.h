#pragma once
// The federation server node: a thin ROS shell around palcas::FederationServer. Services
// take RSU submissions and hand out the global model; a ROS-time timer (sim time under
// use_sim_time) closes rounds; each closed round is logged, published and checkpointed.

#include <diagnostic_updater/diagnostic_updater.h>
#include <palcas_msgs/FetchGlobalModel.h>
#include <palcas_msgs/SubmitWeights.h>
#include <ros/ros.h>

#include <palcas_core/common/message_auth.h>
#include <palcas_core/federation/federation_server.h>

#include <memory>

#include "palcas_fedserver/fedserver_options.h"

namespace palcas::fedserver {

class FedServerNode {
 public:
  /// Loads options, builds the initial global model (or resumes from the checkpoint),
  /// advertises, offers the services, starts the timer. @throws std::exception naming
  /// what failed (invalid parameter, unreadable checkpoint, layout mismatch).
  FedServerNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

 private:
  /// ~learning/state_size 0: waits for the bridge's road and uses 40 + its lane count.
  void takeStateSizeFromTheRoad();
  /// Fresh start: PdqnAgent(learning).exportModel(); resume: the checkpoint, whose
  /// layout must be the learning config's (otherwise no RSU could submit to it).
  void initializeModel();
  bool onSubmit(palcas_msgs::SubmitWeights::Request& req,
                palcas_msgs::SubmitWeights::Response& res);
  bool onFetch(palcas_msgs::FetchGlobalModel::Request& req,
               palcas_msgs::FetchGlobalModel::Response& res);
  void onTimer(const ros::TimerEvent&);
  /// poll() at the current ROS time; on a close: log, checkpoint, publish the version.
  void pollAndReport();
  void publishStatus();
  static double nowS() { return ros::Time::now().toSec(); }
  /// /diagnostics "federation" (describeFederation).
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& s);

  ros::NodeHandle nh_, private_nh_;
  FedServerOptions options_;
  FederationServer server_;
  std::unique_ptr<auth::MessageKey> auth_key_;  ///< null: submissions are not authenticated
  ros::Publisher status_pub_, version_pub_;
  ros::ServiceServer submit_srv_, fetch_srv_;
  ros::Timer poll_timer_;
  diagnostic_updater::Updater diagnostics_;
  double round_opened_s_ = 0.0;          ///< ROS time the open round opened (or the node started)
  std::uint64_t rejected_reported_ = 0;  ///< submissions refused, at the last diagnostics report
};

/// What the federation status says about its health.
struct FederationFacts {
  FederationStatus status;
  std::size_t expected_rsus = 0;
  double open_round_age_s = 0.0;
  std::uint64_t rejected_new = 0;  ///< submissions refused since the last report
};
/// OK while rounds average to finite models and nobody sends refused submissions; WARN after
/// a refused submission (malformed, forged, stale) since the last report or an unknown RSU's
/// fetch; ERROR once an average was not finite (the global model was kept).
void describeFederation(const FederationFacts& f, diagnostic_updater::DiagnosticStatusWrapper& s);

}  // namespace palcas::fedserver
