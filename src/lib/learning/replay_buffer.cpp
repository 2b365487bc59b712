#include "palcas_core/learning/replay_buffer.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "palcas_core/common/action.h"
#include "palcas_core/common/rng.h"
#include "palcas_core/learning/nn/serialization.h"

namespace palcas {

ReplayBuffer::ReplayBuffer(nn::Index state_size, size_t capacity)
    : state_size_(state_size), capacity_(capacity) {
  if (state_size < 1) throw std::invalid_argument("ReplayBuffer: state_size must be >= 1");
  if (capacity < 1) throw std::invalid_argument("ReplayBuffer: capacity must be >= 1");
  states_.resize(state_size, static_cast<nn::Index>(capacity));
  next_states_.resize(state_size, static_cast<nn::Index>(capacity));
  actions_.resize(capacity);
  params_.resize(capacity);
  rewards_.resize(capacity);
  dones_.resize(capacity);
}

void ReplayBuffer::push(const nn::Vector& state, int action, float param, float reward,
                        const nn::Vector& next_state, bool done) {
  if (state.size() != state_size_ || next_state.size() != state_size_)
    throw std::invalid_argument("ReplayBuffer::push: states must have " +
                                std::to_string(state_size_) + " values, got " +
                                std::to_string(state.size()) + " and " +
                                std::to_string(next_state.size()));
  if (!isValidActionCode(action))
    throw std::invalid_argument("ReplayBuffer::push: unknown action " + std::to_string(action));
  if (!state.allFinite() || !next_state.allFinite())
    throw std::invalid_argument("ReplayBuffer::push: non-finite value in a state");
  if (!std::isfinite(param) || !std::isfinite(reward))
    throw std::invalid_argument("ReplayBuffer::push: non-finite parameter or reward");
  const auto col = static_cast<nn::Index>(next_);
  states_.col(col) = state;
  next_states_.col(col) = next_state;
  actions_[next_] = action;
  params_[next_] = param;
  rewards_[next_] = reward;
  dones_[next_] = done ? 1.0f : 0.0f;
  next_ = (next_ + 1) % capacity_;  // ring: the oldest slot is overwritten when full
  if (size_ < capacity_) ++size_;
}

void ReplayBuffer::sample(size_t batch_size, Rng& rng, ReplayBatch& out) const {
  if (batch_size == 0) throw std::invalid_argument("ReplayBuffer::sample: batch_size is 0");
  if (size_ == 0) throw std::runtime_error("ReplayBuffer::sample: the buffer is empty");
  const auto n = static_cast<nn::Index>(batch_size);
  out.states.resize(state_size_, n);
  out.next_states.resize(state_size_, n);
  out.actions.resize(batch_size);
  out.params.resize(1, n);
  out.rewards.resize(1, n);
  out.dones.resize(1, n);
  for (nn::Index j = 0; j < n; ++j) {
    const size_t i = rng.uniformIndex(size_);  // storage columns [0, size_) are all valid
    const auto col = static_cast<nn::Index>(i);
    out.states.col(j) = states_.col(col);
    out.next_states.col(j) = next_states_.col(col);
    out.actions[j] = actions_[i];
    out.params(0, j) = params_[i];
    out.rewards(0, j) = rewards_[i];
    out.dones(0, j) = dones_[i];
  }
}

size_t ReplayBuffer::slot(size_t i) const {
  if (i >= size_)
    throw std::out_of_range("ReplayBuffer: index " + std::to_string(i) + " >= size " +
                            std::to_string(size_));
  return size_ < capacity_ ? i : (next_ + i) % capacity_;
}

int ReplayBuffer::actionAt(size_t i) const { return actions_[slot(i)]; }
float ReplayBuffer::rewardAt(size_t i) const { return rewards_[slot(i)]; }

void ReplayBuffer::write(nn::ByteWriter& out) const {
  out.u64(static_cast<uint64_t>(state_size_));
  out.u64(capacity_);
  out.u64(size_);
  out.u64(next_);
  // Only the filled columns [0, size_) are stored.
  const size_t values = static_cast<size_t>(state_size_) * size_;
  out.floats(states_.data(), values);
  out.floats(next_states_.data(), values);
  std::vector<float> actions(actions_.begin(), actions_.begin() + static_cast<long>(size_));
  out.floats(actions.data(), size_);
  out.floats(params_.data(), size_);
  out.floats(rewards_.data(), size_);
  out.floats(dones_.data(), size_);
}

void ReplayBuffer::read(nn::ByteReader& in) {
  const uint64_t state_size = in.u64(), capacity = in.u64(), size = in.u64(), next = in.u64();
  if (state_size != static_cast<uint64_t>(state_size_) || capacity != capacity_)
    throw std::runtime_error("ReplayBuffer::read: record has state size " +
                             std::to_string(state_size) + " and capacity " +
                             std::to_string(capacity) + ", the buffer " +
                             std::to_string(state_size_) + " and " + std::to_string(capacity_));
  if (size > capacity || next >= capacity || (size < capacity && next != size))
    throw std::runtime_error("ReplayBuffer::read: inconsistent size/position");
  const std::vector<float> s = in.floats(), s2 = in.floats(), a = in.floats(), p = in.floats(),
                           r = in.floats(), d = in.floats();
  const size_t values = static_cast<size_t>(state_size_) * size;
  if (s.size() != values || s2.size() != values || a.size() != size || p.size() != size ||
      r.size() != size || d.size() != size)
    throw std::runtime_error("ReplayBuffer::read: array sizes do not match the record size");
  for (float action : a)
    if (!isValidActionCode(static_cast<int>(action)))
      throw std::runtime_error("ReplayBuffer::read: unknown action in the record");
  // All checks passed: commit.
  size_ = size;
  next_ = next;
  std::copy(s.begin(), s.end(), states_.data());
  std::copy(s2.begin(), s2.end(), next_states_.data());
  for (size_t i = 0; i < size; ++i) actions_[i] = static_cast<int>(a[i]);
  std::copy(p.begin(), p.end(), params_.begin());
  std::copy(r.begin(), r.end(), rewards_.begin());
  std::copy(d.begin(), d.end(), dones_.begin());
}

}  // namespace palcas
