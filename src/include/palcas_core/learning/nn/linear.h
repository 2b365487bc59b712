#pragma once
// Fully connected layer y = W x + b (W: out x in, b: out).

#include "palcas_core/learning/nn/layer.h"

namespace palcas::nn {

/// Dense layer. Parameter order: W column-major (out*in values), then b (out values).
class Linear : public Layer {
 public:
  /// He/Kaiming uniform init for ReLU nets: W ~ U(-sqrt(6/in), sqrt(6/in)), b = 0.
  /// Throws std::invalid_argument unless in, out >= 1.
  Linear(Index in, Index out, Rng& init_rng);

  std::string typeName() const override { return "Linear"; }
  std::string description() const override;
  Index inputSize() const override { return in_; }
  Index outputSize() const override { return out_; }
  const Matrix& forward(const Matrix& input, bool training) override;
  const Matrix& backward(const Matrix& grad_output, const BackwardOptions& options) override;
  std::unique_ptr<Layer> clone() const override;

  Eigen::Map<Matrix> weight() { return Eigen::Map<Matrix>(params_.data(), out_, in_); }
  Eigen::Map<const Matrix> weight() const {
    return Eigen::Map<const Matrix>(params_.data(), out_, in_);
  }
  Eigen::Map<Vector> bias() { return Eigen::Map<Vector>(params_.data() + out_ * in_, out_); }

 private:
  Index in_, out_;
  const Matrix* input_ = nullptr;
  Matrix output_, grad_input_;
};

}  // namespace palcas::nn
