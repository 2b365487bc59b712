#include "palcas_core/learning/pdqn_config.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "palcas_core/common/checks.h"
#include "palcas_core/learning/nn/bf16_gemm.h"

namespace palcas {

namespace {
template <typename T>
void require(bool ok, const char* field, T value, const std::string& rule) {
  common::require(ok, "PdqnConfig.", field, " = ", value, " is invalid: ", rule);
}
}  // namespace

void PdqnConfig::validate() const {
  require(state_size >= 1, "state_size", state_size, "must be >= 1");
  require(!hidden_sizes.empty(), "hidden_sizes", hidden_sizes.size(), "needs >= 1 layer");
  for (int h : hidden_sizes) require(h >= 1, "hidden_sizes", h, "entries must be >= 1");
  require(dropout >= 0 && dropout < 1, "dropout", dropout, "must be in [0, 1)");
  require(!bf16_products || nn::bf16GemmAvailable(), "bf16_products", bf16_products,
          "needs a build with AVX-512 BF16 (this one was built for a CPU without it)");
  require(huber_delta > 0 && std::isfinite(huber_delta), "huber_delta", huber_delta, "must be > 0");
  require(learning_rate >= 0 && std::isfinite(learning_rate), "learning_rate", learning_rate,
          "must be >= 0");
  require(weight_decay >= 0 && std::isfinite(weight_decay), "weight_decay", weight_decay,
          "must be >= 0");
  require(adam_beta1 >= 0 && adam_beta1 < 1, "adam_beta1", adam_beta1, "must be in [0, 1)");
  require(adam_beta2 >= 0 && adam_beta2 < 1, "adam_beta2", adam_beta2, "must be in [0, 1)");
  require(adam_eps > 0 && std::isfinite(adam_eps), "adam_eps", adam_eps, "must be > 0");
  // Batch norm in training mode needs >= 2 samples per batch.
  require(batch_size >= (batch_norm ? 2 : 1), "batch_size", batch_size,
          "must be >= 2 with batch norm, >= 1 without");
  require(gamma >= 0 && gamma <= 1, "gamma", gamma, "must be in [0, 1]");
  require(replay_capacity >= 1, "replay_capacity", replay_capacity, "must be >= 1");
  require(target_update_steps >= 1, "target_update_steps", target_update_steps, "must be >= 1");
  require(epsilon_final >= 0 && epsilon_final <= 1, "epsilon_final", epsilon_final,
          "must be in [0, 1]");
  require(epsilon_start >= epsilon_final && epsilon_start <= 1, "epsilon_start", epsilon_start,
          "must be in [epsilon_final, 1]");
  require(epsilon_decay > 0 && epsilon_decay <= 1, "epsilon_decay", epsilon_decay,
          "must be in (0, 1]");
  require(std::isfinite(accel_min_mps2) && std::isfinite(accel_max_mps2) &&
              accel_min_mps2 < accel_max_mps2,
          "accel_min_mps2", accel_min_mps2, "must be finite and < accel_max_mps2");
  require(target_soft_tau >= 0 && target_soft_tau <= 1, "target_soft_tau", target_soft_tau,
          "must be in [0, 1]");
  require(epsilon_linear_rounds >= 0 && std::isfinite(epsilon_linear_rounds),
          "epsilon_linear_rounds", epsilon_linear_rounds, "must be finite and >= 0");
  require(accel_noise_std_mps2 >= 0 && std::isfinite(accel_noise_std_mps2),
          "accel_noise_std_mps2", accel_noise_std_mps2, "must be >= 0");
}

}  // namespace palcas
