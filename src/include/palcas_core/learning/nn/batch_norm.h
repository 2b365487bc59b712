#pragma once
// Batch normalisation over the batch, per feature (Ioffe & Szegedy 2015), with PyTorch's
// BatchNorm1d semantics: training mode normalises with the batch statistics and updates
// the running statistics; eval mode normalises with the running statistics.

#include "palcas_core/learning/nn/layer.h"

namespace palcas::nn {

/// BatchNorm1d. Parameters: gamma (size), beta (size). Buffers: running_mean (size),
/// running_var (size); initial 0 and 1.
class BatchNorm1d : public Layer {
 public:
  /// Throws std::invalid_argument unless size >= 1, 0 < momentum <= 1, eps > 0.
  explicit BatchNorm1d(Index size, Scalar momentum = 0.1f, Scalar eps = 1e-5f);

  std::string typeName() const override { return "BatchNorm1d"; }
  std::string description() const override;
  Index inputSize() const override { return size_; }
  Index outputSize() const override { return size_; }
  /// Training mode needs a batch of >= 2 columns (std::invalid_argument otherwise, like
  /// PyTorch): the variance of one sample is undefined.
  const Matrix& forward(const Matrix& input, bool training) override;
  const Matrix& backward(const Matrix& grad_output, const BackwardOptions& options) override;
  std::unique_ptr<Layer> clone() const override;

  Eigen::Map<const Vector> gamma() const { return {params_.data(), size_}; }
  Eigen::Map<const Vector> beta() const { return {params_.data() + size_, size_}; }
  Eigen::Map<const Vector> runningMean() const { return {buffers_.data(), size_}; }
  Eigen::Map<const Vector> runningVar() const { return {buffers_.data() + size_, size_}; }
  Scalar momentum() const { return momentum_; }
  /// Added to the variance before the square root.
  Scalar eps() const { return eps_; }

 private:
  Index size_;
  Scalar momentum_, eps_;
  bool has_forward_ = false, last_training_ = false;
  Vector inv_std_;  // 1 / sqrt(var + eps) of the last forward (batch or running var)
  Matrix xhat_;     // normalised input of the last forward
  Matrix output_, grad_input_;
};

}  // namespace palcas::nn
