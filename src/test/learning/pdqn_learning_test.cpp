// A learning test that can fail: a small synthetic task with a discrete choice and a
// continuous parameter, trained from a fixed seed with a small network.
//
// Task ("pick the lane action, or the acceleration that reaches the target speed"):
//   state (6) = one-hot of the correct action k (4), (v - 25 m/s) / 5 m/s,
//   (v_target - v) / 5 m/s, with v ~ U[20, 30] m/s and, for k = a2,
//   v_target = v + a_req * 1 s, a_req ~ U[-4, 2] m/s^2 (else v_target = v).
//   Features are centred and scaled as the RSU's state normaliser does; an un-normalised
//   speed pair (v / 33.5, v_target / 33.5) leaves the gap at ~0.1 of the feature scale and
//   needs several times more steps.
//   reward = 0 for a wrong action; 1 for a correct a0 / a1 / a3; for a correct a2
//   max(0, 1 - |v + a dt - v_target| / 2) = max(0, 1 - |a - a_req| / 2) (dt = 1 s).
//   Episodes of 4 independent steps (done at the 4th), gamma 0.9, so the TD target
//   bootstraps through the target networks.
// Greedy optimum: 1 on every state. A uniformly random policy earns about
// 0.75 * 0.25 * 1 + 0.25 * 0.25 * E[max(0, 1 - |U(-4.5, 2.6) - a_req| / 2)] ~ 0.21.
#include <Eigen/Core>
#include <gtest/gtest.h>

#include <cmath>

#include "palcas_core/learning/pdqn_agent.h"

using namespace palcas;
using nn::Index;
using nn::Matrix;

namespace {

constexpr float SPEED_MID_MPS = 25.0f;
constexpr float SPEED_SCALE_MPS = 5.0f;
constexpr Index STATE_SIZE = 6;
constexpr Index CAVS_PER_ROUND = 8;
constexpr int EPISODE_STEPS = 4;
constexpr float PASS_MEAN_RETURN = 0.85f;  // per-step greedy reward that counts as learned

struct Task {
  int correct;  // action code k
  float v_mps, a_req_mps2;
};

Task drawTask(Rng& rng) {
  Task t;
  t.correct = static_cast<int>(rng.uniformIndex(4));
  t.v_mps = rng.uniform(20.0f, 30.0f);
  t.a_req_mps2 = t.correct == 2 ? rng.uniform(-4.0f, 2.0f) : 0.0f;
  return t;
}

void writeState(const Task& t, Matrix& states, Index col) {
  states.col(col).setZero();
  states(t.correct, col) = 1.0f;
  states(4, col) = (t.v_mps - SPEED_MID_MPS) / SPEED_SCALE_MPS;
  states(5, col) = t.a_req_mps2 * 1.0f / SPEED_SCALE_MPS;  // (v_target - v) / scale, dt = 1 s
}

float reward(const Task& t, const Decision& d) {
  if (static_cast<int>(d.action) != t.correct) return 0.0f;
  if (t.correct != 2) return 1.0f;
  return std::max(0.0f, 1.0f - std::abs(d.accel_mps2 - t.a_req_mps2) / 2.0f);
}

PdqnConfig taskConfig(float learning_rate) {
  PdqnConfig c;
  c.state_size = STATE_SIZE;
  c.hidden_sizes = {32, 32};
  c.batch_size = 64;
  c.learning_rate = learning_rate;
  c.gamma = 0.9f;
  c.replay_capacity = 20000;
  c.target_update_steps = 100;
  c.epsilon_decay = 0.997;  // per round: 0.997^1000 = 0.05
  c.epsilon_final = 0.05;
  c.accel_noise_std_mps2 = 0.3f;
  c.seed = 2024;
  return c;
}

// Runs `rounds` exploring decision rounds of 8 CAVs, one gradient step per round once the
// replay holds a batch (no step when learn is false).
void train(PdqnAgent& agent, int rounds, bool learn) {
  Rng env(7);
  std::vector<Task> tasks(CAVS_PER_ROUND), next(CAVS_PER_ROUND);
  for (auto& t : tasks) t = drawTask(env);
  Matrix states(STATE_SIZE, CAVS_PER_ROUND), next_states(STATE_SIZE, CAVS_PER_ROUND);
  std::vector<Decision> decisions;
  for (int round = 0; round < rounds; ++round) {
    for (Index j = 0; j < CAVS_PER_ROUND; ++j) writeState(tasks[j], states, j);
    agent.act(states, true, decisions);
    const bool done = round % EPISODE_STEPS == EPISODE_STEPS - 1;
    for (Index j = 0; j < CAVS_PER_ROUND; ++j) {
      next[j] = drawTask(env);
      writeState(next[j], next_states, j);
      agent.remember(states.col(j), decisions[j], reward(tasks[j], decisions[j]),
                     next_states.col(j), ALL_ACTIONS, done);
    }
    tasks.swap(next);
    if (learn && agent.canUpdate()) agent.update();
  }
}

struct Evaluation {
  float mean_reward;        // over all evaluation states
  float accel_mean_reward;  // over the states whose correct action is a2
};

Evaluation evaluateGreedy(PdqnAgent& agent) {
  Rng env(99);  // the same 400 evaluation states for every policy
  const Index n = 400;
  std::vector<Task> tasks(n);
  Matrix states(STATE_SIZE, n);
  for (Index j = 0; j < n; ++j) {
    tasks[j] = drawTask(env);
    writeState(tasks[j], states, j);
  }
  const std::vector<Decision> decisions = agent.act(states, false);
  double sum = 0, accel_sum = 0;
  int accel_count = 0;
  for (Index j = 0; j < n; ++j) {
    const float r = reward(tasks[j], decisions[j]);
    sum += r;
    if (tasks[j].correct == 2) {
      accel_sum += r;
      ++accel_count;
    }
  }
  return {static_cast<float>(sum / n), static_cast<float>(accel_sum / accel_count)};
}

constexpr int TRAINING_ROUNDS = 5000;

}  // namespace

TEST(PdqnLearning, TrainedGreedyPolicyBeatsTheThreshold) {
  Eigen::setNbThreads(1);
  PdqnAgent agent(taskConfig(1e-3f));
  const Evaluation before = evaluateGreedy(agent);
  train(agent, TRAINING_ROUNDS, true);
  const Evaluation after = evaluateGreedy(agent);
  std::printf("greedy mean reward: untrained %.3f -> trained %.3f (a2 states %.3f)\n",
              before.mean_reward, after.mean_reward, after.accel_mean_reward);
  EXPECT_LT(before.mean_reward, PASS_MEAN_RETURN);
  EXPECT_GE(after.mean_reward, PASS_MEAN_RETURN);
  // The continuous parameter is learned too: a mean reward >= 0.6 on a2 states means
  // |a - a_req| <= 0.8 m/s^2 on average (a random acceleration earns ~0.3 there).
  EXPECT_GE(after.accel_mean_reward, 0.6f);
}

TEST(PdqnLearning, WithoutLearningTheThresholdIsNotReached) {
  Eigen::setNbThreads(1);
  PdqnAgent agent(taskConfig(0.0f));  // lr 0: AdamW leaves every weight as initialised
  train(agent, TRAINING_ROUNDS, true);
  const Evaluation frozen = evaluateGreedy(agent);
  PdqnAgent idle(taskConfig(1e-3f));
  train(idle, TRAINING_ROUNDS, false);  // same experience, no update() at all
  const Evaluation no_updates = evaluateGreedy(idle);
  std::printf("greedy mean reward: lr 0 %.3f, no updates %.3f\n", frozen.mean_reward,
              no_updates.mean_reward);
  EXPECT_LT(frozen.mean_reward, PASS_MEAN_RETURN);
  EXPECT_LT(no_updates.mean_reward, PASS_MEAN_RETURN);
}
