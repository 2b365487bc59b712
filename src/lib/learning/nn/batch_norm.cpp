#include "palcas_core/learning/nn/batch_norm.h"

#include <sstream>

#include "checks.h"

namespace palcas::nn {

BatchNorm1d::BatchNorm1d(Index size, Scalar momentum, Scalar eps)
    : size_(size), momentum_(momentum), eps_(eps) {
  if (size < 1) throw std::invalid_argument("BatchNorm1d: size must be >= 1");
  if (!(momentum > 0 && momentum <= 1))
    throw std::invalid_argument("BatchNorm1d: momentum must be in (0, 1]");
  if (!(eps > 0)) throw std::invalid_argument("BatchNorm1d: eps must be > 0");
  params_.resize(2 * size);
  params_ << Vector::Ones(size), Vector::Zero(size);  // gamma = 1, beta = 0
  grads_ = Vector::Zero(2 * size);
  buffers_.resize(2 * size);
  buffers_ << Vector::Zero(size), Vector::Ones(size);  // running mean 0, running var 1
}

std::string BatchNorm1d::description() const {
  return "BatchNorm1d(" + std::to_string(size_) + ")";
}

const Matrix& BatchNorm1d::forward(const Matrix& input, bool training) {
  detail::checkBatch(input, size_, "BatchNorm1d::forward");
  const Index n = input.cols();
  Eigen::Map<Vector> running_mean(buffers_.data(), size_);
  Eigen::Map<Vector> running_var(buffers_.data() + size_, size_);
  if (training) {
    if (n < 2)
      throw std::invalid_argument("BatchNorm1d::forward: training needs a batch of >= 2, got 1");
    // mu_B = (1/N) sum x ; var_B = (1/N) sum (x - mu_B)^2 (biased, used to normalise).
    const Vector mean = input.rowwise().mean();
    xhat_ = input.colwise() - mean;
    const Vector var = xhat_.array().square().rowwise().mean();
    inv_std_ = (var.array() + eps_).rsqrt();
    // Running stats (PyTorch): r = (1 - m) r + m stat, with the UNBIASED batch variance.
    running_mean = (1 - momentum_) * running_mean + momentum_ * mean;
    running_var = (1 - momentum_) * running_var +
                  momentum_ * var * (static_cast<Scalar>(n) / static_cast<Scalar>(n - 1));
  } else {
    xhat_ = input.colwise() - Vector(running_mean);
    inv_std_ = (running_var.array() + eps_).rsqrt();
  }
  // xhat = (x - mean) / sqrt(var + eps); y = gamma xhat + beta.
  xhat_ = inv_std_.asDiagonal() * xhat_;
  output_.resize(size_, n);
  output_.noalias() = Vector(gamma()).asDiagonal() * xhat_;
  output_.colwise() += beta();
  has_forward_ = true;
  last_training_ = training;
  return output_;
}

const Matrix& BatchNorm1d::backward(const Matrix& grad_output, const BackwardOptions& options) {
  if (!has_forward_) throw std::logic_error("BatchNorm1d::backward without forward");
  detail::checkGrad(grad_output, size_, xhat_.cols(), "BatchNorm1d::backward");
  // dgamma = sum_n dy xhat ; dbeta = sum_n dy.
  const Vector dgamma = (grad_output.array() * xhat_.array()).rowwise().sum();
  const Vector dbeta = grad_output.rowwise().sum();
  if (options.param_grads) grads_ << dgamma, dbeta;
  const Vector scale = gamma().cwiseProduct(inv_std_);
  if (last_training_) {
    // Batch statistics depend on x: dx = gamma/sigma (dy - dbeta/N - xhat dgamma/N).
    const Scalar inv_n = Scalar(1) / static_cast<Scalar>(xhat_.cols());
    grad_input_ = (grad_output.colwise() - dbeta * inv_n);
    grad_input_.array() -= xhat_.array().colwise() * (dgamma.array() * inv_n);
    grad_input_ = scale.asDiagonal() * grad_input_;
  } else {
    // Running statistics are constants: dx = gamma/sigma dy.
    grad_input_.noalias() = scale.asDiagonal() * grad_output;
  }
  return grad_input_;
}

std::unique_ptr<Layer> BatchNorm1d::clone() const {
  auto copy = std::make_unique<BatchNorm1d>(size_, momentum_, eps_);
  copy->params_ = params_;
  copy->buffers_ = buffers_;
  return copy;
}

}  // namespace palcas::nn
