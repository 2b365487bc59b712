#include "palcas_core/learning/replay_buffer.h"

#include <gtest/gtest.h>

#include <limits>

#include "palcas_core/common/rng.h"
#include "palcas_core/learning/nn/serialization.h"

using namespace palcas;
using nn::Vector;

namespace {
Vector state(float value) { return Vector::Constant(2, value); }
}  // namespace

TEST(ReplayBuffer, DropsOldestWhenFull) {
  ReplayBuffer buffer(2, 3);
  for (int i = 1; i <= 4; ++i) buffer.push(state(i), i % 4, 0.0f, float(i), state(i + 1), false);
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
  for (int i = 0; i < 5; ++i) buffer.push(state(i), i % 4, 0.5f * i, 10.0f * i, state(i + 100), i == 4);
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
  }
}

TEST(ReplayBuffer, SamplingIsUniformAndSeeded) {
  ReplayBuffer buffer(1, 4);
  for (int i = 0; i < 4; ++i) buffer.push(Vector::Constant(1, i), 0, 0, 0, Vector::Zero(1), false);
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
  buffer.push(state(1), 0, 0, 1, state(2), false);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(buffer.push(Vector::Zero(3), 0, 0, 0, state(0), false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(0), 4, 0, 0, state(0), false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(0), -1, 0, 0, state(0), false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(nan), 0, 0, 0, state(0), false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(0), 0, nan, 0, state(0), false), std::invalid_argument);
  EXPECT_THROW(buffer.push(state(0), 0, 0, nan, state(0), false), std::invalid_argument);
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
  for (int i = 1; i <= 5; ++i) a.push(state(i), i % 4, 0.1f * i, float(i), state(-i), i % 2 == 0);
  nn::ByteWriter w;
  a.write(w);
  ReplayBuffer b(2, 3);
  nn::ByteReader r(w.bytes(), "test");
  b.read(r);
  ASSERT_EQ(b.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(b.rewardAt(i), a.rewardAt(i));
    EXPECT_EQ(b.actionAt(i), a.actionAt(i));
  }
  Rng ra(4), rb(4);
  ReplayBatch ba, bb;
  a.sample(16, ra, ba);
  b.sample(16, rb, bb);
  EXPECT_EQ(ba.states, bb.states);
  EXPECT_EQ(ba.next_states, bb.next_states);
  EXPECT_EQ(ba.dones, bb.dones);
  // Pushing continues at the same ring position: the next push drops reward 3.
  a.push(state(6), 0, 0, 6, state(6), false);
  b.push(state(6), 0, 0, 6, state(6), false);
  EXPECT_EQ(b.rewardAt(0), 4.0f);
  EXPECT_EQ(a.rewardAt(0), b.rewardAt(0));
}

TEST(ReplayBuffer, ReadRefusesAnotherCapacityOrTruncatedRecord) {
  ReplayBuffer a(2, 3);
  a.push(state(1), 0, 0, 1, state(2), false);
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
