#!/usr/bin/python3
"""rostest: a test RSU's advisories are executed in SUMO, and bad ones are rejected.

The node registers with the bridge as ~rsu_id and answers every step (lockstep). Each test
sets a plan (a function of the state) that decides the advisories of the next steps.
"""
import math
import os
import sys
import threading
import unittest

import rospy
import rostest
from palcas_msgs.msg import Advisory, AdvisoryArray, AdvisoryRejection, EpisodeMetrics, VehicleStateArray
from palcas_msgs.srv import RegisterRsu

# waiting.py beside this file (catkin's devel relay runs this file from elsewhere).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from waiting import WaitUntil  # noqa: E402

WALL_TIMEOUT_S = 60.0


class AdvisoryTest(WaitUntil, unittest.TestCase):
    WALL_TIMEOUT_S = WALL_TIMEOUT_S

    @classmethod
    def setUpClass(cls):
        cls.rsu_id = rospy.get_param("~rsu_id", "test_rsu")
        cls.lock = threading.Lock()
        cls.plan = None          # function(state) -> list of AdvisoryArray to publish
        cls.history = []         # states seen, in order
        cls.rejections = []
        cls.metrics = None
        cls.pub = rospy.Publisher("/advisories", AdvisoryArray, queue_size=100)
        rospy.Subscriber("/advisory_rejections", AdvisoryRejection, cls.on_rejection, queue_size=100)
        rospy.Subscriber("/episode_metrics", EpisodeMetrics, cls.on_metrics, queue_size=10)
        rospy.Subscriber("/vehicle_states", VehicleStateArray, cls.on_states, queue_size=100,
                         tcp_nodelay=True)
        rospy.wait_for_service("/register_rsu", timeout=WALL_TIMEOUT_S)
        reply = rospy.ServiceProxy("/register_rsu", RegisterRsu)(rsu_id=cls.rsu_id)
        assert reply.accepted, reply.reason

    @classmethod
    def on_states(cls, msg):
        with cls.lock:
            cls.history.append(msg)
            plan = cls.plan
        arrays = plan(msg) if plan else []
        if not any(a.step == msg.step for a in arrays):
            arrays.append(cls.answer(msg.step, []))  # lockstep: always answer
        for a in arrays:
            cls.pub.publish(a)

    @classmethod
    def on_rejection(cls, msg):
        with cls.lock:
            cls.rejections.append(msg)

    @classmethod
    def on_metrics(cls, msg):
        with cls.lock:
            cls.metrics = msg

    @classmethod
    def answer(cls, step, advisories):
        a = AdvisoryArray()
        a.header.stamp = rospy.Time.now()
        a.step = step
        a.rsu_id = cls.rsu_id
        a.advisories = advisories
        return a

    @staticmethod
    def advisory(vehicle_id, action, accel=0.0):
        return Advisory(vehicle_id=vehicle_id, action=action, accel_mps2=accel, model_version=0)

    def latest(self):
        return self.history[-1] if self.history else None

    def vehicle_in(self, state, vid):
        return next((v for v in state.vehicles if v.id == vid), None)

    def test_lane_change_left_is_executed(self):
        # CAVs on lane 1 of the mainline, away from the road's ends and off the merge edge.
        def room_on_lane_2(state, v):
            # SUMO refuses a change that would collide at once: only test CAVs with room.
            return all(abs(o.x_m - v.x_m) > 25.0 for o in state.vehicles if o.lane == 2)

        def eligible():
            s = self.latest()
            if s is None:
                return None
            ids = [v.id for v in s.vehicles
                   if v.is_cav and v.lane == 1 and v.edge.startswith("main_") and "merge" not in v.edge
                   and (160.0 < v.x_m < 230.0 or 250.0 < v.x_m < 355.0 or 460.0 < v.x_m < 530.0)
                   and v.speed_mps > 3.0 and room_on_lane_2(s, v)]
            return (s.step, ids) if ids else None
        step, targets = self.wait_until(eligible, "a moving CAV on lane 1 with room on lane 2")
        sent = {"done": False}

        def plan(state):
            if sent["done"]:
                return []
            sent["done"] = True
            return [self.answer(state.step, [self.advisory(t, Advisory.LANE_LEFT) for t in targets
                                             if self.vehicle_in(state, t)])]
        with self.lock:
            type(self).plan = plan
            rejections_before = len(self.rejections)
        start_len = len(self.history)
        # 2 s for the change plus a little: 30 steps.
        self.wait_until(lambda: len(self.history) >= start_len + 30, "30 more steps")
        with self.lock:
            type(self).plan = None
            states = self.history[start_len:]
            rejected = [r.vehicle_id for r in self.rejections[rejections_before:]]
        changed = [t for t in targets
                   if any(self.vehicle_in(s, t) and self.vehicle_in(s, t).lane == 2 for s in states)]
        still_there = [t for t in targets if self.vehicle_in(states[-1], t)]
        for t in targets:
            trace = [(s.step, self.vehicle_in(s, t).edge, self.vehicle_in(s, t).lane,
                      round(self.vehicle_in(s, t).lateral_m, 2)) for s in states if self.vehicle_in(s, t)]
            rospy.loginfo("lane-change target %s: %s", t, trace)
        self.assertFalse([t for t in targets if t in rejected], "lane-change advisories were rejected")
        self.assertGreaterEqual(len(changed), max(1, (len(still_there) + 1) // 2),
                                "advised CAVs %s did not reach lane 2 (changed: %s)" % (targets, changed))

    def test_acceleration_is_executed(self):
        def eligible():
            s = self.latest()
            if s is None:
                return None
            for v in s.vehicles:
                if v.is_cav and v.lane >= 1 and v.speed_mps > 12.0 and 20.0 < v.x_m < 150.0:
                    return v.id
            return None
        target = self.wait_until(eligible, "a fast CAV")
        accel = -2.0

        def plan(state):
            if self.vehicle_in(state, target):
                return [self.answer(state.step, [self.advisory(target, Advisory.ACCELERATE, accel)])]
            return []
        with self.lock:
            type(self).plan = plan
        start_len = len(self.history)
        self.wait_until(lambda: len(self.history) >= start_len + 12, "12 more steps")
        with self.lock:
            type(self).plan = None
            states = self.history[start_len:start_len + 12]
        speeds = [self.vehicle_in(s, target).speed_mps for s in states if self.vehicle_in(s, target)]
        self.assertGreaterEqual(len(speeds), 12, "the CAV left the road during the test")
        # From the first applied step, 10 steps (1.0 s) at the commanded acceleration, clipped
        # to the comfort band (config/bridge.yaml max_advised_accel_mps2 1.47): about -1.47 m/s.
        executed = max(accel, -1.47)
        drop = speeds[11] - speeds[1]
        self.assertAlmostEqual(drop, executed * 1.0, delta=0.3,
                               msg="speed went %s; expected about %.2f m/s over 1 s" % (speeds, executed))

    def test_bad_advisories_are_rejected_and_counted(self):
        def eligible():
            s = self.latest()
            if s is None:
                return None
            cavs = [v for v in s.vehicles if v.is_cav and v.lane >= 1]
            lane1 = [v for v in cavs if v.lane == 1 and not v.on_accel_lane]
            hdvs = [v for v in s.vehicles if not v.is_cav]
            if len(cavs) >= 6 and lane1 and hdvs:
                return s, cavs, lane1[0], hdvs[0]
            return None
        _, cavs, lane1_cav, hdv = self.wait_until(eligible, "six CAVs, one on lane 1, and a human driver")
        others = [c for c in cavs if c.id != lane1_cav.id]
        expected = {
            ("no_such_vehicle", AdvisoryRejection.UNKNOWN_VEHICLE),
            (hdv.id, AdvisoryRejection.NOT_A_CAV),
            (others[0].id, AdvisoryRejection.NOT_FINITE),
            (others[1].id, AdvisoryRejection.ACCEL_OUT_OF_RANGE),
            (lane1_cav.id, AdvisoryRejection.NO_SUCH_LANE),
            (others[2].id, AdvisoryRejection.UNKNOWN_ACTION),
            (others[3].id, AdvisoryRejection.DUPLICATE),
            (others[4].id, AdvisoryRejection.STALE_STEP),
        }
        sent = {"done": False}

        def plan(state):
            if sent["done"]:
                return []
            sent["done"] = True
            bad = [
                self.advisory("no_such_vehicle", Advisory.KEEP),
                self.advisory(hdv.id, Advisory.KEEP),
                self.advisory(others[0].id, Advisory.ACCELERATE, float("nan")),
                self.advisory(others[1].id, Advisory.ACCELERATE, 3.1),
                self.advisory(lane1_cav.id, Advisory.LANE_RIGHT),
                self.advisory(others[2].id, 7),
                self.advisory(others[3].id, Advisory.KEEP),
                self.advisory(others[3].id, Advisory.KEEP),
            ]
            stale = self.answer(state.step - 1, [self.advisory(others[4].id, Advisory.KEEP)])
            return [stale, self.answer(state.step, bad)]
        with self.lock:
            before = len(self.rejections)
            type(self).plan = plan

        def all_seen():
            got = {(r.vehicle_id, r.reason) for r in self.rejections[before:]}
            return got if expected <= got else None
        got = self.wait_until(all_seen, "eight rejections")
        with self.lock:
            type(self).plan = None
            details = [r.detail for r in self.rejections[before:]]
        self.assertTrue(all(details), "every rejection names its reason")
        self.assertTrue(any("3.1" in d for d in details), details)
        # Exactly one rejection each: the duplicate's first KEEP was applied.
        self.assertEqual(len([g for g in got if g[0] == others[3].id]), 1)
        # The episode metrics count them (metrics_period_s is short in this test).
        self.wait_until(lambda: self.metrics is not None and self.metrics.advisories_rejected >= 8,
                        "EpisodeMetrics.advisories_rejected >= 8")


if __name__ == "__main__":
    rospy.init_node("advisory_test")
    rostest.rosrun("palcas_tests", "advisory_test", AdvisoryTest)
