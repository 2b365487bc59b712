#pragma once
// AdamW (Loshchilov & Hutter 2019) with PyTorch's torch.optim.AdamW update, per value:
//   p <- p (1 - lr wd)                        (decoupled weight decay, before Adam)
//   m <- b1 m + (1 - b1) g ;  v <- b2 v + (1 - b2) g^2
//   p <- p - (lr / (1 - b1^t)) m / (sqrt(v) / sqrt(1 - b2^t) + eps)
// Weight decay applies to every parameter (weights, biases, BN gamma/beta), as PyTorch does
// for model.parameters(); batch-norm running statistics are buffers and never touched.

#include <cstdint>

#include "palcas_core/learning/nn/types.h"

namespace palcas::nn {

class Network;
class ByteWriter;
class ByteReader;

struct AdamWConfig {
  Scalar learning_rate = 1e-3f;
  Scalar beta1 = 0.9f;
  Scalar beta2 = 0.999f;
  Scalar eps = 1e-8f;
  Scalar weight_decay = 1e-2f;
};

/// AdamW optimiser for one network; moment vectors sized on the first step.
class AdamW {
 public:
  /// Throws std::invalid_argument naming the field unless lr >= 0, 0 <= b1, b2 < 1,
  /// eps > 0, wd >= 0 (all finite).
  explicit AdamW(const AdamWConfig& config = {});

  /// One update of `network`'s parameters from the gradients of its last backward().
  /// Throws std::invalid_argument if the parameter count differs from earlier steps.
  void step(Network& network);

  uint64_t stepCount() const { return step_; }
  /// Size of each moment vector (0 before the first step).
  Index momentSize() const { return m_.size(); }
  const AdamWConfig& config() const { return config_; }

  /// Step count and moments (not the config) for checkpoints.
  void write(ByteWriter& out) const;
  /// Reads what write() wrote; throws std::runtime_error (optimiser unchanged) on a
  /// truncated or inconsistent record.
  void read(ByteReader& in);

 private:
  AdamWConfig config_;
  uint64_t step_ = 0;
  Vector m_, v_;
};

}  // namespace palcas::nn
