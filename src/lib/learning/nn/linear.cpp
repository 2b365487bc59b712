#include "palcas_core/learning/nn/linear.h"

#include <cmath>
#include <stdexcept>

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

void Linear::setBf16Products(bool on) {
  if (on && !bf16GemmAvailable())
    throw std::logic_error("Linear::setBf16Products: this build has no AVX-512 BF16 (built for a CPU without it)");
  bf16_ = on;
}

namespace {
// bf16Gemm's tiles: 32 output rows, column pairs of depth, 8 columns of its input.
bool bf16Fits(Index rows, Index depth, Index cols) { return rows % 32 == 0 && depth % 2 == 0 && cols % 8 == 0; }
}  // namespace

const Matrix& Linear::forward(const Matrix& input, bool /*training*/) {
  detail::checkBatch(input, in_, "Linear::forward");
  input_ = &input;
  const Eigen::Map<const Vector> bias(params_.data() + out_ * in_, out_);
  if (bf16_ && bf16Fits(out_, in_, input.cols())) {
    packBf16Into(params_.data(), out_, in_, 1, out_, packed_);
    bf16Gemm(packed_, input, output_, bf16_x_);
    output_.colwise() += bias;
    return output_;
  }
  // y = W x + b, one column per sample: start from b and accumulate W x onto it (one pass
  // less than zero-fill, product, add bias).
  output_.resize(out_, input.cols());
  for (Index j = 0; j < input.cols(); ++j) output_.col(j) = bias;
  output_.noalias() += weight() * input;
  return output_;
}

const Matrix& Linear::backward(const Matrix& grad_output, const BackwardOptions& options) {
  if (input_ == nullptr) throw std::logic_error("Linear::backward without forward");
  detail::checkGrad(grad_output, out_, input_->cols(), "Linear::backward");
  const Index batch = grad_output.cols();
  if (options.param_grads) {
    // dL/dW = G X^T, dL/db = G 1 (sum over the batch).
    if (bf16_ && bf16Fits(out_, batch, in_)) {
      packBf16Into(grad_output.data(), out_, batch, 1, out_, packed_);
      input_t_ = input_->transpose();
      bf16Gemm(packed_, input_t_, product_, bf16_x_);
      Eigen::Map<Matrix>(grads_.data(), out_, in_) = product_;
    } else {
      Eigen::Map<Matrix>(grads_.data(), out_, in_).noalias() = grad_output * input_->transpose();
    }
    Eigen::Map<Vector>(grads_.data() + out_ * in_, out_) = grad_output.rowwise().sum();
  }
  // dL/dx = W^T G, only for the requested trailing rows (none for a first layer).
  const Index from = std::min(std::max<Index>(options.input_grad_from, 0), in_);
  if (bf16_ && from == 0 && bf16Fits(in_, out_, batch)) {
    packBf16Into(params_.data(), in_, out_, out_, 1, packed_);  // W^T(i, k) = W(k, i)
    bf16Gemm(packed_, grad_output, grad_input_, bf16_x_);
    return grad_input_;
  }
  grad_input_.resize(in_ - from, batch);
  if (from < in_) grad_input_.noalias() = weight().rightCols(in_ - from).transpose() * grad_output;
  return grad_input_;
}

std::unique_ptr<Layer> Linear::clone() const {
  auto copy = std::make_unique<Linear>(*this);
  copy->input_ = nullptr;
  return copy;
}

}  // namespace palcas::nn
