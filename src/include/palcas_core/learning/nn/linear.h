#pragma once
// Fully connected layer y = W x + b (W: out x in, b: out).

#include <cstdint>
#include <vector>

#include "palcas_core/learning/nn/bf16_gemm.h"
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

  /// true: forward and backward passes compute their products W x, G x^T and W^T G in
  /// bfloat16 with float sums (bf16Gemm) wherever the shapes fit its tiles (outputs a
  /// multiple of 32, inputs of 8, batch of 8; other products stay float). PdqnAgent turns it
  /// on for its gradient steps only, so its decisions stay float. Throws std::logic_error
  /// when turned on in a build without AVX-512 BF16.
  void setBf16Products(bool on);
  bool bf16Products() const { return bf16_; }

 private:
  Index in_, out_;
  const Matrix* input_ = nullptr;
  Matrix output_, grad_input_;
  bool bf16_ = false;
  // bf16 scratch, reused between calls: packed W, W^T or G, x in bf16, x^T, a product.
  Bf16Weights packed_;
  std::vector<uint16_t> bf16_x_;
  Matrix input_t_, product_;
};

}  // namespace palcas::nn
