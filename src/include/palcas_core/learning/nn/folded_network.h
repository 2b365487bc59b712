#pragma once
// Eval-mode inference snapshot of a Network: every BatchNorm1d folded into the Linear before
// it, bias and activation fused into the matrix product, dropout dropped (identity in eval
// mode), weights pre-packed for a register-blocked kernel. What the agent's decisions and TD
// targets run on; training keeps the layer-by-layer Network.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "palcas_core/learning/nn/types.h"

namespace palcas::nn {

class Network;

/// A Network's eval-mode function y = f(x), folded. Copyable; not thread-safe (forward
/// writes scratch buffers).
class FoldedNetwork {
 public:
  /// Empty: isCurrentFor() is false for every network, forward() throws.
  FoldedNetwork() = default;
  /// Folds `network` as it is now (parameters and running statistics). The chain must be
  /// blocks of Linear, then optionally BatchNorm1d, then optionally ReLU or Tanh, with
  /// Dropout anywhere after a Linear (what makeMlp builds). Throws std::invalid_argument
  /// naming the layer otherwise, or if the network is empty.
  explicit FoldedNetwork(const Network& network);

  /// True if this was folded from `network` in its current state (Network::stateVersion).
  bool isCurrentFor(const Network& network) const;
  /// Re-folds from `network` unless isCurrentFor(network); returns whether it re-folded.
  /// Throws like the constructor (this stays unchanged then).
  bool refresh(const Network& network);

  bool empty() const { return stages_.empty(); }
  Index inputSize() const { return stages_.empty() ? 0 : stages_.front().in; }
  Index outputSize() const { return stages_.empty() ? 0 : stages_.back().out; }

  /// The network's eval-mode output for `input` (inputSize() x n, n >= 1), valid until the
  /// next forward(). Within float rounding of Network::forward in eval mode; column j of the
  /// result depends on column j of the input only, bit for bit (a CAV's decision does not
  /// depend on which other CAVs share the batch). Throws std::invalid_argument on a wrong
  /// row count or an empty batch, std::logic_error if empty().
  const Matrix& forward(const Matrix& input);

 private:
  enum class Activation { kNone, kRelu, kTanh };
  /// One Linear (+ folded BN) + activation. weights: ceil(out / PANEL_ROWS) panels; panel p
  /// holds, for k = 0..in-1, rows p*PANEL_ROWS .. +PANEL_ROWS of column k (zero padded);
  /// heads with fewer outputs than one vector are stored row-major instead.
  struct Stage {
    Index in = 0, out = 0;
    std::vector<Scalar, Eigen::aligned_allocator<Scalar>> weights;
    std::vector<Scalar, Eigen::aligned_allocator<Scalar>> bias;  // padded to whole panels
    Activation activation = Activation::kNone;
  };

  static std::vector<Stage> fold(const Network& network);
  /// W' = diag(row_scale) weight, packed; b' = bias.
  static Stage packStage(const Eigen::Ref<const Matrix>& weight, const Vector& row_scale,
                         const Vector& bias, Activation activation);
  static void runStage(const Stage& stage, const Matrix& input, Matrix& output);

  std::vector<Stage> stages_;
  uint64_t source_version_ = 0;  // Network::stateVersion() folded from; 0 = none
  Matrix scratch_[2];
};

}  // namespace palcas::nn
