#pragma once
// The in-process environment behind the Python module palcas_env, without Python types: the
// bridge's episode loop (palcas_sim::EpisodeRunner, SumoSession: the same validator, advice
// guard, holds and actuation as `./palcas run`) with the RSUs' decision path taken apart at
// its one seam, the choice of each member's decision. Per RSU it does what RsuDecider does
// (rsu_decider.cpp) with the core pieces: RsuSchedule for the decision steps, PeerStates for
// I2I, RsuController::preview() for the members' states and rewards, adviseWith() for the
// masking and the transitions, and the bridge's EpisodeMeasure and writeMetricsJson for
// metrics.json. No ROS connection: ROS messages appear only as the bridge's own plain
// data structs for measuring, and parameters come from the nodes' own loaders over a
// parameter tree (shim/ros/node_handle.h).
//
// An agent is one CAV in one RSU's zone, named "<rsu_id>/<vehicle_id>".

#include <palcas_core/common/action.h>
#include <palcas_core/learning/pdqn_agent.h>
#include <palcas_core/rsu/rsu_controller.h>
#include <palcas_msgs/VehicleStateArray.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "palcas_rsu/peer_states.h"
#include "palcas_rsu/rsu_options.h"
#include "palcas_rsu/rsu_schedule.h"
#include "palcas_sim/episode_runner.h"
#include "palcas_sumo_bridge/bridge_options.h"
#include "palcas_sumo_bridge/episode_measure.h"

namespace palcas::pyenv {

using rsu::CavAdvisory;
using rsu::Closure;
using rsu::DecisionOutput;
using rsu::DecisionView;
using rsu::RsuController;
using rsu::RsuControllerOptions;

/// One agent's hybrid action: an Action code (0 LEFT, 1 RIGHT, 2 ACCELERATE, 3 KEEP) and
/// the acceleration [m/s^2] that ACCELERATE holds (ignored otherwise).
struct AgentAction {
  int advisory = static_cast<int>(Action::kKeep);
  double accel_mps2 = 0.0;
};

/// What one decision step gives the caller (PettingZoo's parallel step, Python-free).
struct StepResult {
  std::map<std::string, std::vector<float>> observations;  ///< the agents that act now, and those ending
  std::map<std::string, double> rewards;
  std::map<std::string, bool> terminations;
  std::map<std::string, bool> truncations;
  std::vector<std::string> agents;  ///< those that must act next (sorted)
  bool episode_over = false;
  std::uint64_t step = 0;
  double time_s = 0.0;
};

/// The parameter tree and where in it the bridge's parameters are.
struct EnvParams {
  std::shared_ptr<const ros::ParamTree> tree;
  std::string bridge_ns = "/palcas_sumo_bridge";
};

class ParallelEnvCore : private sim::EpisodePort {
 public:
  /// Loads the bridge's and every expected RSU's options with the nodes' loaders (errors
  /// name the parameter), checks what the module supports (no V2X channel, no gui, RSUs of
  /// one decision period), generates the scenario and starts SUMO for episode 0 (as the
  /// bridge node does). One at a time per process (libsumo): a second throws.
  explicit ParallelEnvCore(const EnvParams& params);
  ~ParallelEnvCore() override;

  /// Starts an episode: SUMO with `seed` (its scenario regenerated for it) or, without
  /// one, the next episode of the run (seed + k, as a training's episodes). Runs to the
  /// first decision step. An episode under way is ended without writing its metrics.
  StepResult reset(std::optional<unsigned> seed);
  /// The agents' actions for this decision step (every agent of `agents`, nothing else),
  /// then SUMO runs to the next decision step or the episode's end (metrics.json written).
  /// @throws std::invalid_argument naming a missing or unknown agent, an advisory outside
  /// 0..3 or a non-finite acceleration; nothing is applied then.
  StepResult step(const std::map<std::string, AgentAction>& actions);

  const std::vector<std::string>& rsuIds() const { return bridge_.expected_rsus; }
  const std::vector<std::string>& agents() const { return agents_; }
  bool episodeRunning() const { return running_; }
  int stateSize() const;
  int numLanes() const;
  const bridge::BridgeOptions& bridgeOptions() const { return bridge_; }
  const rsu::RsuNodeOptions& rsuOptions(const std::string& rsu_id) const;
  /// The run folder (metrics.json, manifest.json, the generated scenario).
  const std::string& outDir() const { return bridge_.out_dir; }
  std::uint64_t decisionPeriodSteps() const { return period_; }

 private:
  struct Rsu {
    rsu::RsuNodeOptions options;
    std::unique_ptr<RsuController> controller;  ///< the agents, states, advice (its mode)
    /// Evaluating: a training-mode twin fed the same decisions, for the rewards only (an
    /// evaluating RSU closes no transitions); null when training.
    std::unique_ptr<RsuController> rewards;
    std::unique_ptr<rsu::RsuSchedule> schedule;
    std::unique_ptr<rsu::PeerStates> peers;
    rsu::VehicleOutcomes outcomes;
    double last_own_density = 0.0;
    // The open decision (preview) of this step.
    bool due = false;
    GlobalDensities global;
    DecisionView view;
    DecisionView reward_view;
  };

  // EpisodePort
  bool running() const override { return true; }
  void publishStep(const sim::SumoSession& session) override;
  void receive(std::chrono::steady_clock::time_point, const std::function<bool()>&) override {}
  void lockstepMissed(std::uint64_t step, const std::vector<std::string>& late,
                      const std::vector<std::string>& newly_lost) override;
  void rejected(const std::string& rsu_id, const std::string& vehicle_id, metrics::RejectionReason reason,
                const std::string& detail) override;
  void applied(const std::string& vehicle_id) override;
  void actuated(const sim::SumoSession&, const sim::AdvisoryHolds&) override {}
  void stepped(const sim::SumoSession&) override {}
  void progress(const sim::SumoSession&) override {}

  void makeControllers();
  /// Runs SUMO until a decision step with agents to ask, or the episode's end; fills `out`.
  void runToDecision(StepResult& out);
  /// The due RSUs' decisions from the agents' actions (checked by step()): advice to the
  /// bridge's lockstep, cluster states to the peers.
  void applyDecisions(const std::map<std::string, AgentAction>& actions);
  void endEpisode();

  bridge::BridgeOptions bridge_;
  std::string sumocfg_;
  std::vector<Rsu> rsus_;
  std::uint64_t period_ = 10;
  std::unique_ptr<sim::EpisodeRunner> runner_;
  bridge::MeasureRules rules_;
  std::unique_ptr<bridge::EpisodeMeasure> measure_;
  palcas_msgs::VehicleStateArray current_;
  bool any_due_ = false;
  bool running_ = false;
  int episode_ = -1;
  bool fresh_ = true;  ///< the runner's SUMO is episode 0's, not run yet
  std::vector<std::string> agents_;
  std::map<std::string, std::vector<float>> last_observation_;
  std::chrono::steady_clock::time_point decision_open_;
};

/// The shipped policy (a policy folder of the suite) for the RSUs of an environment.
class PolicyCore {
 public:
  /// `folder`: a policy folder (train.json + checkpoints/, as `./palcas run --policy`), or a
  /// checkpoints folder. @throws std::invalid_argument naming the folder when it is not ours,
  /// std::runtime_error when a model does not fit (another road's state size).
  PolicyCore(const std::string& folder, const ParallelEnvCore& env);
  /// Greedy decisions (as an evaluating RSU: no exploration) for agents "<rsu>/<vehicle>".
  std::map<std::string, AgentAction> act(const std::map<std::string, std::vector<float>>& observations);
  /// Q-values (4 x n) and accelerations (n) of one RSU's network on states (state_size x n).
  void evaluate(const std::string& rsu_id, const nn::Matrix& states, nn::Matrix& q, nn::Matrix& accel);
  const std::map<std::string, std::string>& modelFiles() const { return files_; }
  ModelBlob exportModel(const std::string& rsu_id) const;
  const PdqnConfig& config(const std::string& rsu_id) const;
  std::vector<std::string> rsuIds() const;

 private:
  PdqnAgent& agentOf(const std::string& rsu_id);
  std::map<std::string, std::unique_ptr<PdqnAgent>> agents_;
  std::map<std::string, std::string> files_;
};

/// "<rsu_id>/<vehicle_id>" -> (rsu_id, vehicle_id). @throws std::invalid_argument naming it.
std::pair<std::string, std::string> splitAgent(const std::string& agent);

}  // namespace palcas::pyenv
