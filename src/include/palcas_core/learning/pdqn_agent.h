#pragma once
// Parameterised deep Q-network agent (P-DQN, Xiong et al. 2018; paper "Problem
// Formulation"): a parameter network mu_theta(s) -> c and a Q-network Q_phi(s, c) -> one
// value per discrete action; act = argmax_q Q(s, c)_q with c_q taken from mu(s). Only
// action a2 (accelerate) carries a parameter, the acceleration in m/s^2.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "palcas_core/common/action.h"
#include "palcas_core/common/rng.h"
#include "palcas_core/learning/model_blob.h"
#include "palcas_core/learning/nn/adamw.h"
#include "palcas_core/learning/nn/folded_network.h"
#include "palcas_core/learning/nn/huber_loss.h"
#include "palcas_core/learning/nn/network.h"
#include "palcas_core/learning/pdqn_config.h"
#include "palcas_core/learning/replay_buffer.h"

namespace palcas {

/// The decision for one CAV.
struct Decision {
  Action action = Action::kKeep;
  /// Acceleration parameter (m/s^2) within the configured bounds; the advisory's value
  /// when action == kAccelerate, and what is stored in replay for every action.
  float accel_mps2 = 0.0f;
};

/// Losses of one update() (each network's loss on its batch).
struct UpdateStats {
  float q_loss = 0.0f;      ///< mean Huber loss of Q(s, c)[a] against the TD target
  float param_loss = 0.0f;  ///< -mean_n sum_a Q(s_n, mu(s_n))_a (P-DQN's parameter loss)
  uint64_t gradient_steps = 0;
};

/// One PDQN learner: online + target networks, AdamW for each, replay, epsilon, RNG.
/// Deterministic for a seed on one Eigen thread. Not thread-safe. Movable, not copyable.
class PdqnAgent {
 public:
  /// Builds the networks from config (weights from the seeded RNG). Throws
  /// std::invalid_argument naming the field if the config is invalid.
  explicit PdqnAgent(const PdqnConfig& config);
  PdqnAgent(PdqnAgent&&) noexcept;
  PdqnAgent& operator=(PdqnAgent&&) noexcept;
  PdqnAgent(const PdqnAgent&) = delete;
  PdqnAgent& operator=(const PdqnAgent&) = delete;
  ~PdqnAgent();

  /// Decides for every column of states (state_size x n_cavs) in ONE batched forward pass
  /// of each network, in eval mode. explore: epsilon-greedy (random action, uniform
  /// acceleration in the bounds) and Gaussian noise on the greedy acceleration, and
  /// epsilon decays once per call (not per CAV). Throws std::invalid_argument on a wrong
  /// row count, zero columns or a non-finite value (agent unchanged).
  void act(const nn::Matrix& states, bool explore, std::vector<Decision>& out);
  std::vector<Decision> act(const nn::Matrix& states, bool explore);
  /// act() over a default decision per column (a rule's advice): the greedy action is taken
  /// only where its Q value exceeds the default action's by more than `margin` (>= 0, Q
  /// units); elsewhere the default's action is, with the network's acceleration parameter
  /// (the default's own for ACCELERATE). Exploration as act(): an exploring draw stays
  /// random. Throws std::invalid_argument (agent unchanged) as act() does, on a defaults
  /// count other than the column count, or a margin that is negative or not finite.
  void actOverDefaults(const nn::Matrix& states, bool explore, const std::vector<Decision>& defaults,
                       float margin, std::vector<Decision>& out);

  /// Stores a transition (accel_mps2 is clipped to the bounds). next_valid_actions: the
  /// actions that may be taken in next_state (ALL_ACTIONS when nothing is ruled out); the
  /// agent does not read them out of the state, it does not know what a state encodes.
  /// Throws std::invalid_argument like ReplayBuffer::push.
  void remember(const nn::Vector& state, const Decision& decision, float reward,
                const nn::Vector& next_state, ActionMask next_valid_actions, bool done);

  /// True when the replay holds at least one batch.
  bool canUpdate() const;
  /// One gradient step of both networks (Q first, then mu through the updated Q) and a
  /// hard target copy every target_update_steps. Throws std::runtime_error if the replay
  /// holds fewer than batch_size transitions.
  UpdateStats update();

  /// max_a' Q_target(s', mu_target(s'))_a' per column (1 x n): the bootstrap of the TD
  /// target; with td_target_valid_actions only over the actions of next_valid_actions[j]
  /// (one mask per column, stored with the transition). Throws std::invalid_argument on a
  /// mask count other than the column count.
  void nextStateValues(const nn::Matrix& next_states,
                       const std::vector<ActionMask>& next_valid_actions, nn::Matrix& values);

  /// Greedy evaluation without exploration or side effects on epsilon: Q values (4 x n)
  /// and accelerations (1 x n, m/s^2). Same preconditions as act().
  void evaluate(const nn::Matrix& states, nn::Matrix& q_values, nn::Matrix& accel_mps2);

  /// The whole model (online networks) as one flat array; see ModelBlob.
  ModelBlob exportModel() const;
  /// Loads a model into the online networks (targets and optimiser state are kept).
  /// Throws std::invalid_argument (agent untouched) on another layout id, a bad checksum,
  /// a wrong value count or a non-finite value (index named).
  void importModel(const ModelBlob& blob);
  /// The model's head as spans of exportModel()'s values: in each network, the layers from
  /// its `linear_layers`-th last Linear layer to the output (parameters and buffers). 0 =
  /// none. Throws std::invalid_argument unless linear_layers is below each network's count
  /// of Linear layers (a head that is the whole network leaves nothing to share).
  std::vector<nn::Network::StateSpan> headSpans(size_t linear_layers) const;
  /// exportModel() to a model file / importModel() from one (std::runtime_error on error,
  /// agent untouched).
  void saveModel(const std::string& path) const;
  void loadModel(const std::string& path);

  /// Everything: networks, targets, optimisers, replay, epsilon, counters, RNG state.
  void saveCheckpoint(const std::string& path) const;
  /// Throws std::runtime_error (agent untouched) if the file fails a check or was written
  /// by an agent of another layout or replay capacity. A checkpoint written before the
  /// masks were stored with the transitions gets them from rebuild_masks, and is refused
  /// (naming the file) without one.
  void loadCheckpoint(const std::string& path, const NextStateMaskRebuild& rebuild_masks = {});

  /// Identifies the architecture: variant, both networks' layouts.
  std::string layoutId() const;
  uint64_t layoutChecksum() const;

  const PdqnConfig& config() const { return config_; }
  double epsilon() const { return epsilon_; }
  uint64_t gradientSteps() const { return gradient_steps_; }
  uint64_t decisionRounds() const { return decision_rounds_; }
  const ReplayBuffer& replay() const { return replay_; }
  const nn::Network& paramNetwork() const { return mu_; }
  const nn::Network& qNetwork() const { return q_; }
  const nn::Network& paramTargetNetwork() const { return mu_target_; }
  const nn::Network& qTargetNetwork() const { return q_target_; }

 private:
  void checkStates(const nn::Matrix& states, const char* who) const;
  void forwardGreedy(const nn::Matrix& states);  // folded eval mode; fills act_c_, act_q_
  // act() and actOverDefaults(): defaults null = plain greedy.
  void decide(const nn::Matrix& states, bool explore, const std::vector<Decision>* defaults, float margin,
              std::vector<Decision>& out);
  void buildQInput(const nn::Matrix& states, const nn::Matrix& c_norm, nn::Matrix& out) const;
  void selectQ(const nn::Matrix& q_out, nn::Index n, nn::Matrix& out) const;
  // td_target_valid_actions: -inf for the actions outside each column's mask.
  static void maskInvalidNextActions(const std::vector<ActionMask>& next_valid_actions,
                                     nn::Matrix& q);
  float updateQ();
  float updateParam();
  float accelFromNorm(float c) const { return accel_mid_ + accel_half_ * c; }
  float normFromAccel(float a) const { return (a - accel_mid_) / accel_half_; }
  std::string writeExtra() const;
  void readExtra(const std::string& extra, const std::string& what,
                 const NextStateMaskRebuild& rebuild_masks);

  PdqnConfig config_;
  std::unique_ptr<Rng> rng_;  // heap: the dropout layers hold its address across moves
  nn::Network mu_, q_, mu_target_, q_target_;
  // Eval-mode folds of the networks above, re-folded lazily when their state changed
  // (Network::stateVersion), so act() and the TD target skip batch norm and dropout.
  nn::FoldedNetwork mu_fold_, q_fold_, mu_target_fold_, q_target_fold_;
  nn::AdamW mu_opt_, q_opt_;
  nn::HuberLoss huber_;
  ReplayBuffer replay_;
  double epsilon_;
  uint64_t gradient_steps_ = 0, decision_rounds_ = 0;
  float accel_mid_, accel_half_;
  // Scratch matrices reused between calls (no allocation at a steady batch size).
  ReplayBatch batch_;
  nn::Matrix c_norm_, q_in_, q_sel_, pred_, target_y_, grad_q_, grad_c_;
  nn::Matrix act_c_, act_q_in_, act_q_, next_values_;
};

}  // namespace palcas
