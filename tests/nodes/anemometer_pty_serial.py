#!/usr/bin/env python3
"""Plays an anemometer on a pseudo-terminal and checks what anemometer_node publishes.

The pty slave is symlinked to the node's ~port. Sentences are written byte-exact as the
manufacturers document them; the test checks values (SI, REP 103 direction), the count (one
WindMeasurement per wind sentence, none for garbage), stamps (arrival time of the first byte:
after the write, shortly), RawSentence/WindMeasurement stamp equality, survival of garbage, and
reconnection after the device vanishes.
"""
import math
import os
import threading
import time
import tty
import unittest

import rospy
import rostest
from clothwind.msg import RawSentence, WindMeasurement
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

import wind_records

KNOT = 1852.0 / 3600.0


def nmea(body):
    return (wind_records.nmea(body) + '\r\n').encode('ascii')


def wrap(a):
    a = math.fmod(a + math.pi, 2 * math.pi)
    if a <= 0:
        a += 2 * math.pi
    return a - math.pi


class FakeInstrument:
    """A pty whose slave is reachable at `link` (like a udev symlink /dev/anemometer)."""

    def __init__(self, link):
        self.link = link
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)  # no echo/canonical buffering before the node configures the line
        tmp = link + '.tmp'
        if os.path.lexists(tmp):
            os.unlink(tmp)
        os.symlink(os.ttyname(self.slave), tmp)
        os.rename(tmp, link)  # atomic: the node never sees a half-made link

    def write(self, data):
        os.write(self.master, data)

    def vanish(self):
        os.unlink(self.link)
        os.close(self.master)
        os.close(self.slave)


class AnemometerPtySerialTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('anemometer_pty_serial')
        cls.port = rospy.get_param('~port')
        cls.lock = threading.Lock()
        cls.winds, cls.raws, cls.diags = [], [], []
        rospy.Subscriber('anemometer/wind', WindMeasurement, cls.on_wind, queue_size=100)
        rospy.Subscriber('anemometer/raw', RawSentence, cls.on_raw, queue_size=100)
        rospy.Subscriber('/diagnostics', DiagnosticArray, cls.on_diag, queue_size=10)
        # The node tries (and fails) to open a port that does not exist yet, and says so, before
        # the device appears: the retry is what the test is about, so wait for the node to report
        # it (a fixed sleep let a node that started late open the port at its first try).
        deadline = time.time() + 60.0
        while time.time() < deadline and not cls.serial_status_says('not connected: waiting'):
            time.sleep(0.1)
        assert cls.serial_status_says('not connected: waiting'), 'the node never reported waiting for the port'
        cls.dev = FakeInstrument(cls.port)

    @classmethod
    def tearDownClass(cls):
        try:
            cls.dev.vanish()
        except OSError:
            pass

    @classmethod
    def on_wind(cls, m):
        with cls.lock:
            cls.winds.append(m)

    @classmethod
    def on_raw(cls, m):
        with cls.lock:
            cls.raws.append(m)

    @classmethod
    def on_diag(cls, m):
        # The serial node's statuses only (its hardware id is the port; the usb node's and the
        # replay nodes' are not).
        for s in m.status:
            if 'anemometer' in s.name and s.hardware_id == cls.port:
                with cls.lock:
                    cls.diags.append(s)

    @classmethod
    def serial_status_says(cls, text, level=DiagnosticStatus.ERROR):
        with cls.lock:
            return any(s.level == level and text in s.message for s in cls.diags)

    def clear(self):
        with self.lock:
            del self.winds[:]
            del self.raws[:]

    def wait_for_wind(self, probe, timeout):
        """Writes `probe` every 0.1 s until a WindMeasurement arrives."""
        deadline = time.time() + timeout
        while time.time() < deadline and not rospy.is_shutdown():
            self.dev.write(probe)
            time.sleep(0.1)
            with self.lock:
                if self.winds:
                    return True
        return False

    def test_1_values_count_stamps_and_garbage(self):
        probe = nmea('IIMWV,000.0,R,0.0,M,A')
        self.assertTrue(self.wait_for_wind(probe, 20.0), 'node never read the pty')
        time.sleep(0.3)
        self.clear()

        # (bytes, expected speed [m/s] or None for no wind, expected direction [rad], valid, relative)
        records = [
            (nmea('IIMWV,229.0,R,5.8,N,A'), 5.8 * KNOT, wrap(math.pi - math.radians(229.0)), True, True),
            (b'\xff\xfe\x00\x01garbage\r\n', None, None, None, None),
            (nmea('WIMWV,090.0,T,12.6,M,A'), 12.6, math.pi / 2, True, False),
            (b'$IIMWV,229.0,R,5.8,N,A*00\r\n', None, None, None, None),           # bad checksum
            (nmea('IIMWV,180.0,R,36.0,K,A'), 10.0, 0.0, True, True),
            (b'$IIMWV,12\r\n', None, None, None, None),                           # truncated
            (nmea('IIMWV,270.0,R,10.0,S,V'), 4.4704, -math.pi / 2, False, True),  # status void
            (bytes(range(256)) * 4 + b'\n', None, None, None, None),              # binary noise, overlong
            (nmea('IIMWV,045.0,R,5.0,X,A'), None, None, None, None),              # unknown unit
            (nmea('WIMWD,270.0,T,265.5,M,10.0,N,5.1,M'), 5.1, 0.0, True, False),  # westerly blows east (ENU)
            (nmea('IIMWV,315.0,R,2.0,M,A'), 2.0, wrap(math.pi - math.radians(315.0)), True, True),
        ]
        expected = []
        for data, speed, direction, valid, relative in records:
            t0 = rospy.Time.now()
            self.dev.write(data)
            time.sleep(0.15)
            if speed is not None:
                expected.append((t0, speed, direction, valid, relative))
        deadline = time.time() + 10.0  # generous: the test machine's cores are shared
        while time.time() < deadline:
            with self.lock:
                if len(self.winds) >= len(expected):
                    break
            time.sleep(0.1)
        time.sleep(0.5)  # anything extra (a reading from garbage) would arrive by now
        with self.lock:
            winds, raws = list(self.winds), list(self.raws)

        self.assertEqual(len(winds), len(expected), [(w.speed, w.source) for w in winds])
        raw_stamps = {r.header.stamp for r in raws}
        for w, (t0, speed, direction, valid, relative) in zip(winds, expected):
            self.assertAlmostEqual(w.speed, speed, places=6)
            self.assertAlmostEqual(math.cos(w.direction), math.cos(direction), places=6)
            self.assertAlmostEqual(math.sin(w.direction), math.sin(direction), places=6)
            self.assertAlmostEqual(w.velocity.x, speed * math.cos(direction), places=6)
            self.assertAlmostEqual(w.velocity.y, speed * math.sin(direction), places=6)
            self.assertEqual(w.valid, valid)
            self.assertEqual(w.relative, relative)
            self.assertEqual(w.header.frame_id, 'mast')
            # Stamped at the arrival of the first byte: not before we wrote it, and soon after.
            self.assertGreaterEqual(w.header.stamp, t0)
            self.assertLess((w.header.stamp - t0).to_sec(), 2.0)
            self.assertIn(w.header.stamp, raw_stamps)
        sources = [w.source for w in winds]
        self.assertIn('nmea_mwd', sources)
        # Every record is recorded raw, garbage included (for replay), and none carries the terminator.
        self.assertGreaterEqual(len(raws), len(expected) + 4)
        self.assertTrue(all('\r' not in r.data and '\n' not in r.data for r in raws))
        mwv = [r for r in raws if r.data.startswith('$IIMWV,229.0')]
        self.assertTrue(mwv and mwv[0].protocol == 'nmea')

    def test_2_diagnostics(self):
        deadline = time.time() + 5.0
        found = None
        while time.time() < deadline and found is None:
            time.sleep(0.5)
            with self.lock:
                for s in reversed(self.diags):
                    values = {kv.key: kv.value for kv in s.values}
                    if int(values.get('checksum failures', '0')) >= 1:
                        found = values
                        break
        self.assertIsNotNone(found, 'no diagnostics with the checksum failure')
        self.assertTrue(found['protocol'].startswith('nmea'))
        self.assertGreaterEqual(int(found['parse errors']), 3)
        self.assertIn('last valid age [s]', found)

    def test_3_reconnects_after_device_vanishes(self):
        self.dev.vanish()
        # "Says so": an ERROR naming the lost device, before it comes back.
        with self.lock:
            del self.diags[:]
        deadline = time.time() + 20.0
        while time.time() < deadline and not self.serial_status_says('not connected'):
            time.sleep(0.1)
        self.assertTrue(self.serial_status_says('not connected'), 'no ERROR after the device vanished')
        self.clear()
        self.dev = type(self).dev = FakeInstrument(self.port)
        probe = nmea('IIMWV,010.0,R,3.0,M,A')
        self.assertTrue(self.wait_for_wind(probe, 20.0), 'node did not reconnect')
        with self.lock:
            self.assertAlmostEqual(self.winds[-1].speed, 3.0, places=6)
        # ...and counts the disconnection (connected twice, once lost).
        deadline = time.time() + 10.0
        values = {}
        while time.time() < deadline:
            with self.lock:
                values = {kv.key: kv.value for kv in self.diags[-1].values} if self.diags else {}
            if int(values.get('connects', 0)) >= 2:
                break
            time.sleep(0.2)
        self.assertGreaterEqual(int(values.get('disconnects', 0)), 1, values)
        self.assertGreaterEqual(int(values.get('connects', 0)), 2, values)

    def test_4_gill_after_nmea_is_rejected_until_proven(self):
        # The decoder locked onto NMEA: a lone Gill record is treated as noise, not a reading.
        self.clear()
        self.dev.write((wind_records.gill('Q,229,002.74,M,00,') + '\r\n').encode('ascii'))
        time.sleep(0.5)
        self.dev.write(nmea('IIMWV,020.0,R,1.0,M,A'))
        deadline = time.time() + 10.0
        while time.time() < deadline:
            with self.lock:
                if self.winds:
                    break
            time.sleep(0.1)
        time.sleep(0.3)
        with self.lock:
            self.assertEqual([w.source for w in self.winds], ['nmea_mwv'])
            self.assertTrue(any(r.data.startswith('\x02Q,229') for r in self.raws))

    def test_5_a_port_that_opens_and_fails_every_read_is_reopened_ever_more_slowly(self):
        # A device whose port opens and whose every read fails (here each pty's master closes as
        # soon as the node holds its slave: the read gets EIO) was reopened every 0.1 s: the
        # back-off restarted at each open. It restarts when bytes arrive: the delays before the
        # next open grow to ~reconnect_max_delay (1 s here: 0.2, 0.4, 0.8, 1, 1; each 0.1 s
        # before). The bounds leave 0.3 s either way for a loaded machine.
        try:
            self.dev.vanish()
        except OSError:
            pass
        gaps = []
        for i in range(6):
            self.dev = type(self).dev = FakeInstrument(self.port)
            made = time.time()
            self.assertTrue(self.wait_until_held(self.dev, 20.0), 'the node did not open the port (%d)' % i)
            if i > 0:
                gaps.append(time.time() - made)
            self.dev.vanish()
        self.assertGreaterEqual(min(gaps[-2:]), 0.7, 'delays before each reopen [s]: %s' % gaps)
        # Bytes from the instrument restart it: lost after a reading, the port is reopened soon.
        self.dev = type(self).dev = FakeInstrument(self.port)
        self.clear()
        self.assertTrue(self.wait_for_wind(nmea('IIMWV,010.0,R,3.0,M,A'), 20.0), 'no reading after the reopen')
        self.dev.vanish()
        self.dev = type(self).dev = FakeInstrument(self.port)
        made = time.time()
        self.assertTrue(self.wait_until_held(self.dev, 20.0), 'the node did not open the port again')
        self.assertLess(time.time() - made, 0.45, 'the back-off did not restart after a reading (gaps before: %s)' % gaps)

    @staticmethod
    def wait_until_held(dev, timeout):
        """Waits until another process holds dev's pty slave open (the node opened the port)."""
        path = os.ttyname(dev.slave)
        deadline = time.time() + timeout
        while time.time() < deadline:
            for pid in os.listdir('/proc'):
                if not pid.isdigit() or int(pid) == os.getpid():
                    continue
                try:
                    fds = os.listdir('/proc/%s/fd' % pid)
                except OSError:
                    continue
                for fd in fds:
                    try:
                        if os.readlink('/proc/%s/fd/%s' % (pid, fd)) == path:
                            return True
                    except OSError:
                        pass
            time.sleep(0.005)
        return False


if __name__ == '__main__':
    rostest.rosrun('clothwind', 'anemometer_pty_serial', AnemometerPtySerialTest)
