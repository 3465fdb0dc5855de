#!/usr/bin/env python3
"""session_bag_watch beside a real rosbag record: OK while the bag grows, ERROR once it stops."""
import base64
import os
import shutil
import threading
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from std_msgs.msg import String


class SessionBagWatchTest(unittest.TestCase):
    def setUp(self):
        self.prefix = rospy.get_param("~prefix")
        self.lock = threading.Lock()
        self.statuses = []
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=50)
        self.pub = rospy.Publisher("/watch_test/data", String, queue_size=100)

    def tearDown(self):
        shutil.rmtree(os.path.dirname(self.prefix), ignore_errors=True)

    def on_diagnostics(self, msg):
        with self.lock:
            self.statuses += [s for s in msg.status if s.name.endswith("session bag")]

    def wait_for(self, predicate, timeout, what, publish=False):
        deadline = rospy.get_time() + timeout
        while not rospy.is_shutdown() and rospy.get_time() < deadline:
            if publish:
                # Random text: the recorder's LZ4 shrinks repeated bytes to almost nothing.
                self.pub.publish(String(data=base64.b64encode(os.urandom(7500)).decode()))
            with self.lock:
                found = [s for s in self.statuses if predicate(s)]
            if found:
                return found[-1], {kv.key: kv.value for kv in found[-1].values}
            rospy.sleep(0.01)
        with self.lock:
            last = self.statuses[-1].message if self.statuses else "none"
        self.fail("timed out waiting for %s (last status: %s)" % (what, last))

    def test_recording_then_stalled(self):
        self.wait_for(lambda s: True, 20, "the watch's diagnostics")
        deadline = rospy.get_time() + 20
        while self.pub.get_num_connections() == 0 and rospy.get_time() < deadline:
            rospy.sleep(0.1)
        self.assertGreater(self.pub.get_num_connections(), 0, "the recorder did not subscribe")
        name = os.path.basename(self.prefix) + "_"
        status, values = self.wait_for(
            lambda s: s.level == DiagnosticStatus.OK and s.message.startswith("recording " + name) and
            float({kv.key: kv.value for kv in s.values}["write rate [MB/s]"]) > 0.1, 30,
            "an OK of a bag growing at most 1 MB/s", publish=True)
        self.assertTrue(values["bag"].startswith(self.prefix + "_") and values["bag"].endswith(".bag.active"), values)
        self.assertEqual(values["bags begun this session"], "1")
        self.assertEqual(values["bags left open (rosbag reindex them)"], "none")
        self.assertGreater(float(values["free space [GB]"]), 0)
        # Nothing more to record: the bag stops growing, an ERROR within ~stall_after (3 s).
        status, values = self.wait_for(
            lambda s: s.level == DiagnosticStatus.ERROR and "has not grown for" in s.message, 20,
            "an ERROR that the bag stopped growing")
        self.assertIn("(the recorder stopped, or nothing comes to record)", status.message)


if __name__ == "__main__":
    rospy.init_node("session_bag_watch_check")
    rostest.rosrun("clothwind", "session_bag_watch_check", SessionBagWatchTest)
