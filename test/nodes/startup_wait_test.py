#!/usr/bin/python3
"""rostest: the bridge holds step 0 until both recorders' topics have their subscribers.

With min_subscribers 1 and min_marker_subscribers 1 (what system.launch sets when it records),
a vehicle_states subscriber alone must not start the episode: the bridge keeps publishing
/clock at time 0 and no state. Once a /markers subscriber connects, the episode starts at step
0 and the first vehicle markers carry the first steps' times, so a view bag recorded by such a
subscriber misses none of the episode.
"""
import os
import sys
import threading
import unittest

import rospy
import rostest
from palcas_msgs.msg import VehicleStateArray
from rosgraph_msgs.msg import Clock
from visualization_msgs.msg import MarkerArray

# waiting.py beside this file (catkin's devel relay runs this file from elsewhere).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from waiting import WaitUntil  # noqa: E402

# /clock messages at time 0 to see before judging that the bridge holds: it publishes one
# every 0.05 s of wall time while it waits, so this is about 2 s of waiting with the states
# link open.
CLOCKS_WHILE_HOLDING = 40


class StartupWaitTest(WaitUntil, unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.states = []
        self.clocks_at_zero = 0
        self.vehicle_marker_stamps = []
        rospy.Subscriber("/vehicle_states", VehicleStateArray, self.on_states, queue_size=1000)
        rospy.Subscriber("/clock", Clock, self.on_clock, queue_size=1000)

    def on_states(self, msg):
        with self.lock:
            self.states.append((msg.step, msg.header.stamp.to_sec()))

    def on_clock(self, msg):
        with self.lock:
            if msg.clock.to_sec() == 0.0:
                self.clocks_at_zero += 1

    def on_markers(self, msg):
        with self.lock:
            self.vehicle_marker_stamps += [m.header.stamp.to_sec() for m in msg.markers if m.ns == "vehicles"]

    def test_states_wait_for_the_markers_subscriber(self):
        self.wait_until(lambda: self.clocks_at_zero >= CLOCKS_WHILE_HOLDING or self.states,
                        "the bridge's /clock at time 0 or its first state")
        with self.lock:
            early = list(self.states)
        self.assertEqual(early, [], "the bridge stepped with no /markers subscriber: min_marker_subscribers "
                         "was not waited for")

        rospy.Subscriber("/markers", MarkerArray, self.on_markers, queue_size=1000)
        self.wait_until(lambda: self.states and self.vehicle_marker_stamps, "the first state and vehicle markers")
        with self.lock:
            first_step, first_stamp = self.states[0]
            first_markers = min(self.vehicle_marker_stamps)
        self.assertEqual(first_step, 0, "the episode did not start at step 0")
        # Vehicle markers go out every markers_every_steps (5) steps from step 0.
        self.assertLessEqual(first_markers, first_stamp + 0.5 + 1e-6,
                             "the first vehicle markers came %.1f s into the episode" % first_markers)


if __name__ == "__main__":
    rospy.init_node("startup_wait_test")
    rostest.rosrun("palcas_tests", "startup_wait_test", StartupWaitTest)
