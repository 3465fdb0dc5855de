#!/usr/bin/env python3
"""rostest for clip_buffer_node's handling of bad time and bad storage (see clip_buffer_faults.test)."""
import sys
import threading
import unittest

import rospy
import rostest
from clothwind.msg import Clip, WindMeasurement
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sensor_msgs.msg import Image

WIDTH, HEIGHT = 64, 48


def image(stamp, value, encoding="mono8"):
    msg = Image()
    msg.header.stamp = stamp
    msg.header.frame_id = "camera_optical"
    msg.height, msg.width, msg.encoding, msg.step = HEIGHT, WIDTH, encoding, WIDTH
    msg.data = bytes([value % 256]) * (WIDTH * HEIGHT)
    return msg


def reading(stamp, speed):
    msg = WindMeasurement()
    msg.header.stamp = stamp
    msg.header.frame_id = "anemometer"
    msg.speed = speed
    msg.direction = 0.0
    msg.valid = True
    return msg


class ClipBufferFaultsTest(unittest.TestCase):
    def setUp(self):
        self.lock = threading.RLock()
        self.clips = []
        self.statuses = []
        rospy.Subscriber("clips", Clip, self.on_clip, queue_size=200)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=100)
        self.image_pub = rospy.Publisher("camera/image_raw", Image, queue_size=200)
        self.wind_pub = rospy.Publisher("anemometer/wind", WindMeasurement, queue_size=100)
        deadline = rospy.get_time() + 20
        while (self.image_pub.get_num_connections() == 0 or self.wind_pub.get_num_connections() == 0) \
                and rospy.get_time() < deadline:
            rospy.sleep(0.1)
        self.frame = 0

    def on_clip(self, msg):
        with self.lock:
            self.clips.append(msg)

    def on_diagnostics(self, msg):
        with self.lock:
            self.statuses += [s for s in msg.status if "clip buffer" in s.name]

    def latest(self):
        with self.lock:
            s = self.statuses[-1]
        return s, {kv.key: kv.value for kv in s.values}

    def wait_status(self, predicate, timeout, what):
        deadline = rospy.get_time() + timeout
        while rospy.get_time() < deadline:
            with self.lock:
                if self.statuses and predicate(*self.latest()):
                    return self.latest()
            rospy.sleep(0.1)
        self.fail("timed out waiting for %s; last status: %s" % (what, self.latest() if self.statuses else None))

    def stream(self, seconds, offset=0.0, speed=4.0, extra=None):
        """Frames at 30 fps and readings at 2 Hz for `seconds`, stamped now + offset."""
        rate = rospy.Rate(30)
        end = rospy.get_time() + seconds
        while rospy.get_time() < end and not rospy.is_shutdown():
            stamp = rospy.Time.now() + rospy.Duration.from_sec(offset)
            self.image_pub.publish(image(stamp, self.frame))
            if self.frame % 15 == 0:
                self.wind_pub.publish(reading(stamp, speed))
            if extra:
                extra(self.frame, stamp)
            self.frame += 1
            rate.sleep()

    def test_faults(self):
        # 1. Not recording, clips published and labelled anyway.
        self.stream(2.0)
        status, values = self.wait_status(lambda s, v: int(v["clips published"]) > 0, 10, "a clip")
        self.assertEqual(status.level, DiagnosticStatus.ERROR, status.message)
        self.assertIn("not recording", status.message)
        self.assertIn("package.xml/clips", status.message)
        self.assertGreater(int(values["clips not recorded"]), 0)
        with self.lock:
            first = list(self.clips)
        self.assertTrue(first)
        for c in first:
            self.assertGreater(c.wind_count, 0, "clip %d unlabelled" % c.sequence)
            self.assertEqual(c.wind_direction_frame_id, "anemometer")

        # 2. A reading an hour ahead of the clock is refused; later clips keep their labels. A
        # direction in another frame (true wind in ENU beside the instrument's) is left out of the
        # mean direction, its speed kept.
        def future(frame, stamp):
            if frame == self.frame_at_future:
                self.wind_pub.publish(reading(stamp + rospy.Duration(3600), 50.0))
            if frame == self.frame_at_future + 1:
                other = reading(stamp, 10.0)  # a speed of its own: dropped whole, no mean would show it
                other.header.frame_id = "enu"
                other.direction = 1.5
                self.wind_pub.publish(other)
        self.frame_at_future = self.frame + 5
        with self.lock:
            before = len(self.clips)
        self.stream(4.0, extra=future)
        status, values = self.wait_status(lambda s, v: v["readings stamped in the future"] == "1", 5,
                                          "the future reading counted")
        self.assertIn("after the clock refused", status.message)
        self.assertIn("3600", status.message)
        self.assertEqual(values["directions in another frame (left out)"], "1")
        self.assertEqual(values["wind direction frame"], "anemometer")
        deadline = rospy.get_time() + 10
        while rospy.get_time() < deadline:
            with self.lock:
                later = self.clips[before:]
            if len(later) >= 8:
                break
            rospy.sleep(0.1)
        self.assertGreaterEqual(len(later), 8)
        for c in later:
            self.assertGreater(c.wind_count, 0, "clip %d unlabelled" % c.sequence)
            # 4 m/s, or above it in the clips whose window holds the other frame's 10 m/s reading.
            self.assertGreaterEqual(c.wind_mean, 4.0 - 1e-9, "clip %d" % c.sequence)
            self.assertLess(c.wind_mean, 10.0, "clip %d" % c.sequence)
            self.assertAlmostEqual(c.wind_direction_mean, 0.0, places=9)
        self.assertTrue(any(c.wind_mean > 4.0 + 1e-6 for c in later),
                        "the other frame's reading lost its speed too: %s" % [c.wind_mean for c in later])

        # 3. Time goes back 30 s (a bag looped): the waiting clips are labelled, not dropped.
        self.stream(0.6)  # leaves clips waiting for their label (delay 0.5 s)
        self.stream(1.0, offset=-30.0, speed=6.0)
        status, values = self.wait_status(
            lambda s, v: v["time jumps back"] == "1" and v["clips waiting for label"] == "0", 10, "the jump")
        self.assertGreater(int(values["clips labelled at a time jump"]), 0)
        self.assertEqual(int(values["clips made"]), int(values["clips published"]))

        # 4. A frame that cannot be read: ERROR for 10 s, then only in "last error".
        bad = image(rospy.Time.now() - rospy.Duration(30), 0)
        bad.data = bad.data[:100]
        self.image_pub.publish(bad)
        status, values = self.wait_status(lambda s, v: v["errors"] == "1", 5, "the bad frame")
        # In the summary because it is recent (the level is ERROR anyway: the folder never opened).
        self.assertIn("frame dropped", status.message)
        self.assertLess(float(values["last error age [s]"]), 10.0)
        self.stream(11.0, offset=-30.0)
        status, values = self.wait_status(lambda s, v: float(v["last error age [s]"]) > 10.0, 5, "the error to age")
        self.assertNotIn("frame dropped", status.message)
        self.assertIn("frame dropped", values["last error"])
        self.assertIn("not recording", status.message)  # still true: the folder never opened

        # 5. An unstamped frame and reading (a driver leaving header.stamp 0): dropped and said so,
        # not taken for a bag loop (which would forget the minute of readings the labels need).
        jumps = values["time jumps back"]
        published = int(values["clips published"])
        with self.lock:
            before = len(self.clips)
        self.image_pub.publish(image(rospy.Time(0), 0))
        self.wind_pub.publish(reading(rospy.Time(0), 9.0))
        status, values = self.wait_status(lambda s, v: v["errors"] == "3", 5, "the unstamped frame and reading")
        self.assertIn("header.stamp is 0", status.message)
        self.assertIn("header.stamp is 0", values["last error"])
        self.stream(2.0, offset=-30.0)
        status, values = self.wait_status(lambda s, v: int(v["clips published"]) > published, 5, "clips after them")
        self.assertEqual(values["time jumps back"], jumps)
        deadline = rospy.get_time() + 5
        while rospy.get_time() < deadline:
            with self.lock:
                after = self.clips[before:]
            if after:
                break
            rospy.sleep(0.1)
        self.assertTrue(after, "no clip after the unstamped frame")
        for c in after:
            self.assertGreater(c.wind_count, 0, "clip %d lost its label" % c.sequence)

        # 6. Frames that stop coming (a bag ended or paused) are a WARN after 2 s (flush_after is
        # 1 s here), gone once they come again: it stayed "making clips" for ever.
        status, values = self.wait_status(lambda s, v: "no camera frames for" in s.message, 6, "the idle warning")
        self.assertIn("a recording ended or paused", status.message)
        self.stream(1.0, offset=-30.0)
        self.wait_status(lambda s, v: "no camera frames for" not in s.message, 5, "the idle warning to go")


if __name__ == "__main__":
    rospy.init_node("clip_buffer_faults_check")
    rostest.rosrun("clothwind", "clip_buffer_faults", ClipBufferFaultsTest, sys.argv)
