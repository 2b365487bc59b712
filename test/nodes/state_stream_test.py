#!/usr/bin/python3
"""rostest: the bridge publishes one VehicleStateArray per simulation step, on sim time.

Checks on ~messages consecutive states: step numbers increase by one, header stamps by the
step length, /clock matches the state stamp, and vehicles appear with sane fields.
"""
import math
import threading
import time
import unittest

import rospy
import rostest
from palcas_msgs.msg import VehicleStateArray
from rosgraph_msgs.msg import Clock


class StateStreamTest(unittest.TestCase):
    def setUp(self):
        self.states = []
        self.clocks = []
        self.lock = threading.Lock()
        rospy.Subscriber("/vehicle_states", VehicleStateArray, self.on_states, queue_size=1000)
        rospy.Subscriber("/clock", Clock, self.on_clock, queue_size=1000)

    def on_states(self, msg):
        with self.lock:
            self.states.append(msg)

    def on_clock(self, msg):
        with self.lock:
            self.clocks.append(msg.clock.to_sec())

    def wait_for(self, count, timeout_s):
        # Wall-clock timeout on purpose: sim time only moves while the bridge runs.
        end = time.monotonic() + timeout_s
        while time.monotonic() < end and not rospy.is_shutdown():
            with self.lock:
                if len(self.states) >= count:
                    return
            time.sleep(0.02)

    def test_one_state_per_step_on_sim_time(self):
        wanted = rospy.get_param("~messages", 300)
        self.wait_for(wanted, rospy.get_param("~timeout_s", 60.0))
        with self.lock:
            states = list(self.states)
            clocks = set(round(c, 6) for c in self.clocks)
        self.assertGreaterEqual(len(states), wanted, "too few VehicleStateArray messages")
        step_length = states[0].step_length_s
        self.assertAlmostEqual(step_length, 0.1, places=9)
        self.assertEqual(states[0].step, 0, "the bridge started before the subscriber (handshake)")
        for prev, cur in zip(states, states[1:]):
            self.assertEqual(cur.step, prev.step + 1, "a step was skipped or repeated")
            dt = cur.header.stamp.to_sec() - prev.header.stamp.to_sec()
            self.assertAlmostEqual(dt, step_length, places=6)
        # /clock carries every step's time (ROS may drop a message under load: allow 2 %).
        missing_clock = [s.step for s in states if round(s.header.stamp.to_sec(), 6) not in clocks]
        self.assertLessEqual(len(missing_clock), 0.02 * len(states),
                             "/clock never showed these steps' times: %s" % missing_clock[:10])
        seen = [v for s in states for v in s.vehicles]
        self.assertTrue(seen, "no vehicle appeared in %d steps" % len(states))
        for v in seen:
            self.assertTrue(math.isfinite(v.x_m) and math.isfinite(v.speed_mps), v.id)
            self.assertGreaterEqual(v.speed_mps, 0.0)
            self.assertLessEqual(v.lane, states[0].num_lanes)
        self.assertTrue(any(v.is_cav for v in seen) and any(not v.is_cav for v in seen),
                        "expected both CAVs and human-driven vehicles")


if __name__ == "__main__":
    rospy.init_node("state_stream_test")
    rostest.rosrun("palcas_tests", "state_stream_test", StateStreamTest)
