#include "palcas_core/learning/pdqn_agent.h"

#include <Eigen/Core>
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <limits>

#include "common/throws_naming.h"
#include "learning/checkpoint_without_masks.h"
#include "palcas_core/learning/nn/bf16_gemm.h"
#include "palcas_core/learning/nn/serialization.h"

using namespace palcas;
using nn::Index;
using nn::Matrix;
using nn::Vector;

namespace {

PdqnConfig smallConfig(uint64_t seed = 7) {
  PdqnConfig c;
  c.state_size = 5;
  c.hidden_sizes = {8, 8};
  c.batch_size = 16;
  c.replay_capacity = 200;
  c.target_update_steps = 3;
  c.seed = seed;
  return c;
}

Matrix randomStates(Index rows, Index cols, Rng& rng) {
  Matrix m(rows, cols);
  for (Index i = 0; i < m.size(); ++i) m.data()[i] = rng.uniform(-1, 1);
  return m;
}

// Fills the replay with `count` exploring decisions on random states.
void fillReplay(PdqnAgent& agent, int count, uint64_t seed) {
  Rng data(seed);
  const Index s = agent.config().state_size;
  for (int i = 0; i < count; ++i) {
    const Matrix states = randomStates(s, 1, data);
    const Decision d = agent.act(states, true)[0];
    const float reward = d.action == Action::kAccelerate ? 1.0f - std::abs(d.accel_mps2) : 0.0f;
    agent.remember(states.col(0), d, reward, randomStates(s, 1, data).col(0), ALL_ACTIONS,
                   i % 10 == 9);
  }
}

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "palcas_agent_" + name; }

}  // namespace

TEST(PdqnAgent, DefaultConfigIsThePapersTable) {
  const PdqnConfig c;
  EXPECT_EQ(c.state_size, 45);
  EXPECT_EQ(c.hidden_sizes, (std::vector<int>{256, 512, 256}));
  EXPECT_TRUE(c.batch_norm);
  EXPECT_FLOAT_EQ(c.dropout, 0.1f);
  EXPECT_FLOAT_EQ(c.learning_rate, 1e-3f);
  EXPECT_FLOAT_EQ(c.weight_decay, 1e-2f);
  EXPECT_EQ(c.batch_size, 256);
  EXPECT_FLOAT_EQ(c.gamma, 0.995f);
  EXPECT_EQ(c.replay_capacity, 100000);
  EXPECT_EQ(c.target_update_steps, 15000);
  EXPECT_DOUBLE_EQ(c.epsilon_start, 1.0);
  EXPECT_DOUBLE_EQ(c.epsilon_final, 0.02);
  EXPECT_DOUBLE_EQ(c.epsilon_decay, 0.999985);
  EXPECT_FLOAT_EQ(c.accel_min_mps2, -4.5f);
  EXPECT_FLOAT_EQ(c.accel_max_mps2, 2.6f);
  EXPECT_NO_THROW(c.validate());
}

TEST(PdqnAgent, PaperModelSize) {
  PdqnConfig c;
  c.replay_capacity = 10;  // keep the test light; the networks are the paper's
  const PdqnAgent agent(c);
  // mu: 276993 params + 2048 BN stats; Q (input 46, output 4): Linear(46,256) 12032 +
  // 512 + 131584 + 1024 + 131328 + 512 + Linear(256,4) 1028 = 278020 params + 2048 stats.
  EXPECT_EQ(agent.exportModel().values.size(), 276993u + 2048u + 278020u + 2048u);
  EXPECT_NE(agent.layoutId().find("p-dqn mu[Linear(45,256);BatchNorm1d(256);ReLU(256);"
                                  "Dropout(256,0.1);Linear(256,512)"),
            std::string::npos);
}

TEST(PdqnAgent, RejectsInvalidConfigNamingTheField) {
  PdqnConfig c = smallConfig();
  c.gamma = 1.5f;
  try {
    PdqnAgent agent(c);
    ADD_FAILURE() << "accepted gamma 1.5";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gamma"), std::string::npos) << e.what();
  }
  c = smallConfig();
  c.accel_min_mps2 = 3.0f;
  EXPECT_THROW(PdqnAgent{c}, std::invalid_argument);
  c = smallConfig();
  c.batch_size = 1;  // batch norm cannot train on one sample
  EXPECT_THROW(PdqnAgent{c}, std::invalid_argument);
}

TEST(PdqnAgent, ActDecidesEveryColumnWithinBounds) {
  PdqnAgent agent(smallConfig());
  Rng data(1);
  const Matrix states = randomStates(5, 50, data);
  const std::vector<Decision> decisions = agent.act(states, true);
  ASSERT_EQ(decisions.size(), 50u);
  for (const Decision& d : decisions) {
    EXPECT_TRUE(isValidActionCode(static_cast<int>(d.action)));
    EXPECT_GE(d.accel_mps2, -4.5f);
    EXPECT_LE(d.accel_mps2, 2.6f);
  }
}

TEST(PdqnAgent, GreedyActionIsTheArgmaxOfQ) {
  PdqnAgent agent(smallConfig());
  Rng data(2);
  const Matrix states = randomStates(5, 20, data);
  Matrix q, accel;
  agent.evaluate(states, q, accel);
  const std::vector<Decision> decisions = agent.act(states, false);
  for (Index j = 0; j < 20; ++j) {
    Index best;
    q.col(j).maxCoeff(&best);
    EXPECT_EQ(static_cast<Index>(decisions[j].action), best);
    EXPECT_FLOAT_EQ(decisions[j].accel_mps2, accel(0, j));
  }
}

TEST(PdqnAgent, OverDefaultsTheGreedyActionDepartsOnlyByMoreThanTheMargin) {
  PdqnAgent agent(smallConfig());
  Rng data(3);
  const Matrix states = randomStates(5, 40, data);
  Matrix q, accel;
  agent.evaluate(states, q, accel);
  std::vector<Decision> defaults;
  for (Index j = 0; j < 40; ++j) defaults.push_back(Decision{static_cast<Action>(j % ACTION_COUNT), 1.25f});
  // A margin between the smallest and the largest gap, so both outcomes occur.
  std::vector<float> gaps;
  for (Index j = 0; j < 40; ++j) gaps.push_back(q.col(j).maxCoeff() - q(static_cast<Index>(defaults[j].action), j));
  std::vector<float> sorted = gaps;
  std::sort(sorted.begin(), sorted.end());
  const float margin = 0.5f * (sorted[20] + sorted[21]);
  ASSERT_LT(sorted[0], margin);
  ASSERT_GT(sorted[39], margin);
  std::vector<Decision> out;
  agent.actOverDefaults(states, false, defaults, margin, out);
  const std::vector<Decision> greedy = agent.act(states, false);
  int departed = 0;
  for (size_t j = 0; j < 40; ++j) {
    const bool depart = gaps[j] > margin;
    departed += depart;
    const Decision& want = depart ? greedy[j] : defaults[j];
    EXPECT_EQ(out[j].action, want.action) << "column " << j;
    const float want_accel = (!depart && want.action == Action::kAccelerate) ? 1.25f : accel(0, static_cast<Index>(j));
    EXPECT_FLOAT_EQ(out[j].accel_mps2, want_accel) << "column " << j;
  }
  EXPECT_GT(departed, 0);  // both outcomes seen
  EXPECT_LT(departed, 40);
  // Margin 0: the greedy action wherever it is strictly better; a huge one: the defaults.
  agent.actOverDefaults(states, false, defaults, 1e9f, out);
  for (size_t j = 0; j < 40; ++j) EXPECT_EQ(out[j].action, defaults[j].action);
  agent.actOverDefaults(states, false, defaults, 0.0f, out);
  for (size_t j = 0; j < 40; ++j) EXPECT_EQ(out[j].action, gaps[j] > 0 ? greedy[j].action : defaults[j].action);
  EXPECT_THROW(agent.actOverDefaults(states, false, defaults, -1.0f, out), std::invalid_argument);
  EXPECT_THROW(agent.actOverDefaults(states, false, defaults, std::nanf(""), out), std::invalid_argument);
  defaults.pop_back();
  EXPECT_THROW(agent.actOverDefaults(states, false, defaults, 0.0f, out), std::invalid_argument);
}

TEST(PdqnAgent, QIsTheQNetworkOnStateAndNormalisedParameter) {
  for (bool multi_pass : {false, true}) {
    PdqnConfig c = smallConfig();
    c.multi_pass = multi_pass;
    PdqnAgent agent(c);
    Rng data(3);
    const Matrix states = randomStates(5, 4, data);
    Matrix q, accel;
    agent.evaluate(states, q, accel);
    nn::Network mu = agent.paramNetwork(), qnet = agent.qNetwork();
    mu.eval();
    qnet.eval();
    // c_norm = (a - mid)/half with mid = (2.6 - 4.5)/2 = -0.95, half = (2.6 + 4.5)/2 = 3.55.
    const Matrix c_norm = mu.forward(states);
    EXPECT_NEAR(accel(0, 0), -0.95f + 3.55f * c_norm(0, 0), 1e-5f);
    Matrix with_c(6, 4), without_c(6, 4);
    with_c << states, c_norm;
    without_c << states, Matrix::Zero(1, 4);
    const Matrix q_with = qnet.forward(with_c);
    const Matrix q_without = qnet.forward(without_c);
    for (Index a = 0; a < 4; ++a) {
      // P-DQN: every Q_a sees c. MP-DQN: only a2's pass carries c, the others see 0.
      const Matrix& expected = (!multi_pass || a == 2) ? q_with : q_without;
      for (Index j = 0; j < 4; ++j) EXPECT_NEAR(q(a, j), expected(a, j), 1e-5f) << multi_pass;
    }
  }
}

TEST(PdqnAgent, EpsilonDecaysOncePerExploringRound) {
  PdqnConfig c = smallConfig();
  c.epsilon_decay = 0.5;
  c.epsilon_final = 0.2;
  PdqnAgent agent(c);
  Rng data(4);
  const Matrix states = randomStates(5, 10, data);  // 10 CAVs, still one decay per call
  agent.act(states, true);
  EXPECT_DOUBLE_EQ(agent.epsilon(), 0.5);  // 1.0 * 0.5
  agent.act(states, false);
  EXPECT_DOUBLE_EQ(agent.epsilon(), 0.5);  // greedy rounds do not decay
  agent.act(states, true);
  EXPECT_DOUBLE_EQ(agent.epsilon(), 0.25);  // 0.5 * 0.5
  agent.act(states, true);
  EXPECT_DOUBLE_EQ(agent.epsilon(), 0.2);  // max(0.2, 0.125)
  EXPECT_EQ(agent.decisionRounds(), 4u);
}

TEST(PdqnAgent, ActRejectsBadStatesUnchanged) {
  PdqnAgent agent(smallConfig());
  Matrix states = Matrix::Zero(5, 3);
  states(2, 1) = std::numeric_limits<float>::quiet_NaN();
  try {
    agent.act(states, true);
    ADD_FAILURE() << "accepted NaN";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("feature 2 of column 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(agent.act(Matrix::Zero(4, 3), true), std::invalid_argument);
  EXPECT_THROW(agent.act(Matrix::Zero(5, 0), true), std::invalid_argument);
  EXPECT_DOUBLE_EQ(agent.epsilon(), 1.0);
  EXPECT_EQ(agent.decisionRounds(), 0u);
}

TEST(PdqnAgent, UpdateNeedsAFullBatch) {
  PdqnAgent agent(smallConfig());
  fillReplay(agent, 15, 5);  // batch is 16
  EXPECT_FALSE(agent.canUpdate());
  EXPECT_THROW(agent.update(), std::runtime_error);
  fillReplay(agent, 1, 6);
  EXPECT_TRUE(agent.canUpdate());
  const UpdateStats stats = agent.update();
  EXPECT_EQ(stats.gradient_steps, 1u);
  EXPECT_TRUE(std::isfinite(stats.q_loss));
  EXPECT_TRUE(std::isfinite(stats.param_loss));
}

TEST(PdqnAgent, UpdateTrainsBothNetworksAndCopiesTargetsEveryCSteps) {
  PdqnAgent agent(smallConfig());  // C = 3
  fillReplay(agent, 64, 7);
  const Vector mu0 = agent.paramNetwork().getState(), q0 = agent.qNetwork().getState();
  agent.update();
  EXPECT_NE(agent.paramNetwork().getState(), mu0);
  EXPECT_NE(agent.qNetwork().getState(), q0);
  agent.update();
  EXPECT_EQ(agent.qTargetNetwork().getState(), q0);  // still the initial copy
  EXPECT_EQ(agent.paramTargetNetwork().getState(), mu0);
  agent.update();  // step 3 = C: hard copy
  EXPECT_EQ(agent.qTargetNetwork().getState(), agent.qNetwork().getState());
  EXPECT_EQ(agent.paramTargetNetwork().getState(), agent.paramNetwork().getState());
}

TEST(PdqnAgent, SameSeedGivesBitIdenticalWeights) {
  Eigen::setNbThreads(1);
  for (bool multi_pass : {false, true}) {
    PdqnConfig c = smallConfig(11);
    c.multi_pass = multi_pass;
    PdqnAgent a(c), b(c);
    for (PdqnAgent* agent : {&a, &b}) {
      fillReplay(*agent, 64, 8);
      for (int i = 0; i < 20; ++i) agent->update();
    }
    EXPECT_EQ(a.exportModel().values, b.exportModel().values);
    PdqnAgent other(smallConfig(12));
    EXPECT_NE(a.exportModel().values, other.exportModel().values);
  }
}

TEST(PdqnAgent, ExportImportRoundTripAndRefusals) {
  PdqnAgent a(smallConfig(1)), b(smallConfig(2));
  const ModelBlob blob = a.exportModel();
  EXPECT_EQ(blob.layout_checksum, nn::fnv1a64(blob.layout_id));
  b.importModel(blob);
  EXPECT_EQ(b.exportModel().values, blob.values);

  PdqnAgent c(smallConfig(3));
  const std::vector<float> before = c.exportModel().values;
  ModelBlob nan_blob = blob;
  nan_blob.values[17] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(c.importModel(nan_blob), std::invalid_argument);
  ModelBlob short_blob = blob;
  short_blob.values.pop_back();
  EXPECT_THROW(c.importModel(short_blob), std::invalid_argument);
  PdqnConfig wide = smallConfig();
  wide.hidden_sizes = {8, 9};
  try {
    c.importModel(PdqnAgent(wide).exportModel());
    ADD_FAILURE() << "accepted another layout";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("Linear(8,9)"), std::string::npos) << e.what();
  }
  ModelBlob bad_checksum = blob;
  bad_checksum.layout_checksum ^= 1;
  EXPECT_THROW(c.importModel(bad_checksum), std::invalid_argument);
  EXPECT_EQ(c.exportModel().values, before);
}

TEST(PdqnAgent, ModelFileRoundTrip) {
  const std::string path = tempPath("model.palcas");
  PdqnAgent a(smallConfig(1)), b(smallConfig(2));
  a.saveModel(path);
  b.loadModel(path);
  EXPECT_EQ(a.exportModel().values, b.exportModel().values);
  PdqnConfig wide = smallConfig();
  wide.hidden_sizes = {8, 9};
  PdqnAgent other(wide);
  const std::vector<float> before = other.exportModel().values;
  EXPECT_THROW(other.loadModel(path), std::runtime_error);
  EXPECT_EQ(other.exportModel().values, before);
  std::remove(path.c_str());
}

TEST(PdqnAgent, CheckpointResumesBitIdentically) {
  Eigen::setNbThreads(1);
  const std::string path = tempPath("checkpoint.palcas");
  PdqnAgent a(smallConfig(21));
  fillReplay(a, 64, 9);
  for (int i = 0; i < 4; ++i) a.update();
  a.saveCheckpoint(path);
  PdqnAgent b(smallConfig(22));
  b.loadCheckpoint(path);
  EXPECT_EQ(b.epsilon(), a.epsilon());
  EXPECT_EQ(b.gradientSteps(), 4u);
  EXPECT_EQ(b.replay().size(), a.replay().size());
  // Same future: exploration draws, replay samples, dropout masks, Adam moments, targets.
  for (PdqnAgent* agent : {&a, &b}) {
    fillReplay(*agent, 10, 10);
    for (int i = 0; i < 5; ++i) agent->update();
  }
  EXPECT_EQ(a.exportModel().values, b.exportModel().values);
  EXPECT_EQ(a.qTargetNetwork().getState(), b.qTargetNetwork().getState());
  std::remove(path.c_str());
}

TEST(PdqnAgent, CheckpointKeepsTheMasksOfTheTransitions) {
  const std::string path = tempPath("checkpoint_masks.palcas");
  PdqnAgent a(smallConfig(23));
  Rng data(14);
  for (int i = 0; i < 20; ++i)
    a.remember(randomStates(5, 1, data).col(0), Decision{}, 0.0f, randomStates(5, 1, data).col(0),
               static_cast<ActionMask>(1 + i % ALL_ACTIONS), false);
  a.saveCheckpoint(path);
  PdqnAgent b(smallConfig(23));
  b.loadCheckpoint(path);
  ASSERT_EQ(b.replay().size(), 20u);
  for (size_t i = 0; i < 20; ++i)
    EXPECT_EQ(b.replay().nextValidActionsAt(i), a.replay().nextValidActionsAt(i)) << i;
  std::remove(path.c_str());
}

TEST(PdqnAgent, CheckpointWithoutMasksIsReadOnlyWithAWayToRebuildThem) {
  // Checkpoints written before the masks travelled with the transitions: the agent cannot
  // read a mask out of a state, so the caller that knows the state layout rebuilds them.
  const std::string path = tempPath("checkpoint_v1.palcas");
  PdqnAgent a(smallConfig(24));
  fillReplay(a, 40, 15);
  for (int i = 0; i < 2; ++i) a.update();
  a.saveCheckpoint(path);
  palcas_test::dropMasksFromCheckpoint(path);

  PdqnAgent refused(smallConfig(25));
  const std::vector<float> before = refused.exportModel().values;
  palcas_test::expectThrowNaming<std::runtime_error>([&] { refused.loadCheckpoint(path); },
                                                     path + ": checkpoint state version 1");
  EXPECT_EQ(refused.exportModel().values, before);
  EXPECT_EQ(refused.replay().size(), 0u);

  // Rebuilt from each transition's own next state (here: its first feature's sign).
  auto rebuild = [](const Vector& next_state) {
    return next_state(0) > 0 ? ALL_ACTIONS : actionBit(Action::kKeep);
  };
  PdqnAgent b(smallConfig(25));
  b.loadCheckpoint(path, rebuild);
  EXPECT_EQ(b.exportModel().values, a.exportModel().values);
  EXPECT_EQ(b.gradientSteps(), 2u);
  ASSERT_EQ(b.replay().size(), 40u);
  Rng ra(16), rb(16);
  ReplayBatch batch_a, batch_b;
  a.replay().sample(64, ra, batch_a);
  b.replay().sample(64, rb, batch_b);
  EXPECT_EQ(batch_b.next_states, batch_a.next_states);
  EXPECT_EQ(batch_b.rewards, batch_a.rewards);
  for (Index j = 0; j < 64; ++j)
    EXPECT_EQ(batch_b.next_valid_actions[j], rebuild(batch_b.next_states.col(j))) << j;
  std::remove(path.c_str());
}

TEST(PdqnAgent, LoadCheckpointRefusesOtherFilesUnchanged) {
  const std::string path = tempPath("checkpoint_other.palcas");
  PdqnConfig wide = smallConfig();
  wide.hidden_sizes = {8, 9};
  PdqnAgent(wide).saveCheckpoint(path);
  PdqnAgent agent(smallConfig());
  const std::vector<float> before = agent.exportModel().values;
  EXPECT_THROW(agent.loadCheckpoint(path), std::runtime_error);
  agent.saveModel(path);  // a model file is not a checkpoint
  EXPECT_THROW(agent.loadCheckpoint(path), std::runtime_error);
  PdqnConfig other_capacity = smallConfig();
  other_capacity.replay_capacity = 300;
  PdqnAgent(other_capacity).saveCheckpoint(path);
  EXPECT_THROW(agent.loadCheckpoint(path), std::runtime_error);
  EXPECT_EQ(agent.exportModel().values, before);
  std::remove(path.c_str());
}

// act()/evaluate() run on folded copies of the networks (batch norm folded into the
// Linears); they must follow every change of the online networks.
TEST(PdqnAgent, DecisionsFollowUpdatesImportsAndCheckpoints) {
  const std::string path = tempPath("fold_checkpoint.palcas");
  PdqnAgent agent(smallConfig(31));
  Rng data(12);
  const Matrix states = randomStates(5, 6, data);
  auto expectLayered = [&](PdqnAgent& a) {
    Matrix q, accel;
    a.evaluate(states, q, accel);
    nn::Network mu = a.paramNetwork(), qnet = a.qNetwork();
    mu.eval();
    qnet.eval();
    const Matrix c_norm = mu.forward(states);
    Matrix q_in(6, 6);
    q_in << states, c_norm;
    const Matrix q_layered = qnet.forward(q_in);
    for (Index j = 0; j < 6; ++j) {
      // a = -0.95 + 3.55 c_n (see QIsTheQNetworkOnStateAndNormalisedParameter)
      EXPECT_NEAR(accel(0, j), -0.95f + 3.55f * c_norm(0, j), 1e-5f);
      for (Index i = 0; i < 4; ++i) EXPECT_NEAR(q(i, j), q_layered(i, j), 1e-5f);
    }
  };
  expectLayered(agent);
  fillReplay(agent, 64, 13);
  for (int i = 0; i < 4; ++i) agent.update();  // C = 3: targets copied too
  expectLayered(agent);
  agent.saveCheckpoint(path);
  PdqnAgent other(smallConfig(32));
  Matrix q_before, accel_before;
  other.evaluate(states, q_before, accel_before);  // folds its own initial networks first
  other.importModel(agent.exportModel());
  expectLayered(other);
  PdqnAgent resumed(smallConfig(33));
  resumed.act(states, false);  // folds its own initial networks first
  resumed.loadCheckpoint(path);
  expectLayered(resumed);
  std::remove(path.c_str());
}

// ---- Departures from the printed paper (config/departures.yaml); defaults = the paper ----

TEST(PdqnDepartures, DefaultsAreThePapersBehaviour) {
  const PdqnConfig c;
  EXPECT_FALSE(c.td_target_valid_actions);
  EXPECT_EQ(c.target_soft_tau, 0.0f);
  EXPECT_FALSE(c.param_loss_accelerate_only);
  EXPECT_EQ(c.epsilon_linear_rounds, 0.0);
}

TEST(PdqnDepartures, TdTargetMaxSkipsActionsImpossibleInTheNextState) {
  // The masks a 3-lane road's RSU stores with s': no RIGHT in lane 1, no LEFT in lane 3.
  PdqnConfig c = smallConfig();
  Rng data(5);
  const Matrix next = randomStates(5, 60, data);
  std::vector<ActionMask> masks(60);
  for (Index j = 0; j < 60; ++j) {
    const int lane = static_cast<int>(j % 3 + 1);
    masks[j] = lane == 1   ? ALL_ACTIONS & ~actionBit(Action::kLaneRight)
               : lane == 3 ? ALL_ACTIONS & ~actionBit(Action::kLaneLeft)
                           : ALL_ACTIONS;
  }
  // Teach both agents that LEFT pays (+1, terminal), so LEFT has the largest Q almost
  // everywhere; 51 steps = 17 hard copies (C = 3): the targets then equal the online nets.
  auto trained = [&](bool valid_only) {
    PdqnConfig cc = c;
    cc.td_target_valid_actions = valid_only;
    PdqnAgent agent(cc);
    Rng fill(6);
    for (int i = 0; i < 64; ++i) {
      const Matrix st = randomStates(5, 1, fill);
      agent.remember(st.col(0), Decision{Action::kLaneLeft, 0.0f}, 1.0f, st.col(0), ALL_ACTIONS,
                     true);
    }
    for (int i = 0; i < 51; ++i) agent.update();
    return agent;
  };
  PdqnAgent paper = trained(false);
  PdqnAgent ours = trained(true);
  Matrix q, accel, v_paper, v_ours;
  ours.evaluate(next, q, accel);
  paper.nextStateValues(next, masks, v_paper);  // td_target_valid_actions off: masks unused
  ours.nextStateValues(next, masks, v_ours);
  int differ = 0;
  for (Index j = 0; j < 60; ++j) {
    const int lane = static_cast<int>(j % 3 + 1);
    float best = -1e30f;
    for (Index a = 0; a < 4; ++a) {
      if (a == 0 && lane == 3) continue;  // no LEFT from the leftmost lane
      if (a == 1 && lane == 1) continue;  // no RIGHT from lane 1
      best = std::max(best, q(a, j));
    }
    EXPECT_NEAR(v_ours(0, j), best, 1e-5f) << j;
    Matrix q_paper;
    paper.evaluate(next.col(j), q_paper, accel);
    EXPECT_NEAR(v_paper(0, j), q_paper.col(0).maxCoeff(), 1e-5f) << j;
    differ += std::abs(v_ours(0, j) - v_paper(0, j)) > 1e-6f;
  }
  EXPECT_GT(differ, 0) << "no column where an impossible action had the largest Q: test is vacuous";
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [&] { ours.nextStateValues(next, std::vector<ActionMask>(59, ALL_ACTIONS), v_ours); },
      "59 masks for 60 next states");
}

TEST(PdqnDepartures, SoftTargetUpdateMovesTargetsByTau) {
  PdqnConfig c = smallConfig();
  c.target_soft_tau = 0.25f;
  PdqnAgent agent(c);
  fillReplay(agent, 64, 7);
  const Vector q_target0 = agent.qTargetNetwork().getState();
  const Vector mu_target0 = agent.paramTargetNetwork().getState();
  agent.update();
  const Vector q_expected = q_target0 + 0.25f * (agent.qNetwork().getState() - q_target0);
  const Vector mu_expected = mu_target0 + 0.25f * (agent.paramNetwork().getState() - mu_target0);
  EXPECT_TRUE(agent.qTargetNetwork().getState().isApprox(q_expected, 1e-6f));
  EXPECT_TRUE(agent.paramTargetNetwork().getState().isApprox(mu_expected, 1e-6f));
  EXPECT_NE(agent.qTargetNetwork().getState(), agent.qNetwork().getState());  // no hard copy
}

TEST(PdqnDepartures, ParamLossCanUseTheAccelerateHeadOnly) {
  // One state repeated: every batch is that state whatever the sampling. Without batch norm
  // and dropout mu(s) is the same in train and eval mode, so the loss is computable here.
  for (bool accel_only : {false, true}) {
    PdqnConfig c = smallConfig();
    c.batch_norm = false;
    c.dropout = 0.0f;
    c.param_loss_accelerate_only = accel_only;
    PdqnAgent agent(c);
    Rng data(11);
    const Matrix s = randomStates(5, 1, data);
    for (int i = 0; i < 32; ++i)
      agent.remember(s.col(0), Decision{Action::kKeep, 0.0f}, 0.0f, s.col(0), ALL_ACTIONS, false);
    Matrix q, accel;
    agent.evaluate(s, q, accel);
    const float c_norm = (accel(0, 0) + 0.95f) / 3.55f;  // mu(s) before the update
    const UpdateStats u = agent.update();
    nn::Network qnet = agent.qNetwork();  // Q after its step = the Q the mu loss saw
    qnet.eval();
    Matrix in(6, 1);
    in << s, Matrix::Constant(1, 1, c_norm);
    const Matrix q_after = qnet.forward(in);
    const float expected = accel_only ? -q_after(2, 0) : -q_after.sum();
    EXPECT_NEAR(u.param_loss, expected, 1e-4f) << accel_only;
  }
}

TEST(PdqnDepartures, RejectsBadDepartureSettingsNamingThem) {
  auto rejected = [](PdqnConfig c, const std::string& field) {
    try {
      PdqnAgent agent(c);
      ADD_FAILURE() << "accepted a bad " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  PdqnConfig c = smallConfig();
  c.target_soft_tau = 1.5f;
  rejected(c, "target_soft_tau");
  c = smallConfig();
  c.epsilon_linear_rounds = -1.0;
  rejected(c, "epsilon_linear_rounds");
}

TEST(PdqnDepartures, LinearEpsilonReachesItsFloorAfterTheStatedRounds) {
  PdqnConfig c = smallConfig();
  c.epsilon_start = 1.0;
  c.epsilon_final = 0.2;
  c.epsilon_linear_rounds = 4;
  PdqnAgent agent(c);
  Rng data(2);
  const Matrix s = randomStates(5, 3, data);
  const double expected[] = {0.8, 0.6, 0.4, 0.2, 0.2};
  for (double e : expected) {
    agent.act(s, true);
    EXPECT_NEAR(agent.epsilon(), e, 1e-12);
  }
  agent.act(s, false);  // greedy rounds do not count
  EXPECT_NEAR(agent.epsilon(), 0.2, 1e-12);
}

TEST(PdqnAgent, Bf16ProductsChangeTheUpdatesOnlyByBfloat16sPrecisionAndNeverTheDecisions) {
  if (!nn::bf16GemmAvailable()) {
    PdqnConfig c = smallConfig();
    c.bf16_products = true;
    EXPECT_THROW(c.validate(), std::invalid_argument);
    GTEST_SKIP() << "built for a CPU without AVX-512 BF16";
  }
  Eigen::setNbThreads(1);
  // Hidden layers that fit the bf16 tiles (64 x 64), a batch of 32.
  PdqnConfig c = smallConfig(21);
  c.hidden_sizes = {64, 64};
  c.batch_size = 32;
  PdqnConfig low_c = c;
  low_c.bf16_products = true;
  PdqnAgent plain(c), low(low_c), other_data(c);
  const auto weights = [](const PdqnAgent& a) {
    const std::vector<float> v = a.exportModel().values;
    return Eigen::Map<const Vector>(v.data(), static_cast<Index>(v.size())).eval();
  };
  const Vector start = weights(plain);
  ASSERT_EQ(weights(low), start);
  fillReplay(plain, 128, 8);
  fillReplay(low, 128, 8);
  fillReplay(other_data, 128, 9);  // the same start trained on other transitions: a real difference
  for (int i = 0; i < 20; ++i) {
    plain.update();
    low.update();
    other_data.update();
  }
  const Vector moved = weights(plain) - start;
  // The bounds sit between bf16's drift and other data's (journal, "A bfloat16 gradient step").
  const double low_off = (weights(low) - weights(plain)).norm() / moved.norm();
  const double data_off = (weights(other_data) - weights(plain)).norm() / moved.norm();
  EXPECT_GT(low_off, 0.0) << "bf16 products: not the float updates";
  EXPECT_LT(low_off, 0.03) << "20 bf16 steps moved the weights " << low_off << " of the float steps' way off";
  EXPECT_GT(data_off, 0.1) << "the bound must be able to fail: other data moves them " << data_off;

  // The decisions after the steps are the float network's: the same as a float agent holding
  // the bf16-trained model.
  PdqnAgent float_copy(c);
  float_copy.importModel(low.exportModel());
  Rng data(4);
  const Matrix states = randomStates(c.state_size, 16, data);
  std::vector<Decision> from_low, from_float;
  low.act(states, false, from_low);
  float_copy.act(states, false, from_float);
  ASSERT_EQ(from_low.size(), from_float.size());
  for (size_t j = 0; j < from_low.size(); ++j) {
    EXPECT_EQ(from_low[j].action, from_float[j].action);
    EXPECT_EQ(from_low[j].accel_mps2, from_float[j].accel_mps2);
  }
}
