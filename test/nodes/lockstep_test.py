#!/usr/bin/python3
"""rostest: lockstep waits for a slow RSU up to the deadline and no longer.

A test RSU answers each step after ~answer_delay_s (below the deadline): the bridge must wait
for it, so steps come about that far apart and none is late. Then it stays silent: the
bridge must move on after ~deadline_s per step and count late steps. Then it answers again
at once: the pace recovers. Wide margins: the checks are about the order of magnitude, not
timing luck.
"""
import os
import statistics
import sys
import threading
import time
import unittest

import rospy
import rostest
from palcas_msgs.msg import AdvisoryArray, EpisodeMetrics, VehicleStateArray
from palcas_msgs.srv import RegisterRsu

# waiting.py beside this file (catkin's devel relay runs this file from elsewhere).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from waiting import WaitUntil, poll  # noqa: E402


class LockstepTest(WaitUntil, unittest.TestCase):
    def setUp(self):
        self.rsu_id = rospy.get_param("~rsu_id", "slow_rsu")
        self.delay_s = rospy.get_param("~answer_delay_s", 0.05)
        self.deadline_s = rospy.get_param("~deadline_s", 0.3)
        self.lock = threading.Lock()
        self.mode = "slow"          # slow | silent | fast
        self.arrivals = []          # (wall time, step, mode)
        self.metrics = None
        self.pub = rospy.Publisher("/advisories", AdvisoryArray, queue_size=10)
        rospy.Subscriber("/episode_metrics", EpisodeMetrics, self.on_metrics, queue_size=10)
        rospy.Subscriber("/vehicle_states", VehicleStateArray, self.on_states, queue_size=10,
                         tcp_nodelay=True)
        rospy.wait_for_service("/register_rsu", timeout=60)
        self.assertTrue(rospy.ServiceProxy("/register_rsu", RegisterRsu)(rsu_id=self.rsu_id).accepted)

    def on_metrics(self, msg):
        with self.lock:
            self.metrics = msg

    def on_states(self, msg):
        with self.lock:
            mode = self.mode
            self.arrivals.append((time.monotonic(), msg.step, mode))
        if mode == "silent":
            return
        if mode == "slow":
            time.sleep(self.delay_s)
        answer = AdvisoryArray(step=msg.step, rsu_id=self.rsu_id)
        self.pub.publish(answer)

    def run_phase(self, mode, steps):
        with self.lock:
            self.mode = mode
            start = len(self.arrivals)
        self.wait_until(lambda: len(self.arrivals) >= start + steps,
                        "%d steps of phase %s (did the bridge stop publishing?)" % (steps, mode))
        with self.lock:
            phase = [a for a in self.arrivals[start:start + steps] if a[2] == mode]
        return [b[0] - a[0] for a, b in zip(phase, phase[1:])]

    def late_steps(self):
        with self.lock:
            return None if self.metrics is None else self.metrics.late_rsu_steps

    def test_waits_up_to_the_deadline_and_no_longer(self):
        slow = statistics.median(self.run_phase("slow", 30))
        late_before = self.late_steps() or 0
        silent = statistics.median(self.run_phase("silent", 12))
        fast = statistics.median(self.run_phase("fast", 30))
        # Waited for the slow RSU: about answer_delay_s per step, well under the deadline.
        self.assertGreater(slow, 0.7 * self.delay_s, "the bridge did not wait for the slow RSU")
        self.assertLess(slow, 0.8 * self.deadline_s, "the bridge waited past the answer")
        # Silent RSU: about one deadline per step, not more.
        self.assertGreater(silent, 0.8 * self.deadline_s, "the bridge did not wait the deadline")
        self.assertLess(silent, 2.0 * self.deadline_s, "the bridge waited past the deadline")
        # Answering again at once: the pace recovers (the RSU is still live).
        self.assertLess(fast, 0.5 * self.deadline_s)
        # Late steps were counted (metrics_period_s is one step here).
        poll(lambda: (self.late_steps() or 0) >= late_before + 10, 10.0, interval_s=0.05)
        self.assertGreaterEqual(self.late_steps() or 0, late_before + 10)


if __name__ == "__main__":
    rospy.init_node("lockstep_test")
    rostest.rosrun("palcas_tests", "lockstep_test", LockstepTest)
