#!/usr/bin/python3
"""Test: a short training run of the PALCAS arm on the tiny road finishes and leaves what a
user resumes and evaluates from: metrics, a row per episode, every RSU's checkpoint and
learning rows. The same run (seed 1, short schedule) once
aborted inside SUMO 1.15 at t = 58 s (a lane change asked for while a CAV's back was still
on a junction); it is the regression test for that. SUMO 1.15 still aborts rarely on its
own (a known sublane bug, handled by ./palcas train by resuming): an abort is retried once
with the next seed, a second one fails the test.
"""
import csv
import json
import os
import socket
import subprocess
import sys
import tempfile
import unittest

import rospkg
import rostest


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class TrainingSmokeTest(unittest.TestCase):
    def run_training(self, seed):
        out = tempfile.mkdtemp(prefix="palcas_train_smoke_")
        config = rospkg.RosPack().get_path("palcas_config")
        port = free_port()
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_LOG_DIR=out + "/log")
        run = subprocess.run(
            ["roslaunch", "-p", str(port), "palcas_launch", "system.launch", "arm:=palcas", "mode:=train", "scenario:=tiny",
             "seed:=%d" % seed, "duration:=120", "checkpoint_dir:=" + out + "/checkpoints",
             "out_dir:=" + out, "learning_params:=%s/training/short_learning.yaml" % config,
             "rsu_params:=%s/training/short_rsu.yaml" % config,
             # Busy zones off, as in the learning regression test: in 120 s a zone the guard
             # hands back to the CAVs' own driving may collect fewer transitions than one batch
             # (rsu_1: 204 of 256 once the insertion-edge guard shifted seed 1's traffic).
             "bridge_params:=%s/training/learning_only.yaml" % config],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=400, text=True)
        return out, run

    def test_short_training_finishes_with_checkpoints(self):
        out, run = self.run_training(1)
        if "Assertion" in run.stdout:
            print("SUMO aborted (known sublane bug); retrying with the next seed")
            out, run = self.run_training(2)
        self.assertNotIn("Assertion", run.stdout, "SUMO aborted twice:\n" + run.stdout[-3000:])
        self.assertTrue(os.path.exists(out + "/metrics.json"), run.stdout[-3000:])
        self.assertEqual(json.load(open(out + "/metrics.json"))["sim_seconds"], 120.0)
        rows = list(csv.DictReader(open(out + "/episodes.csv")))
        self.assertEqual(len(rows), 1)
        for rsu in ("rsu_0", "rsu_1"):
            for name in ("agent.ckpt", "controller.txt", "model.palcas", "learning.csv"):
                self.assertTrue(os.path.exists("%s/checkpoints/%s/%s" % (out, rsu, name)), (rsu, name))
            learning = list(csv.DictReader(open("%s/checkpoints/%s/learning.csv" % (out, rsu))))
            self.assertGreater(int(learning[-1]["gradient_steps"]), 0, rsu)
        # The server checkpoints after each closed round; 120 s is shorter than one round.


if __name__ == "__main__":
    rostest.rosrun("palcas_tests", "training_smoke_test", TrainingSmokeTest, sys.argv)
