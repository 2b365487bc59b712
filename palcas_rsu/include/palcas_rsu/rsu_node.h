#pragma once
// The RSU node: a thin ROS shell around palcas_core's RsuController. It registers with the
// bridge at its decision period and answers the lockstep on its decision steps only (an
// unregistered RSU answers every step, empty between decisions); at the decision steps
// of its RsuSchedule, once its neighbours' cluster states (and, training, its step's events)
// are in (DecisionInputs), it converts the state, calls the controller once for all its CAVs,
// publishes the advisories, its ClusterState (I2I) and its RsuStatus, then does what the
// schedule says follows (learning, the federation client's tick, checkpoints).

#include <diagnostic_updater/diagnostic_updater.h>
#include <palcas_core/common/message_auth.h>
#include <palcas_core/federation/federation_client.h>
#include <palcas_core/rsu/controller_model.h>
#include <palcas_core/rsu/learning_log.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/ClusterState.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <palcas_msgs/RsuStatus.h>
#include <palcas_msgs/VehicleStateArray.h>
#include <ros/ros.h>

#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "palcas_rsu/decision_inputs.h"
#include "palcas_rsu/federation_transport.h"
#include "palcas_rsu/peer_states.h"
#include "palcas_rsu/rsu_diagnostics.h"
#include "palcas_rsu/rsu_options.h"
#include "palcas_rsu/rsu_schedule.h"

namespace palcas::rsu {

class RsuNode {
 public:
  /// Loads options, builds the controller (resuming or loading a policy as configured),
  /// advertises, subscribes, registers with the bridge, fetches the initial global model.
  /// @throws std::exception naming what failed.
  RsuNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

  /// Final checkpoint (train mode with a checkpoint_dir). Call after spinning ends.
  void shutdown();

 private:
  void onStates(const palcas_msgs::VehicleStateArray::ConstPtr& msg);
  void onEvents(const palcas_msgs::VehicleEventArray::ConstPtr& msg);
  void onClusterState(const palcas_msgs::ClusterState::ConstPtr& msg);
  /// A peer's cluster state into PeerStates, through the V2X channel when it is on.
  void receiveClusterState(const palcas_msgs::ClusterState::ConstPtr& msg);
  void decide(const palcas_msgs::VehicleStateArray& msg, const ros::WallTime& received);
  /// A decision step's state: decided now if its other inputs are in (DecisionInputs), else
  /// held until they arrive or decision_inputs_wait_s has passed.
  void decideWhenReady(const palcas_msgs::VehicleStateArray::ConstPtr& msg, const ros::WallTime& received);
  /// Decides the held state if its inputs are now in (after an event array or a cluster state).
  void decideHeldIfReady();
  /// Decides the held state with what is there (the wait ran out, or a later state came):
  /// the neighbours still missing are presumed down; said once per wait.
  void decideHeldAnyway(const char* why);
  /// The controller's advice on what this RSU heard at the state's step, with the I2I
  /// densities it used (`global`). @throws std::invalid_argument for a malformed state.
  DecisionOutput advise(const palcas_msgs::VehicleStateArray& msg, double now_s, GlobalDensities& global);
  /// Publishes a decision's advisories (and its ClusterState with I2I); returns the
  /// decision's wall time [ms].
  float publishDecision(const palcas_msgs::VehicleStateArray& msg, const DecisionOutput& decision,
                        const GlobalDensities& global, const ros::WallTime& received);
  /// The decision's row of the learning log (errors logged, not thrown).
  void logDecision(std::uint64_t step, float decision_ms);
  /// DEBUG on logger "decision": members, densities and every advisory of one decision.
  void logDecisionDetail(std::uint64_t step, const DecisionOutput& decision, const GlobalDensities& global,
                         float decision_ms) const;
  /// The decision's RsuStatus (msg_conversion's toStatusMsg) and the diagnostics.
  void publishStatus(const palcas_msgs::VehicleStateArray& msg, double now_s, float decision_ms);
  void answerEmpty(const palcas_msgs::VehicleStateArray& msg, const ros::WallTime& received);
  void waitForPeers();
  void registerWithBridge();
  void loadInitialModel();
  /// Logs what the federation client did; publishes the model after a load.
  void onFederationEvent(FederationEvent event, const std::string& message);
  void checkpoint();
  /// Signs (with a key) and publishes one step's answer.
  void publishAdvisories(palcas_msgs::AdvisoryArray& out);
  /// Closes this episode's row of learning.csv (errors logged, not thrown).
  void endEpisodeLog();
  std::string checkpointDir() const;
  /// /diagnostics "<rsu>: decisions" (rsu_diagnostics.h).
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& s);

  ros::NodeHandle nh_, private_nh_;
  RsuNodeOptions options_;
  std::unique_ptr<RsuController> controller_;
  std::unique_ptr<auth::MessageKey> auth_key_;  ///< null: nothing signed or checked
  // When to decide, observe, learn (and the learner thread: finishLearning() before any
  // other use of controller_), tick the federation and checkpoint. After controller_: it
  // joins a running learner before the controller goes.
  RsuSchedule schedule_;
  PeerStates peers_;
  VehicleOutcomes outcomes_;
  // The V2X channel on this RSU's side (options_.v2x.enabled): built at the first state
  // (it needs the step length); null = off, every message as it comes.
  std::unique_ptr<v2x::Channel> channel_;
  std::unique_ptr<v2x::UplinkView> uplink_;
  v2x::DelayLine<palcas_msgs::ClusterState> i2i_in_flight_;
  std::uint64_t i2i_lost_ = 0, i2i_received_ = 0;
  /// The last state's step: a step not after it starts a new episode (the bridge runs
  /// several in one launch), and the channel's view starts afresh.
  std::optional<std::uint64_t> last_state_step_;
  /// The road as this RSU hears it at the state's step (the uplink; the state itself when
  /// the channel is off). @throws std::invalid_argument for a malformed state.
  RoadSnapshot heard(const palcas_msgs::VehicleStateArray& msg);
  /// The channel's counts as /diagnostics key-values (nothing when it is off).
  void addChannelCounts(diagnostic_updater::DiagnosticStatusWrapper& s) const;

  ros::Publisher advisories_pub_, cluster_pub_, status_pub_, submitted_pub_, model_pub_;
  ros::Subscriber states_sub_, events_sub_, cluster_sub_;
  // Federation (train mode with federation on): the client's state machine in the core,
  // reaching the server through ROS services.
  std::unique_ptr<ControllerModel> federated_model_;
  std::unique_ptr<RosFederationTransport> transport_;
  std::unique_ptr<FederationClient> federation_;

  LearningLog learning_log_;  ///< <checkpoint_dir>/<rsu_id>/learning.csv, a row per episode
  /// This zone's density at the previous decision: the "own" global density (veh/km).
  double last_own_density_ = std::numeric_limits<double>::quiet_NaN();
  bool first_state_ = true;
  bool answer_decision_steps_only_ = false;  ///< registered with the bridge at our decision period
  DecisionInputs inputs_;
  palcas_msgs::VehicleStateArray::ConstPtr held_state_;  ///< a decision step waiting for its inputs
  ros::WallTime held_received_;
  ros::WallTimer held_timer_;
  std::uint64_t decisions_held_ = 0, decisions_without_inputs_ = 0;
  diagnostic_updater::Updater diagnostics_;
  palcas_msgs::RsuStatus last_status_;  ///< of the last decision, for the diagnostics
  RecentTimes recent_decision_ms_{1000};
  std::string policy_file_;             ///< the model evaluated ("" in training)
};

}  // namespace palcas::rsu
