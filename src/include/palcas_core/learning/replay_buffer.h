#pragma once
// Experience replay (Mnih et al. 2015): a fixed-capacity ring of transitions
// (s, action, parameter, r, s', done) with uniform sampling.

#include <cstdint>
#include <vector>

#include "palcas_core/learning/nn/types.h"

namespace palcas {

class Rng;
namespace nn {
class ByteWriter;
class ByteReader;
}  // namespace nn

/// A batch drawn from the buffer, one column / entry per sample. Reused between draws so
/// sampling allocates only when the batch size changes.
struct ReplayBatch {
  nn::Matrix states;       ///< state_size x batch
  nn::Matrix next_states;  ///< state_size x batch
  std::vector<int> actions;
  nn::Matrix params;   ///< 1 x batch, acceleration parameter (m/s^2)
  nn::Matrix rewards;  ///< 1 x batch
  nn::Matrix dones;    ///< 1 x batch, 1 = terminal
};

/// Ring buffer of transitions. Not thread-safe.
class ReplayBuffer {
 public:
  /// Throws std::invalid_argument unless state_size >= 1 and capacity >= 1.
  ReplayBuffer(nn::Index state_size, size_t capacity);

  /// Appends a transition, overwriting the oldest when full. Throws std::invalid_argument
  /// (buffer unchanged) on a wrong state size, non-finite value, or action outside [0, 4).
  void push(const nn::Vector& state, int action, float param, float reward,
            const nn::Vector& next_state, bool done);
  /// Draws batch_size indices uniformly WITH replacement from the stored transitions.
  /// Throws std::runtime_error if the buffer is empty, std::invalid_argument if
  /// batch_size == 0.
  void sample(size_t batch_size, Rng& rng, ReplayBatch& out) const;

  size_t size() const { return size_; }
  size_t capacity() const { return capacity_; }
  nn::Index stateSize() const { return state_size_; }
  /// i-th stored transition counted from the oldest (0) - for tests and tools.
  /// Throws std::out_of_range if i >= size().
  int actionAt(size_t i) const;
  float rewardAt(size_t i) const;

  void write(nn::ByteWriter& out) const;
  /// Throws std::runtime_error (buffer unchanged) on a truncated or inconsistent record,
  /// or if its state size / capacity differ from this buffer's.
  void read(nn::ByteReader& in);

 private:
  size_t slot(size_t i) const;  // storage column of the i-th oldest transition

  nn::Index state_size_;
  size_t capacity_;
  size_t size_ = 0, next_ = 0;  // next_: column the next push writes
  nn::Matrix states_, next_states_;
  std::vector<int> actions_;
  std::vector<float> params_, rewards_, dones_;
};

}  // namespace palcas
