#include "palcas_core/learning/nn/dropout.h"

#include <cstdio>

#include "checks.h"
#include "palcas_core/common/rng.h"

namespace palcas::nn {

Dropout::Dropout(Index size, Scalar p) : size_(size), p_(p) {
  if (size < 1) throw std::invalid_argument("Dropout: size must be >= 1");
  if (!(p >= 0 && p < 1)) throw std::invalid_argument("Dropout: p must be in [0, 1)");
}

std::string Dropout::description() const {
  char text[64];
  std::snprintf(text, sizeof(text), "Dropout(%ld,%g)", static_cast<long>(size_),
                static_cast<double>(p_));
  return text;
}

const Matrix& Dropout::forward(const Matrix& input, bool training) {
  detail::checkBatch(input, size_, "Dropout::forward");
  has_forward_ = true;
  last_cols_ = input.cols();
  last_masked_ = training && p_ > 0;
  if (!last_masked_) return input;  // identity: no copy
  if (rng_ == nullptr) throw std::logic_error("Dropout::forward: training without a random source");
  // Keep a unit when a 32-bit uniform draw >= p * 2^32 (two draws per 64-bit word).
  const uint64_t threshold = static_cast<uint64_t>(static_cast<double>(p_) * 4294967296.0);
  const Scalar keep_scale = Scalar(1) / (Scalar(1) - p_);
  mask_.resize(size_, input.cols());
  Scalar* m = mask_.data();
  const Index count = mask_.size();
  for (Index i = 0; i < count; i += 2) {
    const uint64_t bits = rng_->nextU64();
    m[i] = (bits & 0xffffffffULL) >= threshold ? keep_scale : Scalar(0);
    if (i + 1 < count) m[i + 1] = (bits >> 32) >= threshold ? keep_scale : Scalar(0);
  }
  output_ = input.cwiseProduct(mask_);
  return output_;
}

const Matrix& Dropout::backward(const Matrix& grad_output, const BackwardOptions& /*options*/) {
  if (!has_forward_) throw std::logic_error("Dropout::backward without forward");
  detail::checkGrad(grad_output, size_, last_cols_, "Dropout::backward");
  if (!last_masked_) return grad_output;  // identity
  grad_input_ = grad_output.cwiseProduct(mask_);  // dy/dx = mask
  return grad_input_;
}

std::unique_ptr<Layer> Dropout::clone() const {
  auto copy = std::make_unique<Dropout>(size_, p_);
  copy->rng_ = rng_;
  return copy;
}

}  // namespace palcas::nn
