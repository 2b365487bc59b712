#!/usr/bin/python3
"""rostest: only the holders of the deployment's key speak for the RSUs.

The bridge (tiny road, lockstep with rsu_0) and the federation server run with a key file.
This node plays rsu_0 honestly (it holds the key: its arrays and submissions carry the HMAC
tag, computed here in Python over rospy's serialisation, so C++ and Python agree on the
bytes) and an attacker beside it: before every genuine array it publishes a forged one for
the same RSU and step, alternately unsigned and with a wrong tag, ordering every CAV to brake
hard. The bridge must refuse and count every forged array, take the genuine one, never count
rsu_0 late, and never apply a forged advisory. The server must refuse unsigned and wrongly
signed submissions with their reasons, keep the bound on a signed but poisoned one, accept
the genuine one, and sign the global model it serves.
"""
import hashlib
import hmac
import io
import os
import sys
import threading
import unittest

import rospy
import rostest
from palcas_msgs.msg import (Advisory, AdvisoryArray, AdvisoryRejection, EpisodeMetrics, FederationStatus,
                             VehicleStateArray)
from palcas_msgs.srv import FetchGlobalModel, RegisterRsu, SubmitWeights

# waiting.py beside this file (catkin's devel relay runs this file from elsewhere).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from waiting import WaitUntil, poll  # noqa: E402

WALL_TIMEOUT_S = 60.0
RSU = "rsu_0"


def read_key(path):
    with open(path) as f:
        return bytes.fromhex(f.read().strip())


def tag_of(msg, key):
    """HMAC-SHA256 over msg serialised with auth_tag empty and header.seq 0 (rospy sets seq
    when it publishes; palcas_common/message_auth.h)."""
    saved = msg.auth_tag
    msg.auth_tag = b""
    seq = msg.header.seq if hasattr(msg, "header") else None
    if seq is not None:
        msg.header.seq = 0
    buf = io.BytesIO()
    msg.serialize(buf)
    msg.auth_tag = saved
    if seq is not None:
        msg.header.seq = seq
    return hmac.new(key, buf.getvalue(), hashlib.sha256).digest()


def signed(msg, key):
    msg.auth_tag = tag_of(msg, key)
    return msg


class ForgedMessagesTest(WaitUntil, unittest.TestCase):
    WALL_TIMEOUT_S = WALL_TIMEOUT_S

    @classmethod
    def setUpClass(cls):
        cls.key = read_key(rospy.get_param("~auth_key_file"))
        cls.lock = threading.Lock()
        cls.steps = 0
        cls.forged_sent = 0
        cls.genuine_advisories = 0
        cls.rejections = []
        cls.metrics = None
        cls.fed_status = None
        cls.pub = rospy.Publisher("/advisories", AdvisoryArray, queue_size=100)
        rospy.Subscriber("/advisory_rejections", AdvisoryRejection, cls.on_rejection, queue_size=1000)
        rospy.Subscriber("/episode_metrics", EpisodeMetrics, cls.on_metrics, queue_size=10)
        rospy.Subscriber("/fedserver/federation_status", FederationStatus, cls.on_fed_status, queue_size=10)
        rospy.Subscriber("/vehicle_states", VehicleStateArray, cls.on_states, queue_size=100,
                         tcp_nodelay=True)
        rospy.wait_for_service("/register_rsu", timeout=WALL_TIMEOUT_S)
        # The bridge must hear this node from step 0 on: registering before the link to its
        # subscriber is up would leave step 0 unanswered.
        poll(lambda: cls.pub.get_num_connections() >= 1, WALL_TIMEOUT_S, interval_s=0.01)
        reply = rospy.ServiceProxy("/register_rsu", RegisterRsu)(rsu_id=RSU)
        assert reply.accepted, reply.reason

    @classmethod
    def on_states(cls, msg):
        cavs = [v.id for v in msg.vehicles if v.is_cav]
        with cls.lock:
            n = cls.steps
            cls.steps += 1
        # The attacker first: the same RSU and step, every CAV told to brake at -4.5 m/s^2.
        forged = AdvisoryArray(step=msg.step, rsu_id=RSU,
                               advisories=[Advisory(vehicle_id=c, action=Advisory.ACCELERATE,
                                                    accel_mps2=-4.5) for c in cavs])
        forged.auth_tag = b"" if n % 2 == 0 else os.urandom(32)
        # Then rsu_0 itself: KEEP for every CAV, signed.
        genuine = signed(AdvisoryArray(step=msg.step, rsu_id=RSU,
                                       advisories=[Advisory(vehicle_id=c, action=Advisory.KEEP)
                                                   for c in cavs]), cls.key)
        # Counted before they go out: the bridge may apply them and publish metrics before
        # this thread runs again (a loaded machine counted 3371 applied of 3357 counted sent).
        with cls.lock:
            cls.forged_sent += 1
            cls.genuine_advisories += len(cavs)
        cls.pub.publish(forged)
        cls.pub.publish(genuine)

    @classmethod
    def on_rejection(cls, msg):
        with cls.lock:
            cls.rejections.append(msg)

    @classmethod
    def on_metrics(cls, msg):
        with cls.lock:
            cls.metrics = msg

    @classmethod
    def on_fed_status(cls, msg):
        with cls.lock:
            cls.fed_status = {"accepted_total": msg.accepted_total,
                              "rejected_by_reason": dict(zip(msg.rejection_reasons, msg.rejections))}

    def test_forged_arrays_are_refused_counted_and_never_displace_the_genuine_one(self):
        # Enough steps with CAVs on the road that forged braking would show.
        self.wait_until(lambda: self.steps >= 300 and self.genuine_advisories >= 100,
                        "300 steps with 100 advisories")
        with self.lock:
            forged_sent = self.forged_sent
        # Every forged array published so far is refused, each as one UNAUTHENTICATED rejection.
        self.wait_until(lambda: sum(r.reason == AdvisoryRejection.UNAUTHENTICATED
                                    for r in self.rejections) >= forged_sent,
                        "a rejection per forged array")
        # ... and the applied count catches up with the genuine advisories sent.
        with self.lock:
            genuine_then = self.genuine_advisories
        metrics = self.wait_until(lambda: self.metrics if self.metrics is not None and
                                  self.metrics.advisories_applied >= genuine_then else None,
                                  "metrics covering the genuine advisories")
        with self.lock:
            rejections = list(self.rejections)
            genuine_now = self.genuine_advisories
        unauthenticated = [r for r in rejections if r.reason == AdvisoryRejection.UNAUTHENTICATED]
        others = [r for r in rejections if r.reason != AdvisoryRejection.UNAUTHENTICATED]
        # Nothing of the genuine arrays was refused (no duplicate, no stale: not displaced).
        self.assertEqual(others, [], "genuine advisories refused: %s" % others[:3])
        self.assertEqual(metrics.late_rsu_steps, 0, "rsu_0 counted late: its genuine array was not taken")
        # No forged advisory applied: only the genuine KEEPs (sent at most genuine_now).
        self.assertLessEqual(metrics.advisories_applied, genuine_now)
        # The rejection says which check failed and who published it.
        details = {r.detail.split(":")[0] for r in unauthenticated}
        self.assertEqual(details, {"missing_tag", "forged_tag"})
        self.assertTrue(all(r.rsu_id == RSU and r.vehicle_id == "" for r in unauthenticated))
        self.assertIn(rospy.get_name(), unauthenticated[0].detail)

    def test_submissions_need_the_key_and_the_served_model_carries_it(self):
        rospy.wait_for_service("/fedserver/fetch_global_model", timeout=WALL_TIMEOUT_S)
        fetch = rospy.ServiceProxy("/fedserver/fetch_global_model", FetchGlobalModel)
        submit = rospy.ServiceProxy("/fedserver/submit_weights", SubmitWeights)
        reply = fetch(RSU, 0)
        self.assertTrue(reply.available, reply.reason)
        served = reply.weights
        # The server signs what it serves: an RSU can tell its global model from a forged one.
        self.assertEqual(len(served.auth_tag), 32)
        self.assertEqual(bytes(served.auth_tag), tag_of(served, self.key))

        def model(values, key=None, tag=b""):
            w = type(served)(rsu_id=RSU, round=served.round, model_version=served.model_version,
                             sample_count=10, layout_id=served.layout_id,
                             layout_checksum=served.layout_checksum, values=values)
            w.auth_tag = tag_of(w, key) if key else tag
            return w

        honest = list(served.values)
        r = submit(model(honest))
        self.assertFalse(r.accepted)
        self.assertTrue(r.reason.startswith("unauthenticated: missing_tag"), r.reason)
        r = submit(model(honest, key=b"not the deployment's key, 32 by"))
        self.assertFalse(r.accepted)
        self.assertTrue(r.reason.startswith("unauthenticated: forged_tag"), r.reason)
        # A tag copied from a genuine model onto poisoned values does not verify either.
        poisoned = model([1e30] * len(honest))
        poisoned.auth_tag = model(honest, key=self.key).auth_tag
        r = submit(poisoned)
        self.assertTrue(r.reason.startswith("unauthenticated: forged_tag"), r.reason)
        # Signed with the key but poisoned: the norm bound still holds.
        r = submit(model([1e30] * len(honest), key=self.key))
        self.assertFalse(r.accepted)
        self.assertTrue(r.reason.startswith("update_too_large"), r.reason)
        r = submit(model(honest, key=self.key))
        self.assertTrue(r.accepted, r.reason)
        status = self.wait_until(
            lambda: self.fed_status if self.fed_status and self.fed_status["accepted_total"] >= 1 else None,
            "the federation status after the genuine submission")
        self.assertEqual(status["rejected_by_reason"]["unauthenticated"], 3)
        self.assertEqual(status["rejected_by_reason"]["update_too_large"], 1)


if __name__ == "__main__":
    rospy.init_node("forged_messages_test")
    rostest.rosrun("palcas_tests", "forged_messages", ForgedMessagesTest)
