#!/usr/bin/env python3
"""rostest for camera_node under a looping /clock (see tests/camera_clock_loop.test).

Before any /clock: the node's folder does not exist, and its throttled ERROR must reach /rosout.
Then the test writes the folder and publishes /clock itself, three loops of 2 s of ROS time each
returning to exactly the same start, and requires frames in every loop, stamped within it.
"""
import os
import shutil
import sys
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Clock, Log
from sensor_msgs.msg import Image

from camera_folder_check import write_folder

START = 1000.0  # ROS time of every loop's start [s]
LOOP = 2.0      # ROS seconds per loop, played at real speed
LOOPS = 3


class CameraClockLoopTest(unittest.TestCase):
    def test_frames_go_on_after_the_clock_loops(self):
        folder = rospy.get_param("~folder")
        lock = threading.Lock()
        errors, frames = [], []

        def on_log(msg):
            if msg.name.endswith("camera_node") and msg.level >= Log.ERROR:
                with lock:
                    errors.append(msg.msg)

        def on_image(msg):
            with lock:
                frames.append((time.monotonic(), msg.header.stamp.to_sec()))

        windows = []  # the rate check's windows [ROS s], from its diagnostics

        def on_diagnostics(msg):
            for st in msg.status:
                if "image_raw topic status" in st.name:
                    values = {kv.key: kv.value for kv in st.values}
                    if "Duration of window (s)" in values:
                        with lock:
                            windows.append((time.monotonic(), float(values["Duration of window (s)"])))

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=100)
        rospy.Subscriber("/rosout", Log, on_log, queue_size=100)
        rospy.Subscriber("camera/image_raw", Image, on_image, queue_size=100)
        clock = rospy.Publisher("/clock", Clock, queue_size=10)

        # No /clock yet (ROS time 0) and no folder: the node says so within a few seconds.
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline:
            with lock:
                if errors:
                    break
            time.sleep(0.1)
        with lock:
            self.assertTrue(errors, "no ERROR from camera_node on /rosout before /clock started")
            self.assertIn(folder, errors[0])

        write_folder(folder, 24, 16, 1, lambda k: 10 + 20 * k)
        try:
            # The node retries its folder with a back-off of up to 5 s: hold the clock at the
            # start until it publishes (a frame is due at once), then play the loops.
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline:
                clock.publish(Clock(clock=rospy.Time.from_sec(START)))
                time.sleep(0.05)
                with lock:
                    if frames:
                        break
            with lock:
                self.assertTrue(frames, "camera_node published nothing in 20 s with its folder there")
                frames.clear()
            loop_walls = []
            for loop in range(LOOPS):
                loop_walls.append(time.monotonic())
                t = 0.0
                while t <= LOOP:
                    clock.publish(Clock(clock=rospy.Time.from_sec(START + t)))
                    time.sleep(0.01)
                    t += 0.01
            end_wall = time.monotonic()
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        time.sleep(0.2)
        with lock:
            got = list(frames)
        bounds = loop_walls + [end_wall]
        for loop in range(LOOPS):
            # Frames of this loop: received while it played, stamped inside its span of ROS time.
            inside = [s for w, s in got if bounds[loop] <= w < bounds[loop + 1] + 0.1]
            self.assertGreaterEqual(len(inside), 10, "loop %d: %d frames (10 Hz over %.0f s)" % (loop, len(inside), LOOP))
            self.assertTrue(all(START - 1e-6 <= s <= START + LOOP + 0.2 for s in inside),
                            "loop %d: stamps outside the loop: %s" % (loop, inside))
        # The rate check's window is cleared when the clock goes back: it spanned the jump
        # (negative: "Frequency too low" for ten reports after every loop) or, after the first
        # /clock, reached back to time 0.
        with lock:
            played = [w for t, w in windows if t > loop_walls[0]]
        self.assertGreaterEqual(len(played), LOOPS, "too few rate reports while the loops played: %s" % played)
        self.assertTrue(all(w <= LOOP + 0.5 for w in played), "rate windows [ROS s]: %s" % played)
        # (One jump landing between the node's clock read and the rate check's may show once.)
        self.assertLessEqual(sum(1 for w in played if w < 0), 1, "rate windows [ROS s]: %s" % played)


if __name__ == "__main__":
    rospy.init_node("camera_clock_loop_check")
    rostest.rosrun("clothwind", "camera_clock_loop", CameraClockLoopTest, sys.argv)
