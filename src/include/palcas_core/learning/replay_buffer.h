#pragma once
// Experience replay (Mnih et al. 2015): a fixed-capacity ring of transitions
// (s, action, parameter, r, s', valid actions in s', done) with uniform sampling.

#include <cstdint>
#include <functional>
#include <vector>

#include "palcas_core/common/action.h"
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
  /// The actions that may be taken in each next state (the TD target's max runs over them
  /// with td_target_valid_actions).
  std::vector<ActionMask> next_valid_actions;
};

/// The valid-action mask of a next state, for records written before the masks were
/// stored with the transitions: only the caller knows what a state encodes.
using NextStateMaskRebuild = std::function<ActionMask(const nn::Vector& next_state)>;

/// Ring buffer of transitions. Not thread-safe.
class ReplayBuffer {
 public:
  /// Throws std::invalid_argument unless state_size >= 1 and capacity >= 1.
  ReplayBuffer(nn::Index state_size, size_t capacity);

  /// Appends a transition, overwriting the oldest when full. Throws std::invalid_argument
  /// (buffer unchanged) on a wrong state size, non-finite value, action outside [0, 4), or
  /// a mask that is not isValidActionMask.
  void push(const nn::Vector& state, int action, float param, float reward,
            const nn::Vector& next_state, ActionMask next_valid_actions, bool done);
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
  ActionMask nextValidActionsAt(size_t i) const;

  void write(nn::ByteWriter& out) const;
  /// Throws std::runtime_error (buffer unchanged) on a truncated or inconsistent record,
  /// or if its state size / capacity differ from this buffer's.
  void read(nn::ByteReader& in);
  /// read() of a record written before the masks were stored (agent checkpoint state
  /// version 1): each transition's mask is rebuild(its next state). Throws like read(),
  /// and std::runtime_error on a mask that is not isValidActionMask.
  void readWithoutMasks(nn::ByteReader& in, const NextStateMaskRebuild& rebuild);

 private:
  size_t slot(size_t i) const;  // storage column of the i-th oldest transition
  void readRecord(nn::ByteReader& in, const NextStateMaskRebuild* rebuild);

  nn::Index state_size_;
  size_t capacity_;
  size_t size_ = 0, next_ = 0;  // next_: column the next push writes
  nn::Matrix states_, next_states_;
  std::vector<int> actions_;
  std::vector<float> params_, rewards_, dones_;
  std::vector<ActionMask> next_valid_actions_;
};

}  // namespace palcas
