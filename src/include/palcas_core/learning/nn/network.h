#pragma once
// Sequential network owning its layers (MiniDNN's Network, with unique_ptr ownership),
// plus the builder of the multi-layer perceptrons used by the PDQN agent.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "palcas_core/learning/nn/layer.h"

namespace palcas::nn {

/// A chain of layers. Flat views: getParameters() = trainable values of every layer in
/// order; getState() = getParameters() followed by every layer's buffers in order, i.e.
/// EVERYTHING FedAvg averages and a saved model holds. Not thread-safe.
class Network {
 public:
  Network();
  Network(const Network& other);
  Network& operator=(const Network& other);
  Network(Network&&) = default;
  Network& operator=(Network&&) = default;

  /// Appends a layer. Throws std::invalid_argument if its input size differs from the
  /// previous layer's output size or it is null.
  void addLayer(std::unique_ptr<Layer> layer);

  /// Forward pass in the current mode. input: inputSize() x batch (copied, so it may be a
  /// temporary). Returns outputSize() x batch, valid until the next forward().
  /// Throws std::invalid_argument on a wrong shape, std::logic_error if empty.
  const Matrix& forward(const Matrix& input);
  /// Backward pass of the last forward(); see Layer::backward. options.input_grad_from
  /// applies to the first layer; inner layers always propagate the full gradient.
  const Matrix& backward(const Matrix& grad_output, const BackwardOptions& options);

  void train() { training_ = true; }
  void eval() { training_ = false; }
  bool isTraining() const { return training_; }

  Index inputSize() const;
  Index outputSize() const;
  size_t layerCount() const { return layers_.size(); }
  /// Mutable access counts as a state change (see stateVersion()): do not keep the
  /// reference across a decision.
  Layer& layer(size_t i) {
    bumpStateVersion();
    return *layers_.at(i);
  }
  const Layer& layer(size_t i) const { return *layers_.at(i); }

  Index parameterCount() const;
  Index bufferCount() const;
  Index stateCount() const { return parameterCount() + bufferCount(); }

  Vector getParameters() const;
  /// Throws std::invalid_argument (network unchanged) on a wrong size or a non-finite value.
  void setParameters(const Vector& values);
  Vector getState() const;
  /// Sets parameters and buffers from stateCount() values in getState() order.
  /// Throws std::invalid_argument (network unchanged) on a wrong count or non-finite value.
  void setState(const Scalar* values, Index count);
  void setState(const Vector& values) { setState(values.data(), values.size()); }

  /// Where layers [first_layer, layerCount()) sit in getState()'s order: their parameters'
  /// span, then their buffers' span (empty spans left out). Throws std::out_of_range if
  /// first_layer > layerCount(). What a personalised federation keeps local (a model's head).
  struct StateSpan {
    Index begin = 0;
    Index count = 0;
  };
  std::vector<StateSpan> stateSpansFrom(size_t first_layer) const;

  /// Layer descriptions joined by ';', e.g. "Linear(45,256);BatchNorm1d(256);ReLU(256)".
  std::string layout() const;
  /// FNV-1a 64 of layout().
  uint64_t layoutChecksum() const;
  /// Random source for the dropout layers (not owned; must outlive the network's use).
  void setRng(Rng* rng);
  /// Linear::setBf16Products on every Linear layer (not a state change: the values stay).
  void setBf16Products(bool on);

  /// Identifies this network's parameters and buffers as they are now: a value no other
  /// network or earlier state of this one had. Changes on addLayer, setParameters,
  /// setState, a training-mode forward (batch-norm statistics), mutable layer() access
  /// (how optimisers write) and copying. FoldedNetwork uses it to know when to re-fold.
  uint64_t stateVersion() const { return state_version_; }

 private:
  void bumpStateVersion();

  std::vector<std::unique_ptr<Layer>> layers_;
  bool training_ = true;
  Matrix input_;
  uint64_t state_version_;
};

enum class OutputActivation { kNone, kTanh };

/// Shape of an MLP: every hidden block is Linear -> [BatchNorm1d] -> ReLU -> [Dropout],
/// then Linear -> [Tanh].
struct MlpSpec {
  Index input_size = 0;
  std::vector<Index> hidden_sizes;
  Index output_size = 0;
  bool batch_norm = true;
  Scalar dropout = 0.1f;
  OutputActivation output_activation = OutputActivation::kNone;
};

/// Builds the MLP with weights drawn from init_rng. Throws std::invalid_argument on a size
/// < 1 or a dropout outside [0, 1).
Network makeMlp(const MlpSpec& spec, Rng& init_rng);

}  // namespace palcas::nn
