#include "palcas_core/learning/replay_buffer.h"

#include <gtest/gtest.h>

#include <limits>

#include "common/throws_naming.h"
#include "palcas_core/common/rng.h"
#include "palcas_core/learning/nn/serialization.h"

using namespace palcas;
using nn::Vector;

namespace {
Vector state(float value) { return Vector::Constant(2, value); }
// A different valid mask for each i (1..15), so a wrong column shows.
ActionMask maskNumber(int i) { return static_cast<ActionMask>(1 + i % ALL_ACTIONS); }
}  // namespace

TEST(ReplayBuffer, DropsOldestWhenFull) {
  ReplayBuffer buffer(2, 3);
  for (int i = 1; i <= 4; ++i)
    buffer.push(state(i), i % 4, 0.0f, float(i), state(i + 1), ALL_ACTIONS, false);
  // Capacity 3, rewards pushed 1, 2, 3, 4: the 1 is gone, oldest first = 2, 3, 4.
  EXPECT_EQ(buffer.size(), 3u);
  EXPECT_EQ(buffer.rewardAt(0), 2.0f);
  EXPECT_EQ(buffer.rewardAt(1), 3.0f);
  EXPECT_EQ(buffer.rewardAt(2), 4.0f);
  EXPECT_EQ(buffer.actionAt(2), 0);  // 4 % 4
  EXPECT_THROW(buffer.rewardAt(3), std::out_of_range);
}

TEST(ReplayBuffer, SamplesStoredTransitionsConsistently) {
  ReplayBuffer buffer(2, 10);
  for (int i = 0; i < 5; ++i)
    buffer.push(state(i), i % 4, 0.5f * i, 10.0f * i, state(i + 100), maskNumber(i), i == 4);
  Rng rng(1);
  ReplayBatch batch;
  buffer.sample(64, rng, batch);
  ASSERT_EQ(batch.states.cols(), 64);
  for (int j = 0; j < 64; ++j) {
    // Every field of a sampled column belongs to the same transition i = s(0).
    const int i = static_cast<int>(batch.states(0, j));
    EXPECT_EQ(batch.next_states(1, j), i + 100.0f);
    EXPECT_EQ(batch.actions[j], i % 4);
    EXPECT_EQ(batch.params(0, j), 0.5f * i);
    EXPECT_EQ(batch.rewards(0, j), 10.0f * i);
    EXPECT_EQ(batch.dones(0, j), i == 4 ? 1.0f : 0.0f);
    EXPECT_EQ(batch.next_valid_actions[j], maskNumber(i));
  }
}

TEST(ReplayBuffer, SamplingIsUniformAndSeeded) {
  ReplayBuffer buffer(1, 4);
  for (int i = 0; i < 4; ++i)
    buffer.push(Vector::Constant(1, i), 0, 0, 0, Vector::Zero(1), ALL_ACTIONS, false);
  Rng rng(2), same(2);
  ReplayBatch batch, again;
  buffer.sample(40000, rng, batch);
  buffer.sample(40000, same, again);
  EXPECT_EQ(batch.states, again.states);
  // 40000 draws over 4 slots: 10000 each, sigma = sqrt(40000 * 0.25 * 0.75) = 87; 5 sigma.
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR((batch.states.array() == float(i)).count(), 10000, 435) << "slot " << i;
}

TEST(ReplayBuffer, RejectsBadTransitionsUnchanged) {
  ReplayBuffer buffer(2, 3);
  buffer.push(state(1), 0, 0, 1, state(2), ALL_ACTIONS, false);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const ActionMask all = ALL_ACTIONS;
  EXPECT_THROW(buffer.push(Vector::Zero(3), 0, 0, 0, state(0), all, false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(0), 4, 0, 0, state(0), all, false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(0), -1, 0, 0, state(0), all, false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(nan), 0, 0, 0, state(0), all, false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(0), 0, nan, 0, state(0), all, false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(0), 0, 0, nan, state(0), all, false), std::invalid_argument);
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [&] { buffer.push(state(0), 0, 0, 0, state(0), 0, false); }, "next_valid_actions 0");
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [&] { buffer.push(state(0), 0, 0, 0, state(0), 16, false); }, "next_valid_actions 16");
  EXPECT_EQ(buffer.size(), 1u);
  EXPECT_EQ(buffer.rewardAt(0), 1.0f);
  EXPECT_THROW(ReplayBuffer(0, 3), std::invalid_argument);
  EXPECT_THROW(ReplayBuffer(2, 0), std::invalid_argument);
  ReplayBuffer empty(2, 3);
  Rng rng(3);
  ReplayBatch batch;
  EXPECT_THROW(empty.sample(4, rng, batch), std::runtime_error);
  EXPECT_THROW(buffer.sample(0, rng, batch), std::invalid_argument);
}

TEST(ReplayBuffer, SaveLoadRoundTrip) {
  ReplayBuffer a(2, 3);
  for (int i = 1; i <= 5; ++i)
    a.push(state(i), i % 4, 0.1f * i, float(i), state(-i), maskNumber(i), i % 2 == 0);
  nn::ByteWriter w;
  a.write(w);
  ReplayBuffer b(2, 3);
  nn::ByteReader r(w.bytes(), "test");
  b.read(r);
  ASSERT_EQ(b.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(b.rewardAt(i), a.rewardAt(i));
    EXPECT_EQ(b.actionAt(i), a.actionAt(i));
    EXPECT_EQ(b.nextValidActionsAt(i), maskNumber(static_cast<int>(i) + 3));  // 3, 4, 5 kept
  }
  Rng ra(4), rb(4);
  ReplayBatch ba, bb;
  a.sample(16, ra, ba);
  b.sample(16, rb, bb);
  EXPECT_EQ(ba.states, bb.states);
  EXPECT_EQ(ba.next_states, bb.next_states);
  EXPECT_EQ(ba.dones, bb.dones);
  EXPECT_EQ(ba.next_valid_actions, bb.next_valid_actions);
  // Pushing continues at the same ring position: the next push drops reward 3.
  a.push(state(6), 0, 0, 6, state(6), ALL_ACTIONS, false);
  b.push(state(6), 0, 0, 6, state(6), ALL_ACTIONS, false);
  EXPECT_EQ(b.rewardAt(0), 4.0f);
  EXPECT_EQ(a.rewardAt(0), b.rewardAt(0));
}

TEST(ReplayBuffer, ReadRefusesAnotherCapacityOrTruncatedRecord) {
  ReplayBuffer a(2, 3);
  a.push(state(1), 0, 0, 1, state(2), ALL_ACTIONS, false);
  nn::ByteWriter w;
  a.write(w);
  ReplayBuffer other(2, 4);
  nn::ByteReader r(w.bytes(), "test");
  EXPECT_THROW(other.read(r), std::runtime_error);
  EXPECT_EQ(other.size(), 0u);
  const std::string cut = w.bytes().substr(0, w.bytes().size() - 3);
  ReplayBuffer same(2, 3);
  nn::ByteReader rc(cut, "test");
  EXPECT_THROW(same.read(rc), std::runtime_error);
  EXPECT_EQ(same.size(), 0u);
}

TEST(ReplayBuffer, RecordWithoutMasksGetsThemFromItsNextStates) {
  // A record as the buffer wrote it before the masks: write() minus the trailing masks.
  ReplayBuffer a(2, 3);
  for (int i = 1; i <= 4; ++i)
    a.push(state(i), 0, 0, float(i), state(i + 10), maskNumber(i), false);
  nn::ByteWriter w;
  a.write(w);
  const size_t masks_bytes = 8 + 3 * 4;  // the last array: u64 count, 3 floats
  const std::string old_record = w.bytes().substr(0, w.bytes().size() - masks_bytes);

  // The rebuild sees each transition's own next state: mask = its first value - 10.
  auto rebuild = [](const Vector& next_state) {
    return static_cast<ActionMask>(next_state(0) - 10.0f);
  };
  ReplayBuffer b(2, 3);
  nn::ByteReader old(old_record, "test");
  b.readWithoutMasks(old, rebuild);
  EXPECT_EQ(old.remaining(), 0u);
  ASSERT_EQ(b.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(b.rewardAt(i), a.rewardAt(i));
    EXPECT_EQ(b.nextValidActionsAt(i), static_cast<ActionMask>(i + 2));  // next states 12..14
  }
  // A rebuild that leaves no action is refused, the buffer unchanged.
  ReplayBuffer c(2, 3);
  nn::ByteReader again(old_record, "test");
  palcas_test::expectThrowNaming<std::runtime_error>(
      [&] { c.readWithoutMasks(again, [](const Vector&) { return ActionMask{0}; }); },
      "rebuilt mask 0 of transition 0");
  EXPECT_EQ(c.size(), 0u);
}
