#pragma once
// The RSU's decision path, without a ROS connection: what one RSU does with the bridge's
// vehicle states, vehicle events and its neighbours' cluster states, and what it answers.
// The RSU node (rsu_node.h) wires it to topics, services and timers; the bridge's in-process
// mode (palcas_sumo_bridge, `~inprocess_rsus`) calls it directly, so both paths take the
// same decisions by construction. Messages are used as plain data (palcas_msgs structs).
//
// Per decision, in this order (the order is why it is one object):
//   decide()         the state as heard (V2X uplink when on), the peers' cluster states due,
//                    the controller's advice: the advisories and the ClusterState to send;
//   afterPublished() the decision's log row, gradient steps (inline or on the learner
//                    thread, started last), the federation client's tick, the checkpoint,
//                    and the decision's RsuStatus.
// A caller sends decide()'s messages before afterPublished(), so that the bridge need not
// wait for learning.

#include <palcas_core/federation/federation_client.h>
#include <palcas_core/rsu/controller_model.h>
#include <palcas_core/rsu/learning_log.h>
#include <palcas_core/v2x/v2x_channel.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/ClusterState.h>
#include <palcas_msgs/ModelWeights.h>
#include <palcas_msgs/RsuStatus.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <palcas_msgs/VehicleStateArray.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "palcas_rsu/peer_states.h"
#include "palcas_rsu/rsu_options.h"
#include "palcas_rsu/rsu_schedule.h"

namespace palcas::rsu {

/// One decision's messages, before anything is sent.
struct RsuDecision {
  /// The advisories (unsigned: the transport signs) with decision_ms set. Empty advisories
  /// and NaN densities when the state was malformed (`decided` false).
  palcas_msgs::AdvisoryArray advisories;
  /// With I2I on: this zone's ClusterState, to go out before the advisories.
  std::optional<palcas_msgs::ClusterState> cluster_state;
  bool decided = false;
  std::string error;  ///< why not decided
  double time_s = 0.0;
  /// The neighbours' densities this RSU's own peer bookkeeping gave (NaN = unknown), before
  /// any override of decide()'s `used_densities`.
  GlobalDensities from_peers;
};

/// Logs a federation client event on logger "federation", one call per kind so each kind
/// is throttled on its own. The client's messages name the RSU; `who` goes before them
/// ("" in the node, "in process: " in the bridge).
void logFederationEvent(const std::string& who, FederationEvent event, const std::string& message);

/// One decision in words (DEBUG on logger "decision"): members, densities, every advisory.
std::string describeDecision(const RsuDecision& decision, std::uint32_t members);

class RsuDecider {
 public:
  using Clock = std::chrono::steady_clock;
  /// What the federation client reports (kind, text), and the model after a load.
  using FederationLog = std::function<void(FederationEvent, const std::string&)>;
  using ModelLoaded = std::function<void(const palcas_msgs::ModelWeights&)>;

  /// Builds the controller: resumes from the checkpoint (options.resume) or, evaluating,
  /// loads the policy (policy_dir: the global model, else the RSU's own, else the default).
  /// The options must be complete (zones and lanes adopted from the road).
  /// @throws std::exception naming what failed (no policy, a checkpoint that does not fit).
  explicit RsuDecider(RsuNodeOptions options);
  ~RsuDecider();
  RsuDecider(const RsuDecider&) = delete;
  RsuDecider& operator=(const RsuDecider&) = delete;

  /// True when this RSU trains its network with a federation server.
  bool wantsFederation() const;
  /// Starts the federation client over `transport` (kept); joins now when the server is
  /// reachable, else when it first answers. Call once, before the first state.
  void startFederation(std::unique_ptr<FederationTransport> transport, bool server_reachable, FederationLog log,
                       ModelLoaded loaded);

  /// The federation server announced its global model's version (its latched topic): a
  /// waiting RSU fetches when told of a newer one instead of polling every decision.
  void announceGlobalVersion(uint32_t version);
  /// A step's vehicle events (they close training transitions).
  void onEvents(const palcas_msgs::VehicleEventArray& events);
  /// A peer's cluster state (own ones are ignored), through the V2X channel when it is on.
  /// @return false when it was not taken (own, or malformed: `why` says).
  bool onClusterState(const palcas_msgs::ClusterState& state, std::string* why = nullptr);
  /// A step's vehicle states, before deciding on them: the first one checks the road and
  /// starts the V2X channel; a step not after the last starts a new episode; between
  /// decisions the state is heard (uplink) and observed (training rewards over the period).
  /// @return true at this RSU's decision steps (then call decide()).
  /// @throws std::runtime_error when the road's lane count is not the RSU's;
  ///         std::invalid_argument for a malformed state between decisions.
  bool onStates(const palcas_msgs::VehicleStateArray& states);
  /// The decision on a decision step's state; `received` is when the state arrived (for
  /// decision_ms). A malformed state is answered empty, not thrown. `used_densities` (with
  /// I2I on): decide on these global densities (the neighbours' and this zone's own at its
  /// previous decision) instead of the peers' states received and lastOwnDensity()
  /// (replay_policy: the ones a recording says the live RSU used); null = its own.
  RsuDecision decide(const palcas_msgs::VehicleStateArray& states, Clock::time_point received,
                     const GlobalDensities* used_densities = nullptr);
  /// What follows a sent decision (see the header comment); returns the decision's status.
  palcas_msgs::RsuStatus afterPublished(const palcas_msgs::VehicleStateArray& states, const RsuDecision& decision);
  /// An empty answer to a step (no advice: CAVs keep their commands).
  palcas_msgs::AdvisoryArray emptyAnswer(const palcas_msgs::VehicleStateArray& states, Clock::time_point received) const;
  /// Joins the learner, closes the episode's log row and, training with a checkpoint
  /// directory, writes the final checkpoint. @return the checkpoint folder written, or "".
  std::string shutdown();

  const RsuNodeOptions& options() const { return options_; }
  const std::string& rsuId() const { return options_.controller.rsu_id; }
  const RsuController& controller() const { return *controller_; }
  const RsuSchedule& schedule() const { return schedule_; }
  const PeerStates& peers() const { return peers_; }
  /// This zone's density at its previous decision (NaN before the first): the "own" global
  /// density the next decision takes.
  double lastOwnDensity() const { return last_own_density_; }
  /// The policy file evaluated ("" in training and for the rule).
  const std::string& policyFile() const { return policy_file_; }
  bool federationReachable() const { return federation_ && federation_->reachable(); }
  /// The V2X uplink's counts; null when the channel is off.
  const v2x::UplinkCounts* uplinkCounts() const { return uplink_ ? &uplink_->counts() : nullptr; }
  std::uint64_t i2iLost() const { return i2i_lost_; }
  std::uint64_t i2iReceived() const { return i2i_received_; }
  /// Where this RSU's checkpoints go: <checkpoint_dir>/<rsu_id>.
  std::string checkpointDir() const;
  /// Writes the checkpoint now. @throws std::exception naming what failed.
  void checkpoint();

 private:
  void loadInitialModel();
  RoadSnapshot heard(const palcas_msgs::VehicleStateArray& states);

  RsuNodeOptions options_;
  std::unique_ptr<RsuController> controller_;
  // After controller_: it joins a running learner before the controller goes.
  RsuSchedule schedule_;
  PeerStates peers_;
  VehicleOutcomes outcomes_;
  std::unique_ptr<v2x::Channel> channel_;
  std::unique_ptr<v2x::UplinkView> uplink_;
  v2x::DelayLine<palcas_msgs::ClusterState> i2i_in_flight_;
  std::uint64_t i2i_lost_ = 0, i2i_received_ = 0;
  std::optional<std::uint64_t> last_state_step_;
  bool first_state_ = true;
  std::unique_ptr<ControllerModel> federated_model_;
  std::unique_ptr<FederationTransport> transport_;
  std::unique_ptr<FederationClient> federation_;
  ModelLoaded model_loaded_;
  FederationLog federation_log_;
  LearningLog learning_log_;
  /// This zone's density at the previous decision: the "own" global density (veh/km).
  double last_own_density_ = std::numeric_limits<double>::quiet_NaN();
  std::string policy_file_;
};

}  // namespace palcas::rsu
