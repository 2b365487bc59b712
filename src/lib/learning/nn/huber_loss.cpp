#include "palcas_core/learning/nn/huber_loss.h"

#include <stdexcept>
#include <string>

namespace palcas::nn {

HuberLoss::HuberLoss(Scalar delta) : delta_(delta) {
  if (!(delta > 0)) throw std::invalid_argument("HuberLoss: delta must be > 0");
}

Scalar HuberLoss::compute(const Matrix& prediction, const Matrix& target) {
  if (prediction.rows() != target.rows() || prediction.cols() != target.cols() ||
      prediction.size() == 0)
    throw std::invalid_argument("HuberLoss: prediction " + std::to_string(prediction.rows()) +
                                "x" + std::to_string(prediction.cols()) + " vs target " +
                                std::to_string(target.rows()) + "x" +
                                std::to_string(target.cols()) + " (need equal, non-empty)");
  const auto d = (prediction - target).array();
  const auto abs_d = d.abs();
  // Quadratic inside |d| <= delta, linear outside; accumulate in double for the mean.
  const double sum = (abs_d <= delta_)
                         .select(Scalar(0.5) * d.square(), delta_ * (abs_d - Scalar(0.5) * delta_))
                         .template cast<double>()
                         .sum();
  const Scalar inv_count = Scalar(1) / static_cast<Scalar>(prediction.size());
  gradient_ = (d.max(-delta_).min(delta_) * inv_count).matrix();
  return static_cast<Scalar>(sum / static_cast<double>(prediction.size()));
}

}  // namespace palcas::nn
