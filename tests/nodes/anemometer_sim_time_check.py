#!/usr/bin/env python3
"""rostest (tests/anemometer_sim_time.test): anemometer_node ~input:=topic on a replay's clock ages
its readings on ROS time, not the wall clock."""
import time
import unittest

import rospy
import rostest
from clothwind.msg import RawSentence, WindMeasurement
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rosgraph_msgs.msg import Clock
from wind_records import nmea

HARDWARE_ID = 'topic:/anemometer/raw'


class AnemometerSimTimeTest(unittest.TestCase):
    def setUp(self):
        rospy.init_node('anemometer_sim_time_check', anonymous=True)
        self.clock = rospy.Publisher('/clock', Clock, queue_size=10)
        self.raw = rospy.Publisher('/anemometer/raw', RawSentence, queue_size=50)
        self.winds = []
        self.wind_sub = rospy.Subscriber('/anemometer/wind', WindMeasurement, self.winds.append, queue_size=50)
        self.statuses = []
        self.diag_sub = rospy.Subscriber('/diagnostics', DiagnosticArray, self.on_diag, queue_size=20)
        deadline = time.time() + 20.0
        while time.time() < deadline and (self.raw.get_num_connections() == 0 or
                                          self.clock.get_num_connections() == 0 or
                                          self.wind_sub.get_num_connections() == 0):
            time.sleep(0.1)
        self.assertGreater(self.raw.get_num_connections(), 0, 'the node did not subscribe')

    def on_diag(self, m):
        self.statuses.extend(s for s in m.status if s.hardware_id == HARDWARE_ID)

    def set_clock(self, secs):
        c = Clock()
        c.clock = rospy.Time.from_sec(secs)
        self.clock.publish(c)
        time.sleep(0.05)

    def statuses_for(self, wall_seconds):
        """The node's statuses over the next `wall_seconds` of wall time (diagnostics come every
        wall second, clock or not)."""
        start = len(self.statuses)
        time.sleep(wall_seconds)
        got = self.statuses[start:]
        self.assertTrue(got, 'no diagnostics in %.0f s' % wall_seconds)
        return got

    def status_until(self, condition, wall_seconds):
        """The first status from now on that meets `condition`, within `wall_seconds`; else the last."""
        start = len(self.statuses)
        deadline = time.time() + wall_seconds
        while time.time() < deadline:
            for s in self.statuses[start:]:
                if condition(s):
                    return s
            time.sleep(0.1)
        self.assertGreater(len(self.statuses), start, 'no diagnostics in %.0f s' % wall_seconds)
        return self.statuses[-1]

    def test_readings_age_on_the_replays_clock(self):
        t = 1000.0
        for i in range(6):  # a 2 Hz instrument, the clock running with it
            self.set_clock(t)
            m = RawSentence()
            m.header.stamp = rospy.Time.from_sec(t)
            m.header.frame_id = 'mast'
            m.data = nmea('WIMWV,270.0,R,4.0,M,A')
            self.raw.publish(m)
            t += 0.5
            time.sleep(0.45)
        deadline = time.time() + 10
        while time.time() < deadline and len(self.winds) < 6:
            time.sleep(0.1)
        self.assertEqual(len(self.winds), 6)
        self.set_clock(t)
        status = self.status_until(lambda s: s.level == DiagnosticStatus.OK, 5.0)
        self.assertEqual(status.level, DiagnosticStatus.OK, status.message)
        # The replay paused: 5 s of wall time without /clock, past the 3 s ~stale_timeout. No
        # status of those seconds says stale.
        for status in self.statuses_for(5.0):
            self.assertNotIn('stale', status.message)
            self.assertEqual(status.level, DiagnosticStatus.OK, status.message)
        # The replay runs on 5 s of its own time without a reading: stale.
        self.set_clock(t + 5.0)
        status = self.status_until(lambda s: 'valid readings stale' in s.message, 5.0)
        self.assertEqual(status.level, DiagnosticStatus.WARN, status.message)
        self.assertIn('valid readings stale', status.message)


if __name__ == '__main__':
    rostest.rosrun('clothwind', 'anemometer_sim_time_check', AnemometerSimTimeTest)
