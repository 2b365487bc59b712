#!/usr/bin/env python3
"""palcas_env, the Python module (palcas_sumo_bridge/python/README.md):
  1. the shipped policy evaluated from Python gives the metrics `./palcas run` writes for the
     same episode (paper road, 30 s, seed 101): same vehicles, same decisions;
  2. the numpy learner example trains on the tiny road, updates its weights, fits its TD
     targets better than its initial weights and writes its model;
  3. the numpy forward pass of an exported .npz takes the C++ decisions on real states;
  4. bad input raises naming what was wrong and leaves the environment usable; agents enter
     and leave with a final reward and a termination or truncation.
Needs the built workspace, sourced (./palcas test does both); about two minutes.

  palcas_sumo_bridge/python/test/palcas_env_test.py [--xml FILE]
"""
import json
import math
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "test" / "tools"))
sys.path.insert(0, str(ROOT / "palcas_sumo_bridge" / "python" / "examples"))
from junit_runner import run_as_junit  # noqa: E402

import palcas_env  # noqa: E402
from palcas_env.numpy_policy import NumpyPolicy  # noqa: E402

# Fields that differ between two runs of one episode for reasons of the machine, not of the
# traffic: wall-clock time and what is derived from it (the real-time factor, the per-step
# cost buckets) and the RSUs' decision latencies (wall time from the state to the answer:
# through a call inside the bridge there, through Python here).
TIMING_FIELDS = {"wall_seconds", "real_time_factor", "step_timing", "decision_ms_p50", "decision_ms_p90",
                 "decision_ms_p99"}
# Facts ./palcas run adds to a learning arm's metrics.json after the run
# (tools/add_training_facts.py: the policy's folder and its training's federation rounds),
# not measured by the bridge.
ADDED_BY_THE_COMMAND = {"policy", "federation_rounds"}

PYTHON = "/usr/bin/python3"
SEED, DURATION_S = 101, 30


class TmpDir(unittest.TestCase):
    def setUp(self):
        self.tmp = pathlib.Path(tempfile.mkdtemp(prefix="palcas_env_test-"))

    def tearDown(self):
        # PALCAS_KEEP_TEST_DIRS=1 keeps the run folders to look at.
        if not os.environ.get("PALCAS_KEEP_TEST_DIRS"):
            shutil.rmtree(self.tmp, ignore_errors=True)


class ShippedPolicyParity(TmpDir):
    def test_python_evaluation_gives_the_metrics_of_palcas_run(self):
        env = dict(os.environ, PALCAS_NO_BUILD="1")
        r = subprocess.run([str(ROOT / "palcas"), "run", "--arm", "palcas", "--no-compare", "--in-process",
                            "--duration", str(DURATION_S), "--seed", str(SEED), "--pr", "60",
                            "--out", str(self.tmp / "run")], env=env, capture_output=True, text=True, timeout=900)
        self.assertEqual(r.returncode, 0, r.stdout[-3000:] + r.stderr[-3000:])
        suite = json.loads((self.tmp / "run" / "palcas" / "metrics.json").read_text())

        import evaluate_policy
        ours, _, decisions = evaluate_policy.evaluate("shipped", "paper", SEED, DURATION_S, pr=60,
                                                      out_dir=str(self.tmp / "python"))
        self.assertGreater(decisions, 0)
        self.assertGreater(suite["advisories"], 0)  # the policy advised: the comparison means something
        compared = set(suite) - TIMING_FIELDS - ADDED_BY_THE_COMMAND
        self.assertEqual(sorted(compared), sorted(set(ours) - TIMING_FIELDS))
        self.assertGreater(len(compared), 40)
        differ = ["%s: ./palcas run %r, palcas_env %r" % (k, suite[k], ours[k])
                  for k in sorted(compared) if suite[k] != ours[k]]
        self.assertEqual(differ, [])


class NumpyLearner(TmpDir):
    def test_trains_updates_and_writes_its_model(self):
        import numpy_learner
        out = numpy_learner.train("tiny", episodes=2, duration_s=60.0, seed=7, out_dir=str(self.tmp))
        self.assertGreater(out["updates"], 100)
        model = np.load(out["path"])
        self.assertEqual(model["q_weights"].shape, (4, 44))  # tiny: 3 lanes, 43 features + bias
        self.assertTrue(np.any(model["q_weights"] != 0.0))   # it moved off its initial weights
        self.assertTrue(all(math.isfinite(h["mean_reward"]) for h in out["history"]))
        # What it learnt: its Q fits its TD targets better than the initial (zero) Q does.
        self.assertLess(out["td_mse_final"], out["td_mse_initial"])


class NumpyForward(TmpDir):
    def test_numpy_forward_of_the_export_takes_the_cpp_decisions(self):
        env = palcas_env.ParallelEnv(scenario="paper", mode="eval", seed=SEED, duration_s=60.0,
                                     out_dir=str(self.tmp / "run"), policy="shipped")
        self.addCleanup(env.close)
        policy = palcas_env.Policy.load("shipped", env)
        states = {rsu: [] for rsu in env.rsu_ids}
        observations, _ = env.reset(seed=SEED)
        while env.agents:
            for agent in env.agents:
                states[agent.split("/", 1)[0]].append(observations[agent])
            observations, *_ = env.step(policy.act({a: observations[a] for a in env.agents}))
        path = policy.export_npz(str(self.tmp / "policy.npz"))
        numpy_policy = NumpyPolicy(path)
        self.assertEqual(numpy_policy.rsu_ids, env.rsu_ids)
        for rsu, batch in states.items():
            batch = np.array(batch, dtype=np.float32)
            with self.subTest(rsu=rsu):
                self.assertGreater(len(batch), 20)
                cpp = policy.act({"%s/%d" % (rsu, i): s for i, s in enumerate(batch)})
                cpp_advisory = np.array([cpp["%s/%d" % (rsu, i)][0] for i in range(len(batch))])
                cpp_accel = np.array([cpp["%s/%d" % (rsu, i)][1] for i in range(len(batch))])
                advisory, accel = numpy_policy.decide(rsu, batch)
                np.testing.assert_array_equal(advisory, cpp_advisory)
                np.testing.assert_allclose(accel, cpp_accel, rtol=0, atol=1e-4)
                q_cpp, _ = policy.evaluate(rsu, batch)
                q_np, _ = numpy_policy.q_values(rsu, batch)
                np.testing.assert_allclose(q_np, q_cpp, rtol=1e-4, atol=1e-4)


class Api(TmpDir):
    def make(self, **kw):
        env = palcas_env.ParallelEnv(scenario="tiny", mode="train", seed=7, duration_s=60.0,
                                     out_dir=str(self.tmp / "run"), **kw)
        self.addCleanup(env.close)
        return env

    def test_bad_input_raises_naming_it_and_leaves_the_env_usable(self):
        env = self.make()
        observations, _ = env.reset(seed=7)
        self.assertTrue(env.agents)
        agent = env.agents[0]
        keep = {a: (palcas_env.KEEP, 0.0) for a in env.agents}
        cases = [
            (dict(keep, **{agent: (1, 2, 3)}), ValueError, "2 parts"),
            (dict(keep, **{agent: "left"}), TypeError, agent),
            (dict(keep, **{agent: (4, 0.0)}), ValueError, "outside 0..3"),
            (dict(keep, **{agent: (-1, 0.0)}), ValueError, "outside 0..3"),
            (dict(keep, **{agent: (2.5, 0.0)}), ValueError, "integer"),
            (dict(keep, **{agent: (2, float("nan"))}), ValueError, "not finite"),
            (dict(keep, **{agent: (2, "fast")}), ValueError, "acceleration"),
            (dict(keep, **{"rsu_0/no_such_car": (3, 0.0)}), ValueError, "rsu_0/no_such_car"),
            ({a: v for a, v in keep.items() if a != agent}, ValueError, agent),
            ([(3, 0.0)], TypeError, "dict"),
        ]
        for actions, error, named in cases:
            with self.subTest(named=named):
                with self.assertRaises(error) as caught:
                    env.step(actions)
                self.assertIn(named, str(caught.exception))
        for seed in (-1, 2 ** 31, 1.5, "7"):
            with self.subTest(seed=seed):
                with self.assertRaises(ValueError) as caught:
                    env.reset(seed=seed)
                self.assertIn("seed", str(caught.exception))
        self.assertEqual(env.agents[0], agent)  # nothing applied
        observations, rewards, terminations, truncations, infos = env.step(keep)
        self.assertTrue(env.agents)
        for folder, named in ((ROOT / "config", "not a PALCAS policy folder"), (self.tmp / "none", "does not exist")):
            with self.subTest(policy=str(folder)):
                with self.assertRaises(ValueError) as caught:
                    palcas_env.Policy.load(str(folder), env)
                self.assertIn(named, str(caught.exception))
        with self.assertRaises(RuntimeError) as caught:  # the shipped policy is the paper road's (5 lanes)
            palcas_env.Policy.load("shipped", env)
        self.assertIn("policy", str(caught.exception))
        env.step({a: (palcas_env.KEEP, 0.0) for a in env.agents})  # still usable
        with self.assertRaises(RuntimeError) as caught:  # libsumo: one simulation per process
            self.make()
        self.assertIn("close() it first", str(caught.exception))
        env.close()
        with self.assertRaises(RuntimeError):
            env.step({})
        with self.assertRaises(ValueError):
            palcas_env.ParallelEnv(scenario="no_such_road")
        with self.assertRaises(ValueError) as caught:
            self.make(config={"bridge": {"advisory_hold_steps": -3}})
        self.assertIn("advisory_hold_steps", str(caught.exception))
        with self.assertRaises(ValueError) as caught:
            self.make(config={"rsu": {"rsu": {"no_such_key": 1}}})
        self.assertIn("no_such_key", str(caught.exception))

    def test_agents_enter_and_leave_with_a_last_reward(self):
        env = self.make()
        observations, infos = env.reset(seed=7)
        first = observations
        self.assertEqual(set(observations), set(env.agents))
        for agent, state in observations.items():
            self.assertEqual(state.shape, (env.state_size,))
            self.assertEqual(infos[agent]["rsu"], agent.split("/")[0])
        ended, entered, steps = set(), set(env.agents), 0
        while env.agents:
            before = set(env.agents)
            observations, rewards, terminations, truncations, infos = env.step(
                {a: (palcas_env.KEEP, 0.0) for a in env.agents})
            steps += 1
            for agent in set(rewards):
                self.assertTrue(math.isfinite(rewards[agent]), agent)
                self.assertIn(agent, observations)
                if terminations[agent] or truncations[agent]:
                    self.assertNotIn(agent, env.agents)  # gone after its last reward
                    self.assertFalse(terminations[agent] and truncations[agent])
                    ended.add(agent)
            for agent in env.agents:
                self.assertIn(agent, observations)
                self.assertFalse(terminations[agent] or truncations[agent])
            entered |= set(env.agents) - before
        self.assertGreater(steps, 30)
        self.assertTrue(entered and ended)
        self.assertTrue(set(env.possible_agents) >= entered | ended)
        self.assertGreater(env.metrics()["cavs_seen"], 0)
        # The next episode starts afresh; the same seed gives the same first observations.
        again, _ = env.reset(seed=7)
        self.assertEqual(sorted(again), sorted(first))
        for agent in first:
            np.testing.assert_array_equal(again[agent], first[agent])


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "palcas_env")
