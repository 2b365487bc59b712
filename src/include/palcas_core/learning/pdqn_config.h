#pragma once
// Hyper-parameters of the PDQN agent. Defaults = the paper's Table "Hyper/Params"
// (Simulation Setup) where it gives a value; the others are documented choices
// (config/learning.yaml documents every key, src/doc/learning.md the reasons).

#include <cstdint>
#include <vector>

namespace palcas {

struct PdqnConfig {
  int state_size = 45;                           ///< paper: 45
  std::vector<int> hidden_sizes{256, 512, 256};  ///< paper: [256, 512, 256]
  bool batch_norm = true;                        ///< paper: batch normalisation
  float dropout = 0.1f;                          ///< paper: p = 0.1
  float huber_delta = 1.0f;                      ///< paper: Huber loss (delta 1, PyTorch default)
  float learning_rate = 1e-3f;                   ///< paper: AdamW lr 1e-3 (both networks)
  float weight_decay = 1e-2f;                    ///< paper: AdamW weight decay 1e-2
  float adam_beta1 = 0.9f;                       ///< PyTorch default
  float adam_beta2 = 0.999f;                     ///< PyTorch default
  float adam_eps = 1e-8f;                        ///< PyTorch default
  int batch_size = 256;                          ///< paper: b = 256
  float gamma = 0.995f;                          ///< paper: 0.995
  int replay_capacity = 100000;                  ///< paper: B = 100 000
  int target_update_steps = 15000;               ///< paper: C = 15 000 gradient steps
  double epsilon_start = 1.0;                    ///< paper: 1.0
  double epsilon_final = 0.02;                   ///< paper: 0.02
  double epsilon_decay = 0.999985;               ///< paper: x0.999985 per exploring act()
  float accel_min_mps2 = -4.5f;                  ///< paper: a2 in [-4.5, 2.6] m/s^2
  float accel_max_mps2 = 2.6f;
  /// Std of Gaussian noise (m/s^2) added to the greedy acceleration when exploring,
  /// clipped to the bounds; 0 = none. Not in the paper.
  float accel_noise_std_mps2 = 0.2f;
  /// MP-DQN (Bester et al. 2019) multi-pass Q evaluation; off = P-DQN as the paper cites.
  bool multi_pass = false;
  uint64_t seed = 1;

  // Departures from the printed paper (src/doc/learning.md, "Departures"); the defaults
  // here are the paper's behaviour.
  /// true: the TD target's max runs over the actions the policy may take in s', the mask
  /// stored with each transition (the RSU's: no LEFT from lane L, no RIGHT from lane 1 or
  /// the acceleration lane). false (paper P-DQN): over all four actions, including ones
  /// the RSU masks to KEEP and that therefore never get trained.
  bool td_target_valid_actions = false;
  /// > 0: Polyak target update theta' <- tau theta + (1 - tau) theta' after every gradient
  /// step (a horizon of ~1/tau steps, whatever the budget). 0 (paper): hard copy every
  /// target_update_steps.
  float target_soft_tau = 0.0f;
  /// true: the parameter network maximises Q(s, mu(s)) of ACCELERATE only, the one action
  /// the parameter belongs to. false (P-DQN as printed): the sum over all four heads.
  bool param_loss_accelerate_only = false;
  /// > 0: epsilon falls linearly from epsilon_start to epsilon_final over this many
  /// exploring decision rounds (./palcas train sets it to a fraction of the training
  /// budget). 0 (paper): geometric decay by epsilon_decay per round.
  double epsilon_linear_rounds = 0.0;
  /// true: the gradient step's matrix products (every network's forward and backward passes
  /// inside update()) run in bfloat16 with float sums where the layer shapes fit
  /// (nn::Linear::setBf16Products); decisions, the optimiser and the stored model stay float.
  /// Needs a build with AVX-512 BF16. false (paper, float): every product in float.
  bool bf16_products = false;

  /// Throws std::invalid_argument naming the first invalid field and its value.
  void validate() const;
};

}  // namespace palcas
