#pragma once
// Layer interface of the MiniDNN-like network: forward/backward on features x batch
// matrices, trainable parameters and their gradients as flat vectors (for the optimizer
// and FedAvg), and non-trained state ("buffers", e.g. batch-norm running statistics,
// averaged by FedAvg and saved, never touched by the optimizer).

#include <memory>
#include <string>

#include "palcas_core/learning/nn/types.h"

namespace palcas {
class Rng;
}

namespace palcas::nn {

/// What a backward pass must produce.
struct BackwardOptions {
  /// Write the parameter gradients (false: only propagate, e.g. through a frozen Q-net).
  bool param_grads = true;
  /// First input row whose gradient is wanted; rows [input_grad_from, inputSize()) are
  /// returned. inputSize() = no input gradient (first layer during training).
  Index input_grad_from = 0;
};

/// One layer. Owns its parameters, gradients and buffers as flat vectors; subclasses view
/// them as matrices. Not thread-safe; one forward then at most one backward per batch.
class Layer {
 public:
  virtual ~Layer() = default;

  /// Type name used in the layout string, e.g. "Linear".
  virtual std::string typeName() const = 0;
  /// Type and shape, e.g. "Linear(45,256)"; part of the network layout string.
  virtual std::string description() const = 0;
  virtual Index inputSize() const = 0;
  virtual Index outputSize() const = 0;

  /// Forward pass. input: inputSize() x batch. Keeps a pointer to `input`, which must stay
  /// alive and unchanged until backward(). Returns a reference valid until the next
  /// forward(). Throws std::invalid_argument on a wrong row count or an empty batch.
  virtual const Matrix& forward(const Matrix& input, bool training) = 0;
  /// Backward pass for the last forward(). grad_output: outputSize() x batch. Overwrites
  /// (does not accumulate) the parameter gradients when options.param_grads. Returns the
  /// gradient w.r.t. input rows [options.input_grad_from, inputSize()) (element-wise layers
  /// return all rows). Throws std::logic_error without a preceding forward, and
  /// std::invalid_argument on a shape mismatch.
  virtual const Matrix& backward(const Matrix& grad_output, const BackwardOptions& options) = 0;

  /// Deep copy (parameters, buffers, random source pointer; not the cached activations).
  virtual std::unique_ptr<Layer> clone() const = 0;
  /// Random source for stochastic layers (dropout); others ignore it. Not owned.
  virtual void setRng(Rng* /*rng*/) {}

  Vector& parameters() { return params_; }
  const Vector& parameters() const { return params_; }
  const Vector& gradients() const { return grads_; }
  Vector& buffers() { return buffers_; }
  const Vector& buffers() const { return buffers_; }

 protected:
  Vector params_;   ///< trainable values, layer-specific order (see description())
  Vector grads_;    ///< d loss / d params_, same order
  Vector buffers_;  ///< non-trained state (running statistics)
};

}  // namespace palcas::nn
