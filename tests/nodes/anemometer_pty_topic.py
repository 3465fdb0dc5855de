#!/usr/bin/env python3
"""anemometer_node ~input:=topic (rosbag replay): RawSentence in, WindMeasurement out with the
raw message's stamp and frame; garbage and bad checksums give nothing."""
import math
import threading
import time
import unittest

import rospy
import rostest
from clothwind.msg import RawSentence, WindMeasurement
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from wind_records import gill, nmea


class AnemometerTopicTest(unittest.TestCase):
    def setUp(self):
        rospy.init_node('anemometer_pty_topic', anonymous=True)
        self.lock = threading.Lock()
        self.winds = []
        self.sub = rospy.Subscriber('/replay/anemometer/wind', WindMeasurement, self.on_wind, queue_size=50)
        self.pub = rospy.Publisher('/replay/anemometer/raw', RawSentence, queue_size=50)
        deadline = time.time() + 20.0
        while time.time() < deadline and (self.pub.get_num_connections() == 0 or
                                          self.sub.get_num_connections() == 0):
            time.sleep(0.1)
        self.assertGreater(self.pub.get_num_connections(), 0, 'replay node not subscribed')
        time.sleep(0.5)

    def on_wind(self, m):
        with self.lock:
            self.winds.append(m)

    def send(self, data, secs, nsecs, protocol=''):
        m = RawSentence()
        m.header.stamp = rospy.Time(secs, nsecs)
        m.header.frame_id = 'recorded_frame'
        m.data = data
        m.protocol = protocol
        self.pub.publish(m)
        time.sleep(0.2)

    def test_replay_keeps_stamps(self):
        record = gill('Q,229,002.74,M,00,')
        self.send(record, 1234, 5678, 'gill')
        self.send('\\xFF\\x00 garbage', 1235, 0)
        self.send(record[:-1] + ('0' if record[-1] != '0' else '1'), 1236, 0, 'gill')  # bad checksum
        self.send(record, 1237, 999999999, 'gill')
        deadline = time.time() + 10.0
        while time.time() < deadline:
            with self.lock:
                if len(self.winds) >= 2:
                    break
            time.sleep(0.1)
        time.sleep(0.5)
        with self.lock:
            winds = list(self.winds)
        self.assertEqual(len(winds), 2, [(w.header.stamp.to_sec(), w.speed) for w in winds])
        self.assertEqual(winds[0].header.stamp, rospy.Time(1234, 5678))
        self.assertEqual(winds[1].header.stamp, rospy.Time(1237, 999999999))
        for w in winds:
            self.assertEqual(w.header.frame_id, 'recorded_frame')
            self.assertAlmostEqual(w.speed, 2.74, places=9)
            self.assertAlmostEqual(w.direction, math.pi - math.radians(229.0), places=9)
            self.assertEqual(w.source, 'gill')
            self.assertTrue(w.valid)

    def diagnostics(self, hardware_id, count=2, timeout=10.0):
        got = []

        def on_diag(m):
            got.extend(s for s in m.status if s.hardware_id == hardware_id)

        sub = rospy.Subscriber('/diagnostics', DiagnosticArray, on_diag, queue_size=10)
        deadline = time.time() + timeout
        while time.time() < deadline and len(got) < count:
            time.sleep(0.2)
        sub.unregister()
        self.assertGreaterEqual(len(got), count, 'no diagnostics from ' + hardware_id)
        return got[-1], {kv.key: kv.value for kv in got[-1].values}

    def winds_on(self, topic, records):
        winds = []
        sub = rospy.Subscriber(topic, WindMeasurement, winds.append, queue_size=50)
        pub = rospy.Publisher(topic.replace('/wind', '/raw'), RawSentence, queue_size=50)
        deadline = time.time() + 20.0
        while time.time() < deadline and (pub.get_num_connections() == 0 or sub.get_num_connections() == 0):
            time.sleep(0.1)
        time.sleep(0.5)
        for i, data in enumerate(records):
            m = RawSentence()
            m.header.stamp = rospy.Time(2000 + i, 0)
            m.header.frame_id = 'recorded_frame'
            m.data = data
            pub.publish(m)
            time.sleep(0.2)
        time.sleep(0.5)
        sub.unregister()
        return winds

    def test_records_stamped_0_or_far_ahead_are_dropped_and_said(self):
        # They were republished as readings with those stamps, which the clip buffer refuses:
        # counted there, far from their cause.
        record = gill('Q,229,002.74,M,00,')
        winds = []
        sub = rospy.Subscriber('/replay_odd/anemometer/wind', WindMeasurement, winds.append, queue_size=50)
        pub = rospy.Publisher('/replay_odd/anemometer/raw', RawSentence, queue_size=50)
        deadline = time.time() + 20.0
        while time.time() < deadline and (pub.get_num_connections() == 0 or sub.get_num_connections() == 0):
            time.sleep(0.1)
        time.sleep(0.5)
        # TIME_MAX too: its difference from now as a ros::Duration threw, and the node died.
        for stamp in (rospy.Time(0, 0), rospy.Time.now() + rospy.Duration(3600),
                      rospy.Time(4294967295, 999999999), rospy.Time.now()):
            m = RawSentence()
            m.header.stamp = stamp
            m.header.frame_id = 'recorded_frame'
            m.data = record
            m.protocol = 'gill'
            pub.publish(m)
            time.sleep(0.2)
        time.sleep(0.5)
        sub.unregister()
        self.assertEqual(len(winds), 1, [w.header.stamp.to_sec() for w in winds])  # the one stamped now
        status, values = self.diagnostics('topic:/replay_odd/anemometer/raw', count=1)
        self.assertEqual(values['records dropped for their stamps'], '3')

    def test_wind_kinds(self):
        # /replay's decoder already read test_replay_keeps_stamps' two Gill records (unittest runs
        # tests by name): under 3, so it has not locked onto Gill and reads the NMEA ones below.
        mwv = nmea('IIMWV,229.0,R,5.8,M,A')
        mwd_magnetic = nmea('WIMWD,,T,90.0,M,,N,5.0,M')
        implausible = nmea('IIMWV,229.0,R,500.0,M,A')
        void = nmea('IIMWV,229.0,R,5.8,M,V')  # status V: the instrument says the data is void
        winds = self.winds_on('/replay/anemometer/wind', [mwv, mwd_magnetic, implausible, void])
        self.assertEqual([w.source for w in winds], ['nmea_mwv', 'nmea_mwd', 'nmea_mwv'])
        self.assertTrue(math.isnan(winds[1].direction))  # magnetic, no declination
        self.assertAlmostEqual(winds[1].speed, 5.0)
        self.assertFalse(winds[2].valid)
        status, values = self.diagnostics('topic:/replay/anemometer/raw')
        self.assertEqual(status.level, DiagnosticStatus.WARN)
        self.assertIn('instrument flags its readings void: V', status.message)
        self.assertIn('~magnetic_declination', status.message)
        self.assertIn('~earth_frame_id', status.message)
        self.assertIn('speed 500', values['last error'])

        # An MWD without bearings (a calm one) goes with the MWDs: in the instrument's frame, a
        # station's calm first reading made wind_display adopt that frame and refuse the bearings.
        mwd_calm = nmea('WIMWD,,T,,M,0.0,N,0.0,M')
        winds = self.winds_on('/replay_earth/anemometer/wind', [mwv, mwd_magnetic, mwd_calm])
        self.assertEqual([w.header.frame_id for w in winds], ['recorded_frame', 'enu', 'enu'])
        self.assertTrue(math.isnan(winds[2].direction))
        # Magnetic 90 + 10 east = 100 deg true, from the east-south-east: blows to 280 deg, i.e.
        # 170 deg counter-clockwise from east.
        self.assertAlmostEqual(winds[1].direction, math.radians(170.0), places=9)
        status, values = self.diagnostics('topic:/replay_earth/anemometer/raw')
        self.assertEqual(status.level, DiagnosticStatus.OK, status.message)
        self.assertEqual(values['earth frame'], 'enu')

    def test_a_replayed_fine_offset_station_is_not_stale_between_its_records(self):
        winds = self.winds_on('/replay_fo/anemometer/wind', ['052DD200508A007E271C2A1006240100'])
        self.assertEqual([w.source for w in winds], ['fine_offset'])
        time.sleep(7.0)  # past the 5 s allowance of an instrument that reports every second
        status, values = self.diagnostics('topic:/replay_fo/anemometer/raw')
        self.assertNotIn('stale', status.message)
        self.assertEqual(status.level, DiagnosticStatus.OK, status.message)

    def test_usb_without_station_keeps_retrying(self):
        got = []

        def on_diag(m):
            for s in m.status:
                if s.hardware_id == 'usb:1941:8021':
                    got.append(s)

        sub = rospy.Subscriber('/diagnostics', DiagnosticArray, on_diag, queue_size=10)
        deadline = time.time() + 10.0
        while time.time() < deadline and len(got) < 3:
            time.sleep(0.2)
        sub.unregister()
        self.assertGreaterEqual(len(got), 3, 'usb-mode node published no diagnostics (crashed?)')
        self.assertEqual(got[-1].level, DiagnosticStatus.ERROR)
        self.assertIn('not connected', got[-1].message)
        values = {kv.key: kv.value for kv in got[-1].values}
        self.assertEqual(values['input'], 'usb')
        self.assertIn('48 s', values['update period'])


if __name__ == '__main__':
    rostest.rosrun('clothwind', 'anemometer_pty_topic', AnemometerTopicTest)
