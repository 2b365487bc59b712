#include "palcas_core/learning/nn/network.h"

#include <atomic>
#include <stdexcept>

#include "checks.h"
#include "palcas_core/learning/nn/activation.h"
#include "palcas_core/learning/nn/batch_norm.h"
#include "palcas_core/learning/nn/dropout.h"
#include "palcas_core/learning/nn/linear.h"
#include "palcas_core/learning/nn/serialization.h"

namespace palcas::nn {

namespace {
// Process-wide source of state versions, so equal versions mean the same network AND the
// same state (a copy of a network gets a new version).
std::atomic<uint64_t> next_state_version{1};
}  // namespace

void Network::bumpStateVersion() {
  state_version_ = next_state_version.fetch_add(1, std::memory_order_relaxed);
}

Network::Network() { bumpStateVersion(); }

Network::Network(const Network& other) : training_(other.training_) {
  for (const auto& layer : other.layers_) layers_.push_back(layer->clone());
  bumpStateVersion();
}

Network& Network::operator=(const Network& other) {
  if (this != &other) {
    Network copy(other);
    *this = std::move(copy);
  }
  return *this;
}

void Network::addLayer(std::unique_ptr<Layer> layer) {
  if (!layer) throw std::invalid_argument("Network::addLayer: null layer");
  if (!layers_.empty() && layer->inputSize() != layers_.back()->outputSize())
    throw std::invalid_argument("Network::addLayer: " + layer->description() +
                                " does not fit after " + layers_.back()->description());
  layers_.push_back(std::move(layer));
  bumpStateVersion();
}

Index Network::inputSize() const { return layers_.empty() ? 0 : layers_.front()->inputSize(); }
Index Network::outputSize() const { return layers_.empty() ? 0 : layers_.back()->outputSize(); }

const Matrix& Network::forward(const Matrix& input) {
  if (layers_.empty()) throw std::logic_error("Network::forward: no layers");
  detail::checkBatch(input, inputSize(), "Network::forward");
  input_ = input;
  if (training_) bumpStateVersion();  // batch norm updates its running statistics
  const Matrix* x = &input_;
  for (auto& layer : layers_) x = &layer->forward(*x, training_);
  return *x;
}

const Matrix& Network::backward(const Matrix& grad_output, const BackwardOptions& options) {
  if (layers_.empty()) throw std::logic_error("Network::backward: no layers");
  const Matrix* g = &grad_output;
  for (size_t i = layers_.size(); i-- > 0;) {
    BackwardOptions layer_options{options.param_grads, i == 0 ? options.input_grad_from : 0};
    g = &layers_[i]->backward(*g, layer_options);
  }
  return *g;
}

Index Network::parameterCount() const {
  Index count = 0;
  for (const auto& layer : layers_) count += layer->parameters().size();
  return count;
}

Index Network::bufferCount() const {
  Index count = 0;
  for (const auto& layer : layers_) count += layer->buffers().size();
  return count;
}

Vector Network::getParameters() const {
  Vector out(parameterCount());
  Index offset = 0;
  for (const auto& layer : layers_) {
    out.segment(offset, layer->parameters().size()) = layer->parameters();
    offset += layer->parameters().size();
  }
  return out;
}

void Network::setParameters(const Vector& values) {
  if (values.size() != parameterCount())
    throw std::invalid_argument("Network::setParameters: expected " +
                                std::to_string(parameterCount()) + " values, got " +
                                std::to_string(values.size()));
  if (!values.allFinite())
    throw std::invalid_argument("Network::setParameters: non-finite value");
  Index offset = 0;
  for (auto& layer : layers_) {
    layer->parameters() = values.segment(offset, layer->parameters().size());
    offset += layer->parameters().size();
  }
  bumpStateVersion();
}

Vector Network::getState() const {
  Vector out(stateCount());
  out.head(parameterCount()) = getParameters();
  Index offset = parameterCount();
  for (const auto& layer : layers_) {
    out.segment(offset, layer->buffers().size()) = layer->buffers();
    offset += layer->buffers().size();
  }
  return out;
}

std::vector<Network::StateSpan> Network::stateSpansFrom(size_t first_layer) const {
  if (first_layer > layers_.size())
    throw std::out_of_range("Network::stateSpansFrom: layer " + std::to_string(first_layer) + " of " +
                            std::to_string(layers_.size()));
  Index params_before = 0, buffers_before = 0, params_after = 0, buffers_after = 0;
  for (size_t i = 0; i < layers_.size(); ++i) {
    (i < first_layer ? params_before : params_after) += layers_[i]->parameters().size();
    (i < first_layer ? buffers_before : buffers_after) += layers_[i]->buffers().size();
  }
  std::vector<StateSpan> spans;
  if (params_after > 0) spans.push_back({params_before, params_after});
  if (buffers_after > 0) spans.push_back({parameterCount() + buffers_before, buffers_after});
  return spans;
}

void Network::setState(const Scalar* values, Index count) {
  if (count != stateCount())
    throw std::invalid_argument("Network::setState: expected " + std::to_string(stateCount()) +
                                " values, got " + std::to_string(count));
  Eigen::Map<const Vector> all(values, count);
  if (!all.allFinite()) throw std::invalid_argument("Network::setState: non-finite value");
  Index offset = 0;
  for (auto& layer : layers_) {
    layer->parameters() = all.segment(offset, layer->parameters().size());
    offset += layer->parameters().size();
  }
  for (auto& layer : layers_) {
    layer->buffers() = all.segment(offset, layer->buffers().size());
    offset += layer->buffers().size();
  }
  bumpStateVersion();
}

std::string Network::layout() const {
  std::string text;
  for (const auto& layer : layers_) text += (text.empty() ? "" : ";") + layer->description();
  return text;
}

uint64_t Network::layoutChecksum() const { return fnv1a64(layout()); }

void Network::setRng(Rng* rng) {
  for (auto& layer : layers_) layer->setRng(rng);
}

void Network::setBf16Products(bool on) {
  for (auto& layer : layers_)
    if (auto* linear = dynamic_cast<Linear*>(layer.get())) linear->setBf16Products(on);
}

Network makeMlp(const MlpSpec& spec, Rng& init_rng) {
  if (spec.input_size < 1 || spec.output_size < 1)
    throw std::invalid_argument("makeMlp: input and output sizes must be >= 1");
  Network net;
  Index in = spec.input_size;
  for (Index width : spec.hidden_sizes) {
    if (width < 1) throw std::invalid_argument("makeMlp: hidden sizes must be >= 1");
    // Block order Linear -> BN -> ReLU -> Dropout: BN normalises the pre-activation (as in
    // Ioffe & Szegedy), dropout acts on the activation so dropped units are true zeros.
    net.addLayer(std::make_unique<Linear>(in, width, init_rng));
    if (spec.batch_norm) net.addLayer(std::make_unique<BatchNorm1d>(width));
    net.addLayer(std::make_unique<ReLU>(width));
    if (spec.dropout > 0) net.addLayer(std::make_unique<Dropout>(width, spec.dropout));
    in = width;
  }
  net.addLayer(std::make_unique<Linear>(in, spec.output_size, init_rng));
  if (spec.output_activation == OutputActivation::kTanh)
    net.addLayer(std::make_unique<Tanh>(spec.output_size));
  return net;
}

}  // namespace palcas::nn
