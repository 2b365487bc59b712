#pragma once
// Inverted dropout (Srivastava et al. 2014): in training each unit is kept with
// probability 1 - p and scaled by 1/(1 - p), so eval mode is the identity.

#include "palcas_core/learning/nn/layer.h"

namespace palcas::nn {

/// Dropout with a seeded random source (set by setRng; training without one throws).
class Dropout : public Layer {
 public:
  /// Throws std::invalid_argument unless size >= 1 and 0 <= p < 1.
  Dropout(Index size, Scalar p);

  std::string typeName() const override { return "Dropout"; }
  std::string description() const override;
  Index inputSize() const override { return size_; }
  Index outputSize() const override { return size_; }
  /// Training with p > 0 and no random source: std::logic_error.
  const Matrix& forward(const Matrix& input, bool training) override;
  const Matrix& backward(const Matrix& grad_output, const BackwardOptions& options) override;
  std::unique_ptr<Layer> clone() const override;
  void setRng(Rng* rng) override { rng_ = rng; }

  Scalar probability() const { return p_; }

 private:
  Index size_;
  Scalar p_;
  Rng* rng_ = nullptr;
  bool has_forward_ = false, last_masked_ = false;
  Index last_cols_ = 0;
  Matrix mask_;  // 0 or 1/(1-p) per element of the last training forward
  Matrix output_, grad_input_;
};

}  // namespace palcas::nn
