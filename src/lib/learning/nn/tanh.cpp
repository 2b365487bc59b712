#include "palcas_core/learning/nn/tanh.h"

#include "checks.h"

namespace palcas::nn {

Tanh::Tanh(Index size) : size_(size) {
  if (size < 1) throw std::invalid_argument("Tanh: size must be >= 1");
}

std::string Tanh::description() const { return "Tanh(" + std::to_string(size_) + ")"; }

const Matrix& Tanh::forward(const Matrix& input, bool /*training*/) {
  detail::checkBatch(input, size_, "Tanh::forward");
  output_ = input.array().tanh().matrix();
  has_forward_ = true;
  return output_;
}

const Matrix& Tanh::backward(const Matrix& grad_output, const BackwardOptions& /*options*/) {
  if (!has_forward_) throw std::logic_error("Tanh::backward without forward");
  detail::checkGrad(grad_output, size_, output_.cols(), "Tanh::backward");
  // d tanh(x)/dx = 1 - tanh(x)^2 = 1 - y^2.
  grad_input_ = (grad_output.array() * (Scalar(1) - output_.array().square())).matrix();
  return grad_input_;
}

std::unique_ptr<Layer> Tanh::clone() const { return std::make_unique<Tanh>(size_); }

}  // namespace palcas::nn
