#!/usr/bin/env python3
"""A plain numpy learner on the PALCAS road through palcas_env (no deep-learning framework):
linear Q-learning over the paper's state for the advisory, and a linear Gaussian policy for
ACCELERATE's acceleration, trained on the RSUs' own rewards. A worked example of the API,
not a method: it shows the loop, the hybrid action and where the rewards come from.

  examples/numpy_learner.py [--scenario tiny] [--episodes 3] [--duration 120] [--seed 7]
                            [--out DIR]

Writes DIR/numpy_learner.npz (q_weights (4, state_size + 1), accel_weights (state_size + 1),
per-episode history) and prints one line per episode. "Learnt" is measured on the last
episode's transitions: the mean squared TD error under the final weights against the
initial (all-zero) ones.
"""
import argparse
import os
import sys

import numpy as np

import palcas_env

GAMMA = 0.9


class LinearLearner:
    def __init__(self, state_size, accel_bounds, seed, lr=0.01, epsilon=0.2, accel_std=0.5):
        self.rng = np.random.default_rng(seed)
        self.q_weights = np.zeros((4, state_size + 1))      # Q(s, a) = w_a . [s, 1]
        self.accel_weights = np.zeros(state_size + 1)       # mean acceleration = w . [s, 1]
        self.low, self.high = accel_bounds
        self.lr, self.epsilon, self.accel_std = lr, epsilon, accel_std
        self.updates = 0

    @staticmethod
    def features(state):
        return np.append(np.asarray(state, dtype=np.float64), 1.0)

    def act(self, state):
        x = self.features(state)
        advisory = int(self.rng.integers(4)) if self.rng.random() < self.epsilon else int(np.argmax(self.q_weights @ x))
        accel = float(np.clip(self.accel_weights @ x + self.accel_std * self.rng.normal(), self.low, self.high))
        return advisory, accel

    def td_error(self, q_weights, s, a, r, s_next, terminal):
        x = self.features(s)
        target = r if terminal or s_next is None else r + GAMMA * np.max(q_weights @ self.features(s_next))
        return target - q_weights[a] @ x

    def update(self, s, action, r, s_next, terminal):
        a, accel = action
        x = self.features(s)
        delta = self.td_error(self.q_weights, s, a, r, s_next, terminal)
        step = self.lr / (1.0 + x @ x)  # normalised LMS: stable whatever the features' scale
        self.q_weights[a] += step * delta * x
        if a == palcas_env.ACCELERATE:
            # Towards the acceleration that was tried, in proportion to how much better it went.
            self.accel_weights += step * delta * (accel - self.accel_weights @ x) * x
        self.updates += 1
        return delta


def train(scenario="tiny", episodes=3, duration_s=120.0, seed=7, out_dir=None, pr=60):
    env = palcas_env.ParallelEnv(scenario=scenario, mode="train", pr=pr, seed=seed, duration_s=duration_s,
                                 out_dir=out_dir)
    learner = LinearLearner(env.state_size, env.action_space("")["acceleration"], seed)
    history = []
    transitions = []
    for episode in range(episodes):
        observations, _ = env.reset(seed=seed + episode)
        last = {}  # agent -> (state, action) awaiting its reward
        transitions = []
        rewards_sum, deltas = 0.0, []
        while env.agents:
            actions = {agent: learner.act(observations[agent]) for agent in env.agents}
            for agent in env.agents:
                last[agent] = (observations[agent], actions[agent])
            observations, rewards, terminations, truncations, _ = env.step(actions)
            for agent, reward in rewards.items():
                if agent not in last:
                    continue
                s, action = last.pop(agent) if (terminations[agent] or truncations[agent]) else last[agent]
                terminal = bool(terminations[agent])
                s_next = observations.get(agent)
                deltas.append(learner.update(s, action, reward, s_next, terminal))
                transitions.append((s, action[0], reward, s_next, terminal))
                rewards_sum += reward
        metrics = env.metrics()
        row = {"episode": episode, "transitions": len(deltas), "mean_reward": rewards_sum / max(len(deltas), 1),
               "mean_abs_td": float(np.mean(np.abs(deltas))) if deltas else float("nan"),
               "dsr_pct": metrics["dsr_pct"], "collisions": metrics["collisions"]}
        history.append(row)
        print("episode %(episode)d: %(transitions)d transitions, mean reward %(mean_reward).3f, mean |TD| "
              "%(mean_abs_td).3f, DSR %(dsr_pct)s %%, collisions %(collisions)d" % row, flush=True)
    # What was learnt, on the last episode's transitions: the learnt Q against the initial
    # (all-zero) one, both measured against the same targets r + gamma max_a' Q(s', a').
    before, after = float("nan"), float("nan")
    if transitions:
        targets, learnt = [], []
        for s, a, r, s_next, terminal in transitions:
            delta = learner.td_error(learner.q_weights, s, a, r, s_next, terminal)
            q = learner.q_weights[a] @ learner.features(s)
            targets.append(q + delta)
            learnt.append(delta)
        before = float(np.mean(np.square(targets)))
        after = float(np.mean(np.square(learnt)))
    env.close()
    path = os.path.join(env.out_dir, "numpy_learner.npz")
    np.savez(path, q_weights=learner.q_weights, accel_weights=learner.accel_weights,
             history_mean_reward=[h["mean_reward"] for h in history],
             history_mean_abs_td=[h["mean_abs_td"] for h in history], updates=learner.updates,
             td_mse_initial=before, td_mse_final=after)
    print("%d updates; last episode's squared error against the TD targets: %.4f with the initial Q, %.4f "
          "with the learnt Q; model %s"
          % (learner.updates, before, after, path))
    return {"path": path, "updates": learner.updates, "td_mse_initial": before, "td_mse_final": after,
            "history": history}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="tiny")
    ap.add_argument("--episodes", type=int, default=3)
    ap.add_argument("--duration", type=float, default=120.0)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--pr", type=float, default=60)
    ap.add_argument("--out")
    a = ap.parse_args()
    train(a.scenario, a.episodes, a.duration, a.seed, a.out, a.pr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
