#!/usr/bin/python3
"""rostest: one federation round through the node's services, checked with numpy.

Three expected RSUs (rsu_a, rsu_b, rsu_c), quorum 2, deadline 1 s. All three fetch
version 1 (so all are live); rsu_a and rsu_b submit with n_k = 100 and 300; rsu_c stays
silent, so the round closes on its deadline and version 2 must be
(100 a + 300 b) / 400, computed here in float64. Then malformed submissions are refused
with a reason and the global model stays version 2, bit for bit.
"""
import json
import os
import shutil
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from palcas_msgs.msg import FederationStatus, ModelWeights
from palcas_msgs.srv import FetchGlobalModel, SubmitWeights
from std_msgs.msg import UInt32


def status_fields(msg):
    """The FederationStatus message as a dict (rejections by reason)."""
    return {"round": msg.round, "version": msg.global_version, "submitted": list(msg.submitted),
            "rejected_by_reason": dict(zip(msg.rejection_reasons, msg.rejections)),
            "rounds_closed": msg.rounds_closed, "accepted_total": msg.accepted_total,
            "bytes_in_last_round": msg.bytes_in_last_round}


class FedServerRoundTest(unittest.TestCase):
    def setUp(self):
        self.timeout_s = rospy.get_param("~timeout_s", 20.0)
        self.checkpoint_dir = rospy.get_param("~checkpoint_dir")
        # The node writes only when a round closes, which needs our submissions.
        shutil.rmtree(self.checkpoint_dir, ignore_errors=True)
        self.lock = threading.Lock()
        self.version = None
        self.status = None
        rospy.Subscriber("global_model_version", UInt32, self.on_version)
        rospy.Subscriber("federation_status", FederationStatus, self.on_status)
        rospy.wait_for_service("submit_weights", timeout=self.timeout_s)
        rospy.wait_for_service("fetch_global_model", timeout=self.timeout_s)
        self.submit_srv = rospy.ServiceProxy("submit_weights", SubmitWeights)
        self.fetch_srv = rospy.ServiceProxy("fetch_global_model", FetchGlobalModel)

    def on_version(self, msg):
        with self.lock:
            self.version = msg.data

    def on_status(self, msg):
        with self.lock:
            self.status = status_fields(msg)

    def wait_for(self, predicate, what):
        deadline = time.time() + self.timeout_s
        while time.time() < deadline and not rospy.is_shutdown():
            with self.lock:
                if predicate():
                    return
            time.sleep(0.02)
        self.fail("timed out waiting for " + what)

    def fetch(self, rsu_id, min_version):
        return self.fetch_srv(rsu_id=rsu_id, min_version=min_version)

    def submit(self, rsu_id, rnd, base_version, values, n_k, layout_id, checksum):
        w = ModelWeights(rsu_id=rsu_id, round=rnd, model_version=base_version,
                         sample_count=n_k, layout_id=layout_id, layout_checksum=checksum,
                         values=[float(v) for v in values])
        return self.submit_srv(weights=w)

    def test_round_then_malformed_submissions(self):
        # (1) Version 1 for everyone; nothing newer yet.
        for rsu in ("rsu_a", "rsu_b", "rsu_c"):
            res = self.fetch(rsu, 1)
            self.assertTrue(res.available, res.reason)
        v1 = res.weights
        self.assertEqual(v1.model_version, 1)
        self.assertEqual(v1.round, 1)
        self.assertEqual(v1.rsu_id, "server")
        self.assertGreater(len(v1.values), 0)
        res = self.fetch("rsu_a", 2)
        self.assertFalse(res.available)
        self.assertIn("global version 1 < requested 2", res.reason)
        layout, checksum = v1.layout_id, v1.layout_checksum

        # (2) Two of three submit; the round closes on the deadline with quorum 2.
        theta = np.array(v1.values, dtype=np.float32)
        a = (theta + np.float32(0.5)).astype(np.float32)
        b = (theta * np.float32(-2.0) + np.float32(0.25)).astype(np.float32)
        r = self.submit("rsu_a", 1, 1, a, 100, layout, checksum)
        self.assertTrue(r.accepted, r.reason)
        r = self.submit("rsu_b", 1, 1, b, 300, layout, checksum)
        self.assertTrue(r.accepted, r.reason)
        self.assertEqual(r.global_version, 1)  # rsu_c is live: no close before the deadline
        self.wait_for(lambda: self.version == 2, "global_model_version 2")
        res = self.fetch("rsu_a", 2)
        self.assertTrue(res.available, res.reason)
        self.assertEqual(res.weights.model_version, 2)
        self.assertEqual(res.weights.round, 2)
        v2 = np.array(res.weights.values, dtype=np.float32)
        # theta2 = sum_k n_k / n theta_k = (100 a + 300 b) / 400
        expected = (100.0 * a.astype(np.float64) + 300.0 * b.astype(np.float64)) / 400.0
        np.testing.assert_allclose(v2, expected, rtol=1e-6, atol=1e-7)
        self.assertFalse(np.allclose(v2, theta))  # it really changed
        self.wait_for(lambda: self.status is not None and self.status["version"] == 2,
                      "federation_status of version 2")
        self.assertEqual(self.status["round"], 2)
        self.assertEqual(self.status["rounds_closed"], 1)
        self.assertEqual(self.status["bytes_in_last_round"], 2 * 4 * len(theta))
        with open(os.path.join(self.checkpoint_dir, "federation_state.json")) as f:
            state = json.load(f)
        self.assertEqual((state["round"], state["global_version"]), (2, 2))

        # (3) Malformed submissions in round 2: each refused with its reason.
        good = (v2 + np.float32(1.0)).astype(np.float32)
        nan = good.copy()
        nan[1] = np.nan
        cases = [
            ("wrong layout", ("rsu_a", 2, 2, good, 10, layout + "x", checksum), "layout_mismatch"),
            ("NaN", ("rsu_a", 2, 2, nan, 10, layout, checksum), "value 1 is not finite"),
            ("stale round", ("rsu_a", 1, 2, good, 10, layout, checksum), "wrong_round"),
            ("unknown RSU", ("rsu_z", 2, 2, good, 10, layout, checksum), "unknown_rsu"),
            ("n_k 0", ("rsu_a", 2, 2, good, 0, layout, checksum), "bad_sample_count"),
        ]
        for name, args, needle in cases:
            r = self.submit(*args)
            self.assertFalse(r.accepted, name)
            self.assertIn(needle, r.reason, name)
        r = self.submit("rsu_a", 2, 2, good, 10, layout, checksum)
        self.assertTrue(r.accepted, r.reason)  # one valid model: below quorum, round stays open
        r = self.submit("rsu_a", 2, 2, good, 10, layout, checksum)
        self.assertFalse(r.accepted)
        self.assertIn("duplicate", r.reason)
        res = self.fetch("rsu_b", 2)
        self.assertTrue(res.available, res.reason)
        self.assertEqual(res.weights.model_version, 2)
        np.testing.assert_array_equal(np.array(res.weights.values, dtype=np.float32), v2)
        self.wait_for(lambda: self.status["rejected_by_reason"]["duplicate"] == 1,
                      "the duplicate counted in federation_status")
        counts = self.status["rejected_by_reason"]
        for reason in ("layout_mismatch", "non_finite", "wrong_round", "unknown_rsu",
                       "bad_sample_count", "duplicate"):
            self.assertEqual(counts[reason], 1, reason)
        self.assertEqual(self.status["submitted"], ["rsu_a"])


if __name__ == "__main__":
    rospy.init_node("fedserver_round_test")
    rostest.rosrun("palcas_fedserver", "fedserver_round", FedServerRoundTest)
