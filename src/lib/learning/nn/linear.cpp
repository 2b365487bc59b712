#include "palcas_core/learning/nn/linear.h"

#include <cmath>

#include "checks.h"
#include "palcas_core/common/rng.h"

namespace palcas::nn {

Linear::Linear(Index in, Index out, Rng& init_rng) : in_(in), out_(out) {
  if (in < 1 || out < 1)
    throw std::invalid_argument("Linear: sizes must be >= 1, got in=" + std::to_string(in) +
                                " out=" + std::to_string(out));
  params_ = Vector::Zero(out * in + out);
  grads_ = Vector::Zero(params_.size());
  // He uniform (He et al. 2015): Var(W) = 2/in keeps ReLU activations' scale per layer.
  const float bound = std::sqrt(6.0f / static_cast<float>(in));
  for (Index i = 0; i < out * in; ++i) params_[i] = init_rng.uniform(-bound, bound);
}

std::string Linear::description() const {
  return "Linear(" + std::to_string(in_) + "," + std::to_string(out_) + ")";
}

const Matrix& Linear::forward(const Matrix& input, bool /*training*/) {
  detail::checkBatch(input, in_, "Linear::forward");
  input_ = &input;
  // y = W x + b, one column per sample: start from b and accumulate W x onto it (one pass
  // less than zero-fill, product, add bias).
  const Eigen::Map<const Vector> bias(params_.data() + out_ * in_, out_);
  output_.resize(out_, input.cols());
  for (Index j = 0; j < input.cols(); ++j) output_.col(j) = bias;
  output_.noalias() += weight() * input;
  return output_;
}

const Matrix& Linear::backward(const Matrix& grad_output, const BackwardOptions& options) {
  if (input_ == nullptr) throw std::logic_error("Linear::backward without forward");
  detail::checkGrad(grad_output, out_, input_->cols(), "Linear::backward");
  if (options.param_grads) {
    // dL/dW = G X^T, dL/db = G 1 (sum over the batch).
    Eigen::Map<Matrix>(grads_.data(), out_, in_).noalias() = grad_output * input_->transpose();
    Eigen::Map<Vector>(grads_.data() + out_ * in_, out_) = grad_output.rowwise().sum();
  }
  // dL/dx = W^T G, only for the requested trailing rows (none for a first layer).
  const Index from = std::min(std::max<Index>(options.input_grad_from, 0), in_);
  grad_input_.resize(in_ - from, grad_output.cols());
  if (from < in_) grad_input_.noalias() = weight().rightCols(in_ - from).transpose() * grad_output;
  return grad_input_;
}

std::unique_ptr<Layer> Linear::clone() const {
  auto copy = std::make_unique<Linear>(*this);
  copy->input_ = nullptr;
  return copy;
}

}  // namespace palcas::nn
