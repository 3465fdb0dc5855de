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
        self.lazy_statuses = []
        rospy.Subscriber("monitor/wind_markers", MarkerArray, self.keep(self.markers), queue_size=10)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=50)
        self.est_pub = rospy.Publisher("wind/estimate", WindEstimate, queue_size=20)
        self.mean_pub = rospy.Publisher("wind/estimate_mean", WindEstimate, queue_size=20)
        self.wind_pub = rospy.Publisher("anemometer/wind", WindMeasurement, queue_size=20)
        self.clip_pub = rospy.Publisher("clips", Clip, queue_size=5)
        deadline = time.time() + 20
        while time.time() < deadline and (self.est_pub.get_num_connections() < 2 or
                                          self.mean_pub.get_num_connections() < 1 or
                                          self.wind_pub.get_num_connections() < 1):
            time.sleep(0.1)

    def keep(self, where):
        def add(msg):
            with self.lock:
                where.append(msg)
        return add

    def on_diagnostics(self, msg):
        with self.lock:
            self.statuses += [s for s in msg.status if s.name.startswith("wind_display")]
            self.lazy_statuses += [s for s in msg.status if s.name.startswith("lazy/")]

    def text(self):
        with self.lock:
            for m in reversed(self.markers):
                for marker in m.markers:
                    if marker.ns == "wind_text":
                        return marker.text, [a for a in m.markers if a.ns == "anemometer_wind"][0].action
        return None, None

    def wait_redraw(self):
        """Until two marker arrays newer than this call have come (the display drew after it)."""
        with self.lock:
            seen = len(self.markers)
        deadline = time.time() + 10.0
        while time.time() < deadline:
            with self.lock:
                if len(self.markers) >= seen + 2:
                    return
            time.sleep(0.05)
        self.fail("no redraw of the markers in 10 s")

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
        # The display's own frame hangs under it (a robot's tree keeps the anemometer's parent).
        self.assertEqual((t.header.frame_id, t.child_frame_id), ("anemometer", "monitor"))
        self.assertEqual(t.transform.rotation.w, 1.0)

    def test_lazy_display(self):
        """A display nobody subscribes to draws nothing (image_pipeline's lazy nodes), and draws
        at once for a subscriber."""
        pub = rospy.Publisher("lazy/anemometer/wind", WindMeasurement, queue_size=5)
        deadline = time.time() + 20
        while time.time() < deadline and pub.get_num_connections() < 1:
            time.sleep(0.1)
        for _ in range(6):
            wind = WindMeasurement()
            wind.header.stamp, wind.header.frame_id = rospy.Time.now(), "anemometer"
            wind.speed, wind.valid = 2.0, True
            pub.publish(wind)
            time.sleep(0.25)

        def lazy_values():
            with self.lock:
                s = self.lazy_statuses[-1] if self.lazy_statuses else None
            return {kv.key: kv.value for kv in s.values} if s else {}
        deadline = time.time() + 10
        while time.time() < deadline and lazy_values().get("anemometer age [s]", "inf") == "inf":
            time.sleep(0.2)
        self.assertEqual(lazy_values().get("displays drawn"), "0", lazy_values())
        got = []
        sub = rospy.Subscriber("lazy/monitor/wind_markers", MarkerArray, got.append, queue_size=5)
        deadline = time.time() + 10
        while time.time() < deadline and not any("anemometer 2.0" in m.text for a in got for m in a.markers):
            time.sleep(0.1)
        sub.unregister()
        self.assertTrue(any("anemometer 2.0" in m.text for a in got for m in a.markers), got)
        deadline = time.time() + 5
        while time.time() < deadline and lazy_values().get("displays drawn") == "0":
            time.sleep(0.2)
        self.assertNotEqual(lazy_values().get("displays drawn"), "0")
        def reading(frame, speed, vx):
            wind = WindMeasurement()
            wind.header.stamp, wind.header.frame_id = rospy.Time.now(), frame
            wind.speed, wind.valid, wind.velocity.x = speed, True, vx
            pub.publish(wind)

        def wait_lazy(key, value):
            deadline = time.time() + 10
            while time.time() < deadline and lazy_values().get(key) != value:
                time.sleep(0.2)
            self.assertEqual(lazy_values().get(key), value, lazy_values())

        # The readings above were calm (velocity 0, 0, 0: no bearing) in "anemometer": they name no
        # frame, so a bearing in the earth frame after them fixes the display's. The calm ones
        # fixed it before, and every later bearing was left out of the arrow.
        reading("earth", 2.0, 2.0)
        wait_lazy("frame", "earth")
        self.assertEqual(lazy_values().get("readings in another frame (no arrow)"), "0", lazy_values())
        # Once the display has its frame, a calm reading in another frame is left out like any
        # other reading there, not drawn as a zero arrow.
        reading("anemometer", 0.0, 0.0)
        wait_lazy("readings in another frame (no arrow)", "1")
        self.assertEqual(lazy_values().get("frame"), "earth", lazy_values())

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
        # sdn_node's trailing mean of the latest estimate (of the outputs before the clamp) is the
        # one shown: the mean of the clamped estimates read high in calm air.
        mean = WindEstimate()
        mean.header.stamp, mean.clip_sequence = e.header.stamp, e.clip_sequence
        # Over another window than the display's (3 s here): not taken, or its label would lie.
        mean.speed, mean.speed_std, mean.mean_window, mean.mean_count = 3.2, 0.2, 120.0, 4
        self.mean_pub.publish(mean)
        self.wait_redraw()
        text, _ = self.text()
        # (A mean spanning less than the window says so: "2 of 3 s mean 4.0".)
        self.assertRegex(text, r"s mean 4\.0")
        mean.speed, mean.mean_window, mean.mean_count = 3.7, 3.0, 2
        self.mean_pub.publish(mean)
        self.wait_redraw()
        text, _ = self.text()
        self.assertRegex(text, r"s mean 3\.7")

        # An estimate 6 s behind the readings (a clip's span and a backlogged model): no restart
        # of the display (it used to wipe the anemometer's history and show "no reading yet").
        lagging = WindEstimate()
        lagging.header.stamp = rospy.Time.now() - rospy.Duration(6.0)
        lagging.clip_sequence, lagging.speed, lagging.speed_std = 8, 4.0, 0.3
        lagging.reference_speed = 3.0
        self.est_pub.publish(lagging)
        self.wait_redraw()
        text, arrow = self.text()
        self.assertIn("anemometer 3.0 m/s", text)
        # ... nor shown as the latest: the newer estimate stays (the late one hid it, "--").
        self.assertIn("estimate 4.0", text)

        # One reading 10 s late while the clock runs on (a second publisher, a bad stamp): dropped
        # as late, no restart (it wiped the display). Then a reading marked invalid, one whose
        # velocity no anemometer reads and an estimate whose std is absurd: each dropped, counted.
        late = WindMeasurement()
        late.header.stamp, late.header.frame_id = rospy.Time.now() - rospy.Duration(10.0), "anemometer"
        late.speed, late.valid = 7.0, True
        self.wind_pub.publish(late)
        invalid = WindMeasurement()
        invalid.header.stamp, invalid.header.frame_id = rospy.Time.now(), "anemometer"
        invalid.speed, invalid.valid = 30.0, False  # a speed of its own: used, it would move the mean
        self.wind_pub.publish(invalid)
        wild = WindMeasurement()
        wild.header.stamp, wild.header.frame_id = rospy.Time.now(), "anemometer"
        wild.speed, wild.valid = 3.0, True
        wild.velocity.x = 1e30
        self.wind_pub.publish(wild)
        absurd = WindEstimate()
        absurd.header.stamp = rospy.Time.now()
        absurd.clip_sequence, absurd.speed, absurd.speed_std = 11, 4.0, 1e300
        absurd.reference_speed = float("nan")  # the report counts it and compares nothing
        self.est_pub.publish(absurd)
        self.wait_redraw()
        text, arrow = self.text()
        self.assertIn("anemometer 3.0 m/s", text)
        self.assertIn("estimate 4.0 \u00b1 0.3 m/s", text)

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
        self.assertEqual(values["messages more than 5 s behind the newest of their input dropped (clock steady)"], "1")
        self.assertEqual(values["readings marked invalid dropped"], "1")
        self.assertEqual(values["velocities beyond 100 m/s (no arrow)"], "1")
        self.assertEqual(values["speeds or stds outside 0..100 m/s dropped"], "1")
        # "Says so": a WARN, naming each cause.
        self.assertEqual(status.level, DiagnosticStatus.WARN, status.message)
        for cause in ("messages stamped 0 dropped", "messages more than 5 s late dropped",
                      "readings marked invalid dropped", "speeds or stds outside 0..100 m/s dropped"):
            self.assertIn(cause, status.message)
        # ... for ~drop_warn_for (8 s here) after the last drop, then no more: a total since start
        # kept one bad message a WARN for good. The counts stay.
        deadline = time.time() + 20.0
        while time.time() < deadline:
            with self.lock:
                status, values = self.latest_status()
            if "dropped" not in status.message:
                break
            time.sleep(0.2)
        self.assertNotIn("dropped", status.message)
        self.assertIn("no anemometer reading in the mean window", status.message)  # still WARN for that
        self.assertEqual(values["messages stamped 0 dropped"], "2")

        # The report ends after max_wall (30 s; wall time never idles) and writes its summary and
        # its plot.
        summary = rospy.get_param("~summary")
        plot = rospy.get_param("~estimate_plot")
        deadline = time.time() + 45
        while time.time() < deadline and not os.path.exists(summary):
            time.sleep(0.2)
        self.assertTrue(os.path.exists(summary), "no summary written")
        deadline = time.time() + 10
        while time.time() < deadline and not os.path.exists(plot):
            time.sleep(0.2)
        self.assertTrue(os.path.exists(plot), "no plot written")
        os.remove(plot)
        with open(summary) as f:
            j = json.load(f)
        # The one stamped 0 is compared (it has no time, not no label), 47 m/s off.
        self.assertEqual(j["total_clips"], 1)
        self.assertEqual(j["label_window"], 10.0)
        self.assertEqual(j["estimates"]["window"], 10.0)  # the clips' label window, not 60 s
        # Eight estimates: the one stamped TIME_MAX and the one of absurd std have no label, so six
        # are compared.
        self.assertEqual(j["estimates"]["count"], 8)
        self.assertEqual(j["estimates"]["compared"], 6)
        self.assertAlmostEqual(j["estimates"]["rmse"], ((5 * 1.0 + 47.0 ** 2) / 6) ** 0.5, places=6)


if __name__ == "__main__":
    rospy.init_node("monitor_nodes_check")
    rostest.rosrun("clothwind", "monitor_nodes", MonitorNodesTest, sys.argv)
