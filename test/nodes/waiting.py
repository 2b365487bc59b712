"""The rostests' one way to wait: poll a condition, under the test's lock, until it holds or a
wall-clock timeout passes. Wall clock on purpose: simulated time only moves while the bridge
runs, so a wait on it would never end when the bridge stops. Never fixed sleeps."""
import time

import rospy


def poll(condition, timeout_s, lock=None, interval_s=0.02):
    """condition()'s first truthy result (called under `lock` when one is given), or None when
    timeout_s seconds of wall-clock time passed or ROS shut down first."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end and not rospy.is_shutdown():
        if lock is None:
            result = condition()
        else:
            with lock:
                result = condition()
        if result:
            return result
        time.sleep(interval_s)
    return None


class WaitUntil:
    """Mixin for a unittest.TestCase holding `lock`: wait_until fails the test naming what it
    waited for. WALL_TIMEOUT_S and POLL_S are the test's own."""
    WALL_TIMEOUT_S = 60.0
    POLL_S = 0.01

    def wait_until(self, condition, what, timeout_s=None):
        result = poll(condition, self.WALL_TIMEOUT_S if timeout_s is None else timeout_s, self.lock,
                      self.POLL_S)
        if not result:
            self.fail("timed out waiting for " + what)
        return result
