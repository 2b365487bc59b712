#!/usr/bin/python3
"""Test: a 4th cluster and a 4th lane are one number each in one file.

Copies config/scenarios/tiny/ (2 clusters, 3 lanes), changes road/clusters to 4 and
road/num_lanes to 4 in its scenario.yaml, and runs the federated system on it for a short
training episode (`roslaunch palcas_launch system.launch scenario:=<copy>`, nothing else
told about the road). The bag must show four RSUs advising CAVs in their own zones, states
of a 4-lane road, federation rounds closed by all four, and traffic leaving by the 4th exit.
"""
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import unittest

import rosbag
import rospkg
import rostest
import yaml

CLUSTERS, LANES, CLUSTER_LENGTH_M = 4, 4, 300.0


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def four_by_four_scenario(root):
    tiny = os.path.join(rospkg.RosPack().get_path("palcas_config"), "scenarios", "tiny")
    folder = os.path.join(root, "tiny4x4")
    shutil.copytree(tiny, folder)
    path = os.path.join(folder, "scenario.yaml")
    text = open(path).read()
    for key, old, new in (("clusters", 2, CLUSTERS), ("num_lanes", 3, LANES)):
        line = "  %s: %d\n" % (key, old)
        assert text.count(line) == 1, "tiny's scenario.yaml has no single line %r" % line
        text = text.replace(line, "  %s: %d\n" % (key, new))
    open(path, "w").write(text)
    road = yaml.safe_load(text)["road"]
    assert (road["clusters"], road["num_lanes"], road["cluster_length_m"]) == (CLUSTERS, LANES, CLUSTER_LENGTH_M)
    return folder


class FourClusterRoadTest(unittest.TestCase):
    def test_four_rsus_advise_on_a_four_lane_road(self):
        out = tempfile.mkdtemp(prefix="palcas_4x4_")
        scenario = four_by_four_scenario(out)
        tests = rospkg.RosPack().get_path("palcas_tests")
        port = free_port()
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_LOG_DIR=out + "/log")
        run = subprocess.run(
            ["roslaunch", "-p", str(port), "palcas_launch", "system.launch", "arm:=palcas", "scenario:=" + scenario,
             "mode:=train", "duration:=150", "seed:=3", "record:=true", "out_dir:=" + out + "/run",
             "checkpoint_dir:=" + out + "/checkpoints", "respawn:=false",
             "learning_params:=%s/launch/small_learning.yaml" % tests,
             "rsu_params:=%s/launch/small_rsu.yaml" % tests,
             "bridge_params:=%s/launch/closed_loop_bridge.yaml" % tests],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=500, text=True)
        log = run.stdout[-4000:]
        self.assertTrue(os.path.exists(out + "/run/metrics.json"), log)
        metrics = json.load(open(out + "/run/metrics.json"))

        rsus = ["rsu_%d" % k for k in range(CLUSTERS)]
        advised_x = {r: [] for r in rsus}
        lanes_seen, num_lanes = set(), set()
        with rosbag.Bag(out + "/run/episode.bag") as bag:
            # Positions by step: an advisory answers the state of its own `step`, which on a
            # loaded machine need not be the last state recorded before it.
            x_at_step = {}
            for topic, msg, _ in bag.read_messages(topics=["/vehicle_states", "/advisories"]):
                if topic == "/vehicle_states":
                    num_lanes.add(msg.num_lanes)
                    x_at_step[msg.step] = {v.id: v.x_m for v in msg.vehicles}
                    lanes_seen.update(v.lane for v in msg.vehicles)
                else:
                    self.assertIn(msg.rsu_id, rsus, "an advisory from an RSU the road does not have")
                    x = x_at_step.get(msg.step, {})  # a state the recorder dropped: not judged
                    advised_x[msg.rsu_id] += [x[a.vehicle_id] for a in msg.advisories if a.vehicle_id in x]
        self.assertEqual(num_lanes, {LANES}, "the bridge's road has another lane count")
        self.assertIn(LANES, lanes_seen, "no vehicle on lane 4")
        for k, r in enumerate(rsus):
            self.assertGreater(len(advised_x[r]), 10, "%s advised (almost) nobody\n%s" % (r, log))
            inside = [x for x in advised_x[r] if k * CLUSTER_LENGTH_M - 5 <= x < (k + 1) * CLUSTER_LENGTH_M + 5]
            self.assertGreater(len(inside), 0.9 * len(advised_x[r]), "%s advised CAVs outside its zone" % r)
        self.assertGreater(metrics["exits_ok"], 0, "no vehicle took an exit")
        state = json.load(open(out + "/checkpoints/fedserver/federation_state.json"))
        self.assertGreaterEqual(state["round"], 1, "no federation round closed: %s" % state)
        self.assertEqual(sorted(os.listdir(out + "/checkpoints")), sorted(rsus + ["fedserver"]))
        routes = open(out + "/run/scenario/routes.rou.xml").read()
        self.assertIn('r_main_off3', routes, "no route to the 4th exit (default route mix)")


if __name__ == "__main__":
    rostest.rosrun("palcas_tests", "four_cluster_road_test", FourClusterRoadTest, sys.argv)
