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
  next_valid_actions_.resize(capacity);
}

void ReplayBuffer::push(const nn::Vector& state, int action, float param, float reward,
                        const nn::Vector& next_state, ActionMask next_valid_actions,
                        bool done) {
  if (state.size() != state_size_ || next_state.size() != state_size_)
    throw std::invalid_argument("ReplayBuffer::push: states must have " +
                                std::to_string(state_size_) + " values, got " +
                                std::to_string(state.size()) + " and " +
                                std::to_string(next_state.size()));
  if (!isValidActionCode(action))
    throw std::invalid_argument("ReplayBuffer::push: unknown action " + std::to_string(action));
  if (!isValidActionMask(next_valid_actions))
    throw std::invalid_argument("ReplayBuffer::push: next_valid_actions " +
                                std::to_string(next_valid_actions) +
                                " is not a non-empty set of actions");
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
  next_valid_actions_[next_] = next_valid_actions;
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
  out.next_valid_actions.resize(batch_size);
  for (nn::Index j = 0; j < n; ++j) {
    const size_t i = rng.uniformIndex(size_);  // storage columns [0, size_) are all valid
    const auto col = static_cast<nn::Index>(i);
    out.states.col(j) = states_.col(col);
    out.next_states.col(j) = next_states_.col(col);
    out.actions[j] = actions_[i];
    out.params(0, j) = params_[i];
    out.rewards(0, j) = rewards_[i];
    out.dones(0, j) = dones_[i];
    out.next_valid_actions[j] = next_valid_actions_[i];
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
ActionMask ReplayBuffer::nextValidActionsAt(size_t i) const {
  return next_valid_actions_[slot(i)];
}

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
  const std::vector<float> masks(next_valid_actions_.begin(),
                                 next_valid_actions_.begin() + static_cast<long>(size_));
  out.floats(masks.data(), size_);
}

void ReplayBuffer::read(nn::ByteReader& in) { readRecord(in, nullptr); }

void ReplayBuffer::readWithoutMasks(nn::ByteReader& in, const NextStateMaskRebuild& rebuild) {
  if (!rebuild) throw std::invalid_argument("ReplayBuffer::readWithoutMasks: no mask rebuild");
  readRecord(in, &rebuild);
}

void ReplayBuffer::readRecord(nn::ByteReader& in, const NextStateMaskRebuild* rebuild) {
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
  std::vector<ActionMask> masks(size);
  if (rebuild) {
    for (size_t i = 0; i < size; ++i) {
      const int mask = (*rebuild)(Eigen::Map<const nn::Vector>(
          s2.data() + i * static_cast<size_t>(state_size_), state_size_));
      if (!isValidActionMask(mask))
        throw std::runtime_error("ReplayBuffer::read: rebuilt mask " + std::to_string(mask) +
                                 " of transition " + std::to_string(i) +
                                 " is not a non-empty set of actions");
      masks[i] = static_cast<ActionMask>(mask);
    }
  } else {
    const std::vector<float> m = in.floats();
    if (m.size() != size)
      throw std::runtime_error("ReplayBuffer::read: mask count does not match the record size");
    for (size_t i = 0; i < size; ++i) {
      if (!isValidActionMask(static_cast<int>(m[i])))
        throw std::runtime_error("ReplayBuffer::read: invalid action mask in the record");
      masks[i] = static_cast<ActionMask>(m[i]);
    }
  }
  // All checks passed: commit.
  size_ = size;
  next_ = next;
  std::copy(s.begin(), s.end(), states_.data());
  std::copy(s2.begin(), s2.end(), next_states_.data());
  for (size_t i = 0; i < size; ++i) actions_[i] = static_cast<int>(a[i]);
  std::copy(p.begin(), p.end(), params_.begin());
  std::copy(r.begin(), r.end(), rewards_.begin());
  std::copy(d.begin(), d.end(), dones_.begin());
  std::copy(masks.begin(), masks.end(), next_valid_actions_.begin());
}

}  // namespace palcas
