#include "palcas_core/learning/nn/adamw.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "palcas_core/common/checks.h"
#include "palcas_core/learning/nn/network.h"
#include "palcas_core/learning/nn/serialization.h"

namespace palcas::nn {

AdamW::AdamW(const AdamWConfig& c) : config_(c) {
  using common::require;
  require(std::isfinite(c.learning_rate) && c.learning_rate >= 0,
          "AdamW: learning_rate must be >= 0");
  require(c.beta1 >= 0 && c.beta1 < 1, "AdamW: beta1 must be in [0, 1)");
  require(c.beta2 >= 0 && c.beta2 < 1, "AdamW: beta2 must be in [0, 1)");
  require(std::isfinite(c.eps) && c.eps > 0, "AdamW: eps must be > 0");
  require(std::isfinite(c.weight_decay) && c.weight_decay >= 0, "AdamW: weight_decay must be >= 0");
}

void AdamW::step(Network& network) {
  const Index count = network.parameterCount();
  if (step_ == 0 && m_.size() == 0) {
    m_ = Vector::Zero(count);
    v_ = Vector::Zero(count);
  }
  if (m_.size() != count)
    throw std::invalid_argument("AdamW::step: network has " + std::to_string(count) +
                                " parameters, the optimiser state " + std::to_string(m_.size()));
  ++step_;
  const Scalar lr = config_.learning_rate, b1 = config_.beta1, b2 = config_.beta2;
  const Scalar decay = Scalar(1) - lr * config_.weight_decay;
  const double t = static_cast<double>(step_);
  const Scalar step_size = static_cast<Scalar>(lr / (1.0 - std::pow(double(b1), t)));
  const Scalar inv_bc2_sqrt = static_cast<Scalar>(1.0 / std::sqrt(1.0 - std::pow(double(b2), t)));
  Index offset = 0;
  for (size_t i = 0; i < network.layerCount(); ++i) {
    Layer& layer = network.layer(i);
    const Index n = layer.parameters().size();
    if (n == 0) continue;
    // Chunks small enough for L1, so the four statements read each value from memory once
    // instead of four times (same arithmetic per value).
    constexpr Index CHUNK = 1024;
    for (Index start = 0; start < n; start += CHUNK) {
      const Index len = std::min(CHUNK, n - start);
      auto p = layer.parameters().segment(start, len).array();
      const auto g = layer.gradients().segment(start, len).array();
      auto m = m_.segment(offset + start, len).array();
      auto v = v_.segment(offset + start, len).array();
      p *= decay;
      m = b1 * m + (1 - b1) * g;
      v = b2 * v + (1 - b2) * g.square();
      p -= step_size * m / (v.sqrt() * inv_bc2_sqrt + config_.eps);
    }
    offset += n;
  }
}

void AdamW::write(ByteWriter& out) const {
  out.u64(step_);
  out.floats(m_.data(), static_cast<size_t>(m_.size()));
  out.floats(v_.data(), static_cast<size_t>(v_.size()));
}

void AdamW::read(ByteReader& in) {
  const uint64_t step = in.u64();
  std::vector<Scalar> m = in.floats();
  std::vector<Scalar> v = in.floats();
  if (m.size() != v.size() || (step > 0 && m.empty()))
    throw std::runtime_error("AdamW::read: inconsistent optimiser record");
  step_ = step;
  m_ = Eigen::Map<Vector>(m.data(), static_cast<Index>(m.size()));
  v_ = Eigen::Map<Vector>(v.data(), static_cast<Index>(v.size()));
}

}  // namespace palcas::nn
