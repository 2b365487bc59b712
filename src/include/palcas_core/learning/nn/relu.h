#pragma once
// Rectified linear unit y = max(0, x), element-wise.

#include "palcas_core/learning/nn/layer.h"

namespace palcas::nn {

/// ReLU activation; no parameters.
class ReLU : public Layer {
 public:
  /// size: features in = out. Throws std::invalid_argument if size < 1.
  explicit ReLU(Index size);

  std::string typeName() const override { return "ReLU"; }
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

}  // namespace palcas::nn
