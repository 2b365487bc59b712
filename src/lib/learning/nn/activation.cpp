#include "palcas_core/learning/nn/activation.h"

#include "checks.h"

namespace palcas::nn {

template <ActivationKind K>
Activation<K>::Activation(Index size) : size_(size) {
  if (size < 1) throw std::invalid_argument(typeName() + ": size must be >= 1");
}

template <ActivationKind K>
std::string Activation<K>::typeName() const {
  return K == ActivationKind::kReLU ? "ReLU" : "Tanh";
}

template <ActivationKind K>
std::string Activation<K>::description() const {
  return typeName() + "(" + std::to_string(size_) + ")";
}

template <ActivationKind K>
const Matrix& Activation<K>::forward(const Matrix& input, bool /*training*/) {
  detail::checkBatch(input, size_, typeName() + "::forward");
  if constexpr (K == ActivationKind::kReLU) {
    output_ = input.cwiseMax(Scalar(0));  // y = max(0, x)
  } else {
    output_ = input.array().tanh().matrix();
  }
  has_forward_ = true;
  return output_;
}

template <ActivationKind K>
const Matrix& Activation<K>::backward(const Matrix& grad_output,
                                      const BackwardOptions& /*options*/) {
  if (!has_forward_) throw std::logic_error(typeName() + "::backward without forward");
  detail::checkGrad(grad_output, size_, output_.cols(), typeName() + "::backward");
  if constexpr (K == ActivationKind::kReLU) {
    // dy/dx = 1 where x > 0 (equivalently y > 0), else 0 (PyTorch's choice at x = 0).
    grad_input_ = (output_.array() > Scalar(0)).select(grad_output, Scalar(0));
  } else {
    // d tanh(x)/dx = 1 - tanh(x)^2 = 1 - y^2.
    grad_input_ = (grad_output.array() * (Scalar(1) - output_.array().square())).matrix();
  }
  return grad_input_;
}

template <ActivationKind K>
std::unique_ptr<Layer> Activation<K>::clone() const {
  return std::make_unique<Activation<K>>(size_);
}

template class Activation<ActivationKind::kReLU>;
template class Activation<ActivationKind::kTanh>;

}  // namespace palcas::nn
