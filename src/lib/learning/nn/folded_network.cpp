#include "palcas_core/learning/nn/folded_network.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "checks.h"
#include "dense_kernel.h"
#include "palcas_core/learning/nn/batch_norm.h"
#include "palcas_core/learning/nn/linear.h"
#include "palcas_core/learning/nn/network.h"

namespace palcas::nn {

namespace {

[[noreturn]] void unfoldable(size_t index, const Layer& layer, const std::string& why) {
  throw std::invalid_argument("FoldedNetwork: layer " + std::to_string(index) + " (" +
                              layer.description() + ") " + why);
}

}  // namespace

FoldedNetwork::FoldedNetwork(const Network& network)
    : stages_(fold(network)), source_version_(network.stateVersion()) {}

bool FoldedNetwork::isCurrentFor(const Network& network) const {
  return !stages_.empty() && source_version_ == network.stateVersion();
}

bool FoldedNetwork::refresh(const Network& network) {
  if (isCurrentFor(network)) return false;
  stages_ = fold(network);  // may throw: assigned only on success
  source_version_ = network.stateVersion();
  return true;
}

std::vector<FoldedNetwork::Stage> FoldedNetwork::fold(const Network& network) {
  if (network.layerCount() == 0) throw std::invalid_argument("FoldedNetwork: empty network");
  // First check the chain and find each stage's Linear and batch norm; pack afterwards.
  struct Plan {
    const Linear* linear;
    const BatchNorm1d* bn;
    Activation activation;
  };
  std::vector<Plan> plans;
  for (size_t i = 0; i < network.layerCount(); ++i) {
    const Layer& layer = network.layer(i);
    const std::string type = layer.typeName();
    if (type == "Linear") {
      plans.push_back({static_cast<const Linear*>(&layer), nullptr, Activation::kNone});
    } else if (plans.empty()) {
      unfoldable(i, layer, "does not follow a Linear");
    } else if (type == "BatchNorm1d") {
      if (plans.back().bn != nullptr || plans.back().activation != Activation::kNone)
        unfoldable(i, layer, "must come right after its Linear to be folded");
      plans.back().bn = static_cast<const BatchNorm1d*>(&layer);
    } else if (type == "ReLU" || type == "Tanh") {
      if (plans.back().activation != Activation::kNone)
        unfoldable(i, layer, "is a second activation");
      plans.back().activation = type == "ReLU" ? Activation::kRelu : Activation::kTanh;
    } else if (type != "Dropout") {  // dropout is the identity in eval mode
      unfoldable(i, layer, "has no folded form");
    }
  }
  std::vector<Stage> stages;
  for (const Plan& plan : plans) {
    const Index out = plan.linear->outputSize();
    Vector bias = plan.linear->parameters().tail(out);
    Vector scale = Vector::Ones(out);
    if (plan.bn != nullptr) {
      // BN(Wx + b) = g (Wx + b - mu) / s + beta with s = sqrt(var + eps), so
      // W' = diag(g / s) W and b' = g / s (b - mu) + beta (eval mode: running statistics).
      const BatchNorm1d& bn = *plan.bn;
      scale = bn.gamma().cwiseProduct((bn.runningVar().array() + bn.eps()).rsqrt().matrix());
      bias = scale.cwiseProduct(bias - bn.runningMean()) + bn.beta();
    }
    stages.push_back(packStage(plan.linear->weight(), scale, bias, plan.activation));
  }
  return stages;
}

FoldedNetwork::Stage FoldedNetwork::packStage(const Eigen::Ref<const Matrix>& weight,
                                              const Vector& row_scale, const Vector& bias,
                                              Activation activation) {
  using detail::PANEL_ROWS;
  Stage s;
  s.in = weight.cols();
  s.out = weight.rows();
  s.activation = activation;
  const Index panels = (s.out + PANEL_ROWS - 1) / PANEL_ROWS;
  s.bias.assign(static_cast<size_t>(panels * PANEL_ROWS), Scalar(0));
  Eigen::Map<Vector>(s.bias.data(), s.out) = bias;
  if (s.out < detail::SMALL_OUTPUT) {  // a head: row-major W' for dot products
    s.weights.resize(static_cast<size_t>(s.out * s.in));
    Eigen::Map<Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        s.weights.data(), s.out, s.in) = row_scale.asDiagonal() * weight;
    return s;
  }
  // Panel p, input k: rows p*PANEL_ROWS.. of W'(:, k), contiguous in both (column-major W).
  s.weights.assign(static_cast<size_t>(panels * PANEL_ROWS * s.in), Scalar(0));
  for (Index p = 0; p < panels; ++p) {
    const Index row0 = p * PANEL_ROWS, rows = std::min(PANEL_ROWS, s.out - row0);
    for (Index k = 0; k < s.in; ++k)
      Eigen::Map<Vector>(s.weights.data() + (p * s.in + k) * PANEL_ROWS, rows) =
          row_scale.segment(row0, rows).cwiseProduct(weight.col(k).segment(row0, rows));
  }
  return s;
}

void FoldedNetwork::runStage(const Stage& stage, const Matrix& input, Matrix& output) {
  output.resize(stage.out, input.cols());
  const Scalar* w = stage.weights.data();
  const Scalar* b = stage.bias.data();
  const Index in = stage.in, out = stage.out, n = input.cols();
  if (out < detail::SMALL_OUTPUT) {
    detail::smallForward(w, b, in, out, input.data(), n, output.data());
    if (stage.activation == Activation::kRelu) output = output.cwiseMax(Scalar(0));
  } else if (stage.activation == Activation::kRelu) {
    detail::denseForward<true>(w, b, in, out, input.data(), n, output.data());
  } else {
    detail::denseForward<false>(w, b, in, out, input.data(), n, output.data());
  }
  // Same expression as the Tanh layer, so the bounded output matches it.
  if (stage.activation == Activation::kTanh) output = output.array().tanh().matrix();
}

const Matrix& FoldedNetwork::forward(const Matrix& input) {
  if (stages_.empty()) throw std::logic_error("FoldedNetwork::forward: nothing folded");
  detail::checkBatch(input, inputSize(), "FoldedNetwork::forward");
  const Matrix* x = &input;
  for (size_t i = 0; i < stages_.size(); ++i) {
    Matrix& y = scratch_[i % 2];
    runStage(stages_[i], *x, y);
    x = &y;
  }
  return *x;
}

}  // namespace palcas::nn
