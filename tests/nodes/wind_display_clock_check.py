#!/usr/bin/env python3
"""rostest for wind_display_node when the clock goes back (see tests/wind_display_clock.test).

The test plays /clock itself: 4 s of estimates at 6 m/s and readings at 6 m/s from ROS time 2000,
then the clock jumps back 20 s. With no input yet, the display must clear itself ("--" for both:
it is latched, and the previous pass's values stayed on screen until new input came); an estimate
of the previous pass arriving late is counted as such, not as stamped in the future; then only
readings at 1 m/s come: within 3 s the display must show no estimate and the new readings, and
diagnostics must count a restart.
"""
import sys
import threading
import time
import unittest

import rospy
import rostest
from clothwind.msg import WindEstimate, WindMeasurement
from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Clock
from visualization_msgs.msg import MarkerArray


class WindDisplayClockTest(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.text, self.restarts, self.values = None, None, {}
        self.clock_now = 2000.0
        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self.est_pub = rospy.Publisher("wind/estimate", WindEstimate, queue_size=20)
        self.wind_pub = rospy.Publisher("anemometer/wind", WindMeasurement, queue_size=20)
        rospy.Subscriber("monitor/wind_markers", MarkerArray, self.on_markers, queue_size=10)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=50)
        self.running = True
        self.ticker = threading.Thread(target=self.tick)
        self.ticker.start()
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and (self.est_pub.get_num_connections() < 1 or
                                               self.wind_pub.get_num_connections() < 1):
            time.sleep(0.1)

    def tearDown(self):
        self.running = False
        self.ticker.join()

    def tick(self):  # /clock at real speed from self.clock_now
        while self.running:
            with self.lock:
                self.clock_now += 0.02
                now = self.clock_now
            self.clock_pub.publish(Clock(clock=rospy.Time.from_sec(now)))
            time.sleep(0.02)

    def on_markers(self, msg):
        for m in msg.markers:
            if m.ns == "wind_text":
                with self.lock:
                    self.text = m.text

    def on_diagnostics(self, msg):
        for s in msg.status:
            if s.name.endswith("wind display"):
                values = {kv.key: kv.value for kv in s.values}
                with self.lock:
                    self.restarts = values.get("restarts (clock or inputs went back)")
                    self.values = values

    def publish(self, estimate_speed, wind_speed, stamp=None):
        with self.lock:
            stamp = stamp or rospy.Time.from_sec(self.clock_now)
        if estimate_speed is not None:
            e = WindEstimate()
            e.header.stamp = stamp
            e.speed, e.speed_std = estimate_speed, 0.3
            self.est_pub.publish(e)
        w = WindMeasurement()
        w.header.stamp, w.header.frame_id = stamp, "anemometer"
        w.speed, w.valid = wind_speed, True
        w.velocity.x = wind_speed
        self.wind_pub.publish(w)

    def wait_for(self, predicate, seconds):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            with self.lock:
                if predicate():
                    return True
            time.sleep(0.1)
        return False

    def test_a_clock_going_back_clears_the_previous_pass(self):
        for _ in range(8):
            self.publish(6.0, 6.0)
            time.sleep(0.5)
        self.assertTrue(self.wait_for(lambda: self.text and "estimate 6.0" in self.text, 5), self.text)
        with self.lock:
            old_pass = rospy.Time.from_sec(self.clock_now - 0.5)
            self.clock_now -= 20.0  # the bag plays again
        # sdn_node's last estimate of the previous pass, published right after the jump (before
        # or after the display's next tick notices it: counted as the previous pass's either way).
        time.sleep(0.05)
        e = WindEstimate()
        e.header.stamp = old_pass
        e.speed, e.speed_std = 6.0, 0.3
        self.est_pub.publish(e)
        # Nothing of the new pass yet: the display clears itself.
        self.assertTrue(self.wait_for(lambda: self.text and "estimate --" in self.text and
                                      "anemometer --" in self.text, 3), self.text)
        key = "messages of the previous pass dropped (after the clock went back)"
        self.assertTrue(self.wait_for(lambda: self.values.get(key) == "1", 3), self.values)
        with self.lock:
            values = self.values
        self.assertEqual(values["messages stamped more than ~max_future ahead dropped"], "0")
        self.assertIn("estimate --", self.text)
        start = time.monotonic()
        while time.monotonic() - start < 3.0:
            self.publish(None, 1.0)
            time.sleep(0.5)
        with self.lock:
            text, restarts = self.text, self.restarts
        self.assertIn("estimate --", text)
        self.assertIn("anemometer 1.0", text)
        self.assertTrue(self.wait_for(lambda: self.restarts not in (None, "0"), 3), self.restarts)
        time.sleep(1.5)
        with self.lock:
            self.assertEqual(self.restarts, "1")  # once per jump, not once per message and tick


if __name__ == "__main__":
    rospy.init_node("wind_display_clock_check")
    rostest.rosrun("clothwind", "wind_display_clock", WindDisplayClockTest, sys.argv)
