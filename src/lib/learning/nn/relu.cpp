#include "palcas_core/learning/nn/relu.h"

#include "checks.h"

namespace palcas::nn {

ReLU::ReLU(Index size) : size_(size) {
  if (size < 1) throw std::invalid_argument("ReLU: size must be >= 1");
}

std::string ReLU::description() const { return "ReLU(" + std::to_string(size_) + ")"; }

const Matrix& ReLU::forward(const Matrix& input, bool /*training*/) {
  detail::checkBatch(input, size_, "ReLU::forward");
  output_ = input.cwiseMax(Scalar(0));  // y = max(0, x)
  has_forward_ = true;
  return output_;
}

const Matrix& ReLU::backward(const Matrix& grad_output, const BackwardOptions& /*options*/) {
  if (!has_forward_) throw std::logic_error("ReLU::backward without forward");
  detail::checkGrad(grad_output, size_, output_.cols(), "ReLU::backward");
  // dy/dx = 1 where x > 0 (equivalently y > 0), else 0 (PyTorch's choice at x = 0).
  grad_input_ = (output_.array() > Scalar(0)).select(grad_output, Scalar(0));
  return grad_input_;
}

std::unique_ptr<Layer> ReLU::clone() const { return std::make_unique<ReLU>(size_); }

}  // namespace palcas::nn
