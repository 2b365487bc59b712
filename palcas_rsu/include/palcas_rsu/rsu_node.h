#pragma once
// The RSU node: a thin ROS shell around the RSU's decision path (RsuDecider). It registers
// with the bridge at its decision period and answers the lockstep on its decision steps only
// (an unregistered RSU answers every step, empty between decisions); at its decision steps,
// once its neighbours' cluster states (and, training, its step's events) are in
// (DecisionInputs: over ROS they arrive in no fixed order), it has the decider decide,
// publishes its ClusterState (I2I) and advisories, then lets the decider do what follows
// (learning, the federation client's tick, checkpoints) and publishes the RsuStatus.

#include <diagnostic_updater/diagnostic_updater.h>
#include <palcas_core/common/message_auth.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/ClusterState.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <palcas_msgs/RsuStatus.h>
#include <palcas_msgs/VehicleStateArray.h>
#include <ros/ros.h>

#include <memory>
#include <string>

#include "palcas_rsu/decision_inputs.h"
#include "palcas_rsu/rsu_decider.h"
#include "palcas_rsu/rsu_diagnostics.h"
#include "palcas_rsu/rsu_options.h"

namespace palcas::rsu {

class RsuNode {
 public:
  /// Loads options, builds the decider (resuming or loading a policy as configured),
  /// advertises, subscribes, registers with the bridge, fetches the initial global model.
  /// @throws std::exception naming what failed.
  RsuNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

  /// Final checkpoint (train mode with a checkpoint_dir). Call after spinning ends.
  void shutdown();

 private:
  void onStates(const palcas_msgs::VehicleStateArray::ConstPtr& msg);
  void onEvents(const palcas_msgs::VehicleEventArray::ConstPtr& msg);
  void onClusterState(const palcas_msgs::ClusterState::ConstPtr& msg);
  void decide(const palcas_msgs::VehicleStateArray& msg, RsuDecider::Clock::time_point received);
  /// A decision step's state: decided now if its other inputs are in (DecisionInputs), else
  /// held until they arrive or decision_inputs_wait_s has passed.
  void decideWhenReady(const palcas_msgs::VehicleStateArray::ConstPtr& msg, RsuDecider::Clock::time_point received);
  /// Decides the held state if its inputs are now in (after an event array or a cluster state).
  void decideHeldIfReady();
  /// Decides the held state with what is there (the wait ran out, or a later state came):
  /// the neighbours still missing are presumed down; said once per wait.
  void decideHeldAnyway(const char* why);
  void answerEmpty(const palcas_msgs::VehicleStateArray& msg, RsuDecider::Clock::time_point received);
  void waitForPeers();
  void registerWithBridge();
  /// Starts the federation client over the fedserver's services (training with federation).
  void startFederation();
  /// Signs (with a key) and publishes one step's answer.
  void publishAdvisories(palcas_msgs::AdvisoryArray& out);
  /// /diagnostics "<rsu>: decisions" (rsu_diagnostics.h).
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& s);

  ros::NodeHandle nh_, private_nh_;
  std::unique_ptr<RsuDecider> decider_;
  const RsuNodeOptions& options_;  ///< the decider's
  std::unique_ptr<auth::MessageKey> auth_key_;  ///< null: nothing signed or checked

  ros::Publisher advisories_pub_, cluster_pub_, status_pub_, submitted_pub_, model_pub_;
  ros::Subscriber states_sub_, events_sub_, cluster_sub_, version_sub_;

  bool answer_decision_steps_only_ = false;  ///< registered with the bridge at our decision period
  DecisionInputs inputs_;
  palcas_msgs::VehicleStateArray::ConstPtr held_state_;  ///< a decision step waiting for its inputs
  RsuDecider::Clock::time_point held_received_;
  ros::WallTimer held_timer_;
  std::uint64_t decisions_held_ = 0, decisions_without_inputs_ = 0;
  diagnostic_updater::Updater diagnostics_;
  palcas_msgs::RsuStatus last_status_;  ///< of the last decision, for the diagnostics
  RecentTimes recent_decision_ms_{1000};
};

}  // namespace palcas::rsu
