#!/usr/bin/python3
"""Test: eval mode gives identical advisories for the same seed in two runs, with the V2X
channel off and on (latency with jitter, loss and a range shorter than a zone: the channel's
draws follow the seed alone). The bridge waits for an RSU only on its decision steps, so
this also checks that a decision waits for its step's events and its neighbours' cluster
states (palcas_rsu's DecisionInputs): without that wait, which of them an RSU had read when
it decided depended on scheduling.

Runs `roslaunch palcas_launch system.launch arm:=palcas mode:=eval record:=true` twice on the tiny road
(each on its own master port), reads /advisories from both bags and compares every decision:
step, RSU, vehicle, action and acceleration.
"""
import json
import os
import socket
import subprocess
import sys
import tempfile
import unittest

import rosbag
import rospkg
import rostest


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_eval(out, *extra):
    port = free_port()
    tests = rospkg.RosPack().get_path("palcas_tests")
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_LOG_DIR=out + "/log")
    return subprocess.run(
        ["roslaunch", "-p", str(port), "palcas_launch", "system.launch", "arm:=palcas", "scenario:=tiny",
         # 10x real time: at the recording default of 50x a loaded machine's rosbag record
         # (100 messages per topic) can lose advisories, which this test compares.
         "mode:=eval", "policy_dir:=random", "duration:=90", "seed:=7", "record:=true", "real_time_factor:=10",
         "out_dir:=" + out,
         "learning_params:=%s/launch/small_learning.yaml" % tests,
         "bridge_params:=%s/launch/closed_loop_bridge.yaml" % tests] + list(extra),
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300, text=True)


def decisions(bag_path):
    out = {}
    with rosbag.Bag(bag_path) as bag:
        for _, msg, _ in bag.read_messages(topics=["/advisories"]):
            if msg.advisories:
                out[(msg.step, msg.rsu_id)] = [(a.vehicle_id, a.action, round(a.accel_mps2, 5))
                                               for a in msg.advisories]
    return out


class EvalDeterminismTest(unittest.TestCase):
    def test_same_seed_same_advisories(self):
        self.same_twice()

    def test_same_seed_same_advisories_through_the_v2x_channel(self):
        tests = rospkg.RosPack().get_path("palcas_tests")
        outs = self.same_twice("v2x_params:=%s/launch/v2x_impaired.yaml" % tests)
        channel = [json.load(open(out + "/metrics.json"))["v2x"] for out in outs]
        self.assertEqual(channel[0], channel[1], "the channel's counts differ between the runs")
        c = channel[0]
        self.assertTrue(c["enabled"])
        # 20 % lost, every delivered one 2-3 steps late, some beyond the 120 m range.
        self.assertGreater(c["advisories_sent"], 200, c)
        self.assertAlmostEqual(c["advisories_lost"] / c["advisories_sent"], 0.2, delta=0.05)
        self.assertEqual(c["advisories_applied_late"], c["advisories_delivered"], c)
        self.assertGreaterEqual(c["advice_mean_age_s"], 0.2 - 1e-9)
        self.assertLessEqual(c["advice_mean_age_s"], 0.3 + 1e-9)
        self.assertGreater(c["advisories_out_of_range"], 0, c)
        # Every advisory sent met one fate, but those still on their way when the run ended.
        fates = c["advisories_lost"] + c["advisories_out_of_range"] + c["advisories_too_old"] + c["advisories_delivered"]
        self.assertLessEqual(fates, c["advisories_sent"], c)
        self.assertGreater(fates, 0.95 * c["advisories_sent"], c)

    def same_twice(self, *extra):
        runs, outs = [], []
        for _ in range(2):
            out = tempfile.mkdtemp(prefix="palcas_eval_")
            outs.append(out)
            result = run_eval(out, *extra)
            self.assertTrue(os.path.exists(out + "/episode.bag"), result.stdout[-3000:])
            runs.append(decisions(out + "/episode.bag"))
        a, b = runs
        # rosbag record subscribes with a queue of 100 messages: under load it can join late or
        # drop a stretch of /advisories (seen in CI: steps 680-840 missing from one bag while
        # both runs counted the same decisions). A gap in a bag is not a difference between
        # the runs, so compare every (step, RSU) both bags hold, and the full decision counts
        # from metrics.json, which the bridge writes itself.
        counts = [json.load(open(out + "/metrics.json"))["decisions"] for out in outs]
        self.assertEqual(counts[0], counts[1], "the runs made different numbers of decisions")
        common = sorted(set(a) & set(b))
        self.assertGreater(len(common), max(50, counts[0] // 4),
                           "too few decisions in both bags to compare (%d of %d)" % (len(common), counts[0]))
        differing = [k for k in common if a[k] != b[k]]
        self.assertFalse(differing[:5], "different advisories at (step, rsu) %s" % differing[:5])
        return outs


if __name__ == "__main__":
    rostest.rosrun("palcas_tests", "eval_determinism_test", EvalDeterminismTest, sys.argv)
