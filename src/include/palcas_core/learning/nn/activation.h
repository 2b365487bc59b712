#pragma once
// Element-wise activations, one layer type for all of them (they differ only in y = f(x)
// and dy/dx):
//   ReLU: y = max(0, x);
//   Tanh: y = tanh(x); bounds the parameter network's output to [-1, 1] before the agent
//     scales it to the acceleration range.

#include "palcas_core/learning/nn/layer.h"

namespace palcas::nn {

enum class ActivationKind { kReLU, kTanh };

/// An element-wise activation; no parameters. Defined for the kinds above in
/// lib/learning/nn/activation.cpp.
template <ActivationKind K>
class Activation : public Layer {
 public:
  /// size: features in = out. Throws std::invalid_argument if size < 1.
  explicit Activation(Index size);

  /// "ReLU" or "Tanh"
  std::string typeName() const override;
  std::string description() const override;
  Index inputSize() const override { return size_; }
  Index outputSize() const override { return size_; }
  const Matrix& forward(const Matrix& input, bool training) override;
  const Matrix& backward(const Matrix& grad_output, const BackwardOptions& options) override;
  std::unique_ptr<Layer> clone() const override;

 private:
  Index size_;
  bool has_forward_ = false;
  Matrix output_, grad_input_;
};

extern template class Activation<ActivationKind::kReLU>;
extern template class Activation<ActivationKind::kTanh>;

using ReLU = Activation<ActivationKind::kReLU>;
using Tanh = Activation<ActivationKind::kTanh>;

}  // namespace palcas::nn
