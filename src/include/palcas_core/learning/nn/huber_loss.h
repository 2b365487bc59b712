#pragma once
// Huber (smooth L1) loss, mean over all elements, as PyTorch's HuberLoss(delta):
//   l(d) = 0.5 d^2             if |d| <= delta
//        = delta (|d| - delta/2) otherwise,      d = prediction - target.

#include "palcas_core/learning/nn/types.h"

namespace palcas::nn {

/// Huber loss with its gradient w.r.t. the prediction.
class HuberLoss {
 public:
  /// Throws std::invalid_argument unless delta > 0.
  explicit HuberLoss(Scalar delta = 1.0f);

  /// Returns mean_i l(pred_i - target_i) and stores the gradient
  /// dL/dpred_i = clamp(d_i, -delta, delta) / count. Throws std::invalid_argument if the
  /// shapes differ or are empty.
  Scalar compute(const Matrix& prediction, const Matrix& target);
  /// Gradient of the last compute(), same shape as its prediction.
  const Matrix& gradient() const { return gradient_; }

 private:
  Scalar delta_;
  Matrix gradient_;
};

}  // namespace palcas::nn
