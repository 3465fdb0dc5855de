#!/usr/bin/env python3
"""rostest for wind_display_node and clip_report_node (see monitor_nodes.test)."""
import json
import os
import struct
import sys
import threading
import time
import unittest

import rospy
import rostest
from clothwind.msg import Clip, WindEstimate, WindMeasurement
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import TransformStamped
from visualization_msgs.msg import MarkerArray

SENT = []  # wall time of each message sent to the nodes under test


def first_transform(msg):
    """The first TransformStamped of a tf2_msgs/TFMessage taken as rospy.AnyMsg (Debian packages
    tf2_msgs for C++ only): a uint32 count, then the transforms."""
    (count,) = struct.unpack("<I", msg._buff[:4])
    return TransformStamped().deserialize(msg._buff[4:]) if count else None


class MonitorNodesTest(unittest.TestCase):
    def setUp(self):
        self.lock = threading.RLock()
        self.markers = []
        self.statuses = []
        rospy.Subscriber("monitor/wind_markers", MarkerArray, self.keep(self.markers), queue_size=10)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=50)
        self.est_pub = rospy.Publisher("wind/estimate", WindEstimate, queue_size=20)
        self.wind_pub = rospy.Publisher("anemometer/wind", WindMeasurement, queue_size=20)
        self.clip_pub = rospy.Publisher("clips", Clip, queue_size=5)
        deadline = time.time() + 20
        while time.time() < deadline and (self.est_pub.get_num_connections() < 2 or
                                          self.wind_pub.get_num_connections() < 1):
            time.sleep(0.1)

    def keep(self, where):
        def add(msg):
            with self.lock:
                where.append(msg)
        return add

    def on_diagnostics(self, msg):
        with self.lock:
            self.statuses += [s for s in msg.status if s.name.endswith("wind display")]

    def text(self):
        with self.lock:
            for m in reversed(self.markers):
                for marker in m.markers:
                    if marker.ns == "wind_text":
                        return marker.text, [a for a in m.markers if a.ns == "anemometer_wind"][0].action
        return None, None

    def latest_status(self):
        with self.lock:
            s = self.statuses[-1]
        return s, {kv.key: kv.value for kv in s.values}

    # Sorted first (unittest runs tests by name): nothing has been sent to the display yet. rviz
    # showed "Fixed Frame [monitor] does not exist" until data came, as the display published
    # /tf_static only when it first drew.
    def test_a_fixed_frame_before_any_data(self):
        received = []
        sub = rospy.Subscriber("/tf_static", rospy.AnyMsg, lambda m: received.append((time.time(), m)))
        deadline = time.time() + 10.0
        while time.time() < deadline and not received:
            time.sleep(0.1)
        sub.unregister()
        self.assertTrue(received, "no /tf_static from wind_display before any input")
        self.assertEqual(SENT, [])
        self.assertEqual(received[0][1]._connection_header["type"], "tf2_msgs/TFMessage")
        t = first_transform(received[0][1])
        # The frame the display would draw in: "anemometer" until a reading names its own.
        self.assertEqual((t.header.frame_id, t.child_frame_id), ("monitor", "anemometer"))
        self.assertEqual(t.transform.rotation.w, 1.0)

    def test_display_and_report(self):
        for i in range(8):  # 4 s: estimates at 1 Hz, readings at 2 Hz
            now = rospy.Time.now()
            wind = WindMeasurement()
            wind.header.stamp = now
            wind.header.frame_id = "anemometer"
            wind.speed, wind.direction, wind.valid = 3.0, 0.0, True
            wind.velocity.x = 3.0
            SENT.append(time.time())
            self.wind_pub.publish(wind)
            if i % 2 == 0:
                e = WindEstimate()
                e.header.stamp = now
                e.clip_sequence = i // 2
                e.clip_start = now - rospy.Duration(1.16)
                e.clip_end = now
                e.speed, e.speed_std, e.reference_speed = 4.0, 0.3, 3.0
                self.est_pub.publish(e)
            time.sleep(0.5)
        zero = WindEstimate()  # stamped 0: dropped by the display; the report still compares it
        zero.clip_sequence, zero.speed, zero.reference_speed = 9, 50.0, 3.0
        self.est_pub.publish(zero)
        zero_wind = WindMeasurement()
        zero_wind.speed, zero_wind.valid = 3.0, True
        self.wind_pub.publish(zero_wind)
        # Stamped TIME_MAX (a "no time" value some drivers use): dropped by the display, which it
        # used to kill (every later age was a Duration out of 32-bit range); and a clip whose last
        # frame is stamped so, which killed the report before it wrote anything.
        far = rospy.Time(4294967295, 999999999)
        far_wind = WindMeasurement()
        far_wind.header.stamp, far_wind.header.frame_id = far, "anemometer"
        far_wind.speed, far_wind.valid = 9.0, True
        self.wind_pub.publish(far_wind)
        far_estimate = WindEstimate()
        far_estimate.header.stamp, far_estimate.clip_sequence = far, 10
        far_estimate.speed, far_estimate.reference_speed = 9.0, float("nan")
        self.est_pub.publish(far_estimate)
        clip = Clip()
        clip.header.stamp = rospy.Time.now()
        clip.sequence, clip.num_frames, clip.frame_rate, clip.label_window = 1, 2, 25.0, 10.0
        clip.frame_stamps = [rospy.Time.now(), far]
        self.clip_pub.publish(clip)
        time.sleep(0.3)
        text, arrow = self.text()
        self.assertIsNotNone(text, "no markers")
        self.assertIn("estimate 4.0 \u00b1 0.3 m/s", text)
        self.assertIn("anemometer 3.0 m/s", text)
        self.assertEqual(arrow, 0)  # ADD

        # An estimate 6 s behind the readings (a clip's span and a backlogged model): no restart
        # of the display (it used to wipe the anemometer's history and show "no reading yet").
        lagging = WindEstimate()
        lagging.header.stamp = rospy.Time.now() - rospy.Duration(6.0)
        lagging.clip_sequence, lagging.speed, lagging.speed_std = 8, 4.0, 0.3
        lagging.reference_speed = 3.0
        self.est_pub.publish(lagging)
        time.sleep(0.3)
        text, arrow = self.text()
        self.assertIn("anemometer 3.0 m/s", text)

        # Past stale_after (4 s) and mean_window (3 s): polled, since markers come at 5 Hz and
        # diagnostics once a second on a machine that may be busy.
        deadline = time.time() + 15.0
        while time.time() < deadline:
            text, arrow = self.text()
            with self.lock:
                status, values = self.latest_status() if self.statuses else (None, {})
            if ("anemometer --" in text and arrow == 2 and status is not None and
                    "no anemometer reading in the mean window" in status.message):
                break
            time.sleep(0.2)
        self.assertIn("estimate --", text)
        self.assertIn("anemometer --", text)
        self.assertEqual(arrow, 2)  # DELETE
        self.assertIn("estimate stale", status.message)
        self.assertIn("no anemometer reading in the mean window", status.message)
        self.assertEqual(values["messages stamped 0 dropped"], "2")
        self.assertEqual(values["messages stamped more than ~max_future ahead dropped"], "2")
        self.assertEqual(values["restarts (clock or inputs went back)"], "0")
        # "Says so": a WARN, naming each cause.
        self.assertEqual(status.level, DiagnosticStatus.WARN, status.message)
        self.assertIn("messages stamped 0 dropped", status.message)

        # The report ends after max_wall (30 s; wall time never idles) and writes its summary
        # although the plot's path lies under a file.
        summary = rospy.get_param("~summary")
        deadline = time.time() + 45
        while time.time() < deadline and not os.path.exists(summary):
            time.sleep(0.2)
        self.assertTrue(os.path.exists(summary), "no summary written")
        with open(summary) as f:
            j = json.load(f)
        # The one stamped 0 is compared (it has no time, not no label), 47 m/s off.
        self.assertEqual(j["total_clips"], 1)
        self.assertEqual(j["label_window"], 10.0)
        self.assertEqual(j["estimates"]["window"], 10.0)  # the clips' label window, not 60 s
        # Seven estimates: the one stamped TIME_MAX has no label, so six are compared.
        self.assertEqual(j["estimates"]["count"], 7)
        self.assertEqual(j["estimates"]["compared"], 6)
        self.assertAlmostEqual(j["estimates"]["rmse"], ((5 * 1.0 + 47.0 ** 2) / 6) ** 0.5, places=6)


if __name__ == "__main__":
    rospy.init_node("monitor_nodes_check")
    rostest.rosrun("clothwind", "monitor_nodes", MonitorNodesTest, sys.argv)
