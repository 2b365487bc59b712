// PdqnAgent: model export/import and checkpoints (file format: nn/serialization.h).
#include <cmath>
#include <stdexcept>

#include "palcas_core/learning/nn/serialization.h"
#include "palcas_core/learning/pdqn_agent.h"

namespace palcas {

namespace {
// 2: each transition stores the valid actions of its next state. 1: none stored (the agent
// read them out of the next state's ego-lane feature); read with a mask rebuild.
constexpr uint32_t CHECKPOINT_EXTRA_VERSION = 2;
constexpr uint32_t CHECKPOINT_EXTRA_VERSION_WITHOUT_MASKS = 1;
}

std::string PdqnAgent::layoutId() const {
  return std::string("palcas-pdqn/1 ") + (config_.multi_pass ? "mp-dqn" : "p-dqn") + " mu[" +
         mu_.layout() + "] q[" + q_.layout() + "]";
}

uint64_t PdqnAgent::layoutChecksum() const { return nn::fnv1a64(layoutId()); }

ModelBlob PdqnAgent::exportModel() const {
  ModelBlob blob;
  blob.layout_id = layoutId();
  blob.layout_checksum = layoutChecksum();
  const nn::Vector mu = mu_.getState(), q = q_.getState();
  blob.values.reserve(static_cast<size_t>(mu.size() + q.size()));
  blob.values.assign(mu.data(), mu.data() + mu.size());
  blob.values.insert(blob.values.end(), q.data(), q.data() + q.size());
  return blob;
}

void PdqnAgent::importModel(const ModelBlob& blob) {
  if (blob.layout_id != layoutId())
    throw std::invalid_argument("PdqnAgent::importModel: model layout '" + blob.layout_id +
                                "' differs from this agent's '" + layoutId() + "'");
  validateModelBlob(blob);  // checksum and finiteness, index named
  const nn::Index mu_count = mu_.stateCount(), q_count = q_.stateCount();
  if (static_cast<nn::Index>(blob.values.size()) != mu_count + q_count)
    throw std::invalid_argument("PdqnAgent::importModel: " + std::to_string(blob.values.size()) +
                                " values, the layout needs " +
                                std::to_string(mu_count + q_count));
  // Every check passed, so neither setState can throw half-way.
  mu_.setState(blob.values.data(), mu_count);
  q_.setState(blob.values.data() + mu_count, q_count);
}

std::vector<nn::Network::StateSpan> PdqnAgent::headSpans(size_t linear_layers) const {
  std::vector<nn::Network::StateSpan> spans;
  if (linear_layers == 0) return spans;
  nn::Index offset = 0;
  for (const nn::Network* net : {&mu_, &q_}) {
    std::vector<size_t> linear;
    for (size_t i = 0; i < net->layerCount(); ++i)
      if (net->layer(i).typeName() == "Linear") linear.push_back(i);
    if (linear_layers >= linear.size())
      throw std::invalid_argument("PdqnAgent::headSpans: a head of " + std::to_string(linear_layers) +
                                  " Linear layers, the network has " + std::to_string(linear.size()) +
                                  " (at least one must stay shared)");
    for (nn::Network::StateSpan span : net->stateSpansFrom(linear[linear.size() - linear_layers])) {
      span.begin += offset;
      spans.push_back(span);
    }
    offset += net->stateCount();
  }
  return spans;
}

void PdqnAgent::saveModel(const std::string& path) const { saveModelBlob(exportModel(), path); }

void PdqnAgent::loadModel(const std::string& path) {
  const ModelBlob blob = loadModelBlob(path);
  try {
    importModel(blob);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

std::string PdqnAgent::writeExtra() const {
  nn::ByteWriter w;
  w.u32(CHECKPOINT_EXTRA_VERSION);
  const nn::Vector mu_t = mu_target_.getState(), q_t = q_target_.getState();
  w.floats(mu_t.data(), static_cast<size_t>(mu_t.size()));
  w.floats(q_t.data(), static_cast<size_t>(q_t.size()));
  mu_opt_.write(w);
  q_opt_.write(w);
  replay_.write(w);
  w.f64(epsilon_);
  w.u64(gradient_steps_);
  w.u64(decision_rounds_);
  w.str(rng_->state());
  return w.bytes();
}

void PdqnAgent::readExtra(const std::string& extra, const std::string& what,
                          const NextStateMaskRebuild& rebuild_masks) {
  nn::ByteReader r(extra, what + " (checkpoint state)");
  const uint32_t version = r.u32();
  const bool without_masks = version == CHECKPOINT_EXTRA_VERSION_WITHOUT_MASKS;
  if (version != CHECKPOINT_EXTRA_VERSION && !without_masks)
    throw std::runtime_error(what + ": checkpoint state version " + std::to_string(version) +
                             ", expected " + std::to_string(CHECKPOINT_EXTRA_VERSION));
  if (without_masks && !rebuild_masks)
    throw std::runtime_error(what + ": checkpoint state version " + std::to_string(version) +
                             " stores no valid-action masks with its transitions, and no way "
                             "to rebuild them from the next states was given");
  const std::vector<float> mu_t = r.floats(), q_t = r.floats();
  try {
    mu_target_.setState(mu_t.data(), static_cast<nn::Index>(mu_t.size()));
    q_target_.setState(q_t.data(), static_cast<nn::Index>(q_t.size()));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(what + ": target network: " + e.what());
  }
  mu_opt_.read(r);
  q_opt_.read(r);
  if ((mu_opt_.momentSize() != 0 && mu_opt_.momentSize() != mu_.parameterCount()) ||
      (q_opt_.momentSize() != 0 && q_opt_.momentSize() != q_.parameterCount()))
    throw std::runtime_error(what + ": optimiser state does not match the networks");
  if (without_masks)
    replay_.readWithoutMasks(r, rebuild_masks);
  else
    replay_.read(r);
  epsilon_ = r.f64();
  if (!(epsilon_ >= 0 && epsilon_ <= 1))
    throw std::runtime_error(what + ": epsilon " + std::to_string(epsilon_) + " outside [0, 1]");
  gradient_steps_ = r.u64();
  decision_rounds_ = r.u64();
  try {
    rng_->setState(r.str());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(what + ": " + e.what());
  }
  if (r.remaining() != 0) throw std::runtime_error(what + ": trailing bytes in checkpoint state");
}

void PdqnAgent::saveCheckpoint(const std::string& path) const {
  nn::FileContents c;
  c.kind = nn::FileKind::kAgentCheckpoint;
  c.layout = layoutId();
  c.layout_checksum = layoutChecksum();
  c.values = exportModel().values;
  c.extra = writeExtra();
  nn::writeModelFile(path, c);
}

void PdqnAgent::loadCheckpoint(const std::string& path,
                               const NextStateMaskRebuild& rebuild_masks) {
  nn::FileContents c = nn::readModelFile(path, nn::FileKind::kAgentCheckpoint);
  if (c.layout != layoutId())
    throw std::runtime_error(path + " holds layout '" + c.layout + "', this agent is '" +
                             layoutId() + "'");
  // Everything is read into a fresh agent; *this changes only once all of it succeeded.
  PdqnAgent loaded(config_);
  try {
    loaded.importModel(ModelBlob{c.layout, c.layout_checksum, std::move(c.values)});
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  loaded.readExtra(c.extra, path, rebuild_masks);
  *this = std::move(loaded);
}

}  // namespace palcas
