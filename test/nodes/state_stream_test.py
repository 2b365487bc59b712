#!/usr/bin/python3
"""rostest: the bridge publishes one VehicleStateArray per simulation step, on sim time.

Checks on ~messages consecutive states: step numbers increase by one, header stamps by the
step length, /clock matches the state stamp, and vehicles appear with sane fields.
"""
import math
import os
import sys
import threading
import unittest

import rospy
import rostest
from palcas_msgs.msg import VehicleStateArray
from rosgraph_msgs.msg import Clock

# waiting.py beside this file (catkin's devel relay runs this file from elsewhere).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from waiting import poll  # noqa: E402


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

    def test_one_state_per_step_on_sim_time(self):
        wanted = rospy.get_param("~messages", 300)
        # No failure here: the checks below say what fell short.
        poll(lambda: len(self.states) >= wanted, rospy.get_param("~timeout_s", 60.0), self.lock)
        with self.lock:
            states = list(self.states)
            clock_sequence = [round(c, 6) for c in self.clocks]
        clocks = set(clock_sequence)
        self.assertGreaterEqual(len(states), wanted, "too few VehicleStateArray messages")
        step_length = states[0].step_length_s
        self.assertAlmostEqual(step_length, 0.1, places=9)
        self.assertEqual(states[0].step, 0, "the bridge started before the subscriber (handshake)")
        for prev, cur in zip(states, states[1:]):
            self.assertEqual(cur.step, prev.step + 1, "a step was skipped or repeated")
            dt = cur.header.stamp.to_sec() - prev.header.stamp.to_sec()
            self.assertAlmostEqual(dt, step_length, places=6)
        # /clock carries the steps' times and nothing else, never going back. A loaded CI box
        # lost two bursts of 5 clock messages in 300 between the bridge and this rospy
        # subscriber (queues of 1000 on both sides): tolerate 10 % missing, none invented.
        missing_clock = [s.step for s in states if round(s.header.stamp.to_sec(), 6) not in clocks]
        self.assertLessEqual(len(missing_clock), 0.10 * len(states),
                             "/clock never showed these steps' times: %s" % missing_clock[:10])
        step_times = set(round(s.header.stamp.to_sec(), 6) for s in states)
        first, last = min(step_times), max(step_times)
        stray = [c for c in clocks if first <= c <= last and c not in step_times]
        self.assertFalse(stray, "/clock showed times no step had: %s" % sorted(stray)[:10])
        went_back = [(a, b) for a, b in zip(clock_sequence, clock_sequence[1:]) if b < a]
        self.assertFalse(went_back, "/clock went back in time: %s" % went_back[:5])
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
