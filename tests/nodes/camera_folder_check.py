#!/usr/bin/env python3
"""rostest for camera_node in folder mode (see tests/camera_node.test).

Writes two PNG sequences (colour 40x30 and grey 24x16) into folders the nodes are already
polling for (written under a temporary name, then renamed, so a node never sees half a folder),
then checks the published images and camera_info. PNGs are written with zlib only: the test
needs no OpenCV in Python.
"""
import os
import shutil
import struct
import sys
import tempfile
import threading
import time
import unittest

import yaml
import zlib

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sensor_msgs.msg import CameraInfo, Image
from sensor_msgs.srv import SetCameraInfo

N_FRAMES = 10


def write_png(path, width, height, channels, pixel):
    """pixel(x, y) -> tuple of `channels` bytes (RGB or grey)."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)  # filter type none
        for x in range(width):
            raw.extend(pixel(x, y))
    colour_type = 2 if channels == 3 else 0

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw)))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def colour_value(k):
    return 20 + 20 * k


def grey_value(k):
    return 200 - 15 * k


def write_folder(target, width, height, channels, value):
    staging = tempfile.mkdtemp(prefix=".staging_", dir=os.path.dirname(target))
    for k in range(N_FRAMES):
        v = value(k)
        if channels == 3:
            pixel = lambda x, y, v=v: (v, 255 - v, 7)  # R, G, B
        else:
            pixel = lambda x, y, v=v: (v,)
        write_png(os.path.join(staging, "frame_%04d.png" % k), width, height, channels, pixel)
    os.rename(staging, target)


class Collector:
    def __init__(self, prefix):
        self.lock = threading.Lock()
        self.images = []  # (receive time, msg)
        self.infos = []
        rospy.Subscriber(prefix + "camera/image_raw", Image, self.on_image, queue_size=50)
        rospy.Subscriber(prefix + "camera/camera_info", CameraInfo, self.on_info, queue_size=50)

    def on_image(self, msg):
        with self.lock:
            self.images.append((rospy.get_time(), msg))

    def on_info(self, msg):
        with self.lock:
            self.infos.append(msg)

    def wait_for(self, count, timeout):
        deadline = time.time() + timeout
        while time.time() < deadline and not rospy.is_shutdown():
            with self.lock:
                if len(self.images) >= count:
                    return True
            time.sleep(0.05)
        return False


class CameraFolderTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("camera_folder_check")
        cls.colour_folder = rospy.get_param("~colour_folder")
        cls.grey_folder = rospy.get_param("~grey_folder")
        cls.calibration_file = rospy.get_param("~calibration_file")
        cls.garbage_folder = rospy.get_param("~garbage_folder")
        cls.diagnostics = []
        cls.started = time.time()
        rospy.Subscriber("/diagnostics", DiagnosticArray, lambda m: cls.diagnostics.append(m))
        cls.colour = Collector("/")
        cls.grey = Collector("/mono/")
        cls.calibrated = Collector("/calib/")
        cls.refused = {"badurl": Collector("/badurl/"), "badyaml": Collector("/badyaml/")}
        # The nodes poll for folders that do not exist yet and say so; the folders are made only
        # once both have said it, so the retry is what is tested (a fixed sleep let a node that
        # started late find them at its first try).
        def waiting(folder):
            return any(st.level == DiagnosticStatus.ERROR and "cannot open" in st.message and
                       st.hardware_id.endswith(folder)
                       for m in list(cls.diagnostics) for st in m.status)
        deadline = time.time() + 60.0
        while time.time() < deadline and not (waiting(cls.colour_folder) and waiting(cls.grey_folder)):
            time.sleep(0.1)
        assert waiting(cls.colour_folder) and waiting(cls.grey_folder), "the nodes never reported the missing folders"
        write_folder(cls.colour_folder, 40, 30, 3, colour_value)
        write_folder(cls.grey_folder, 24, 16, 1, grey_value)
        staging = tempfile.mkdtemp(prefix=".staging_", dir=os.path.dirname(cls.garbage_folder))
        for k in range(3):
            with open(os.path.join(staging, "frame_%04d.png" % k), "wb") as f:
                f.write(b"not a png")
        os.rename(staging, cls.garbage_folder)
        cls.garbage_written = time.time()

    @classmethod
    def tearDownClass(cls):
        for folder in (cls.colour_folder, cls.grey_folder, cls.garbage_folder):
            shutil.rmtree(folder, ignore_errors=True)
        if os.path.exists(cls.calibration_file):
            os.remove(cls.calibration_file)

    def check_stream(self, collector, rate, width, height, encoding, channels, frame_id, expected, K):
        # Two full loops of the folder, plus some, after the first image.
        n = 2 * N_FRAMES + 5
        self.assertTrue(collector.wait_for(n, timeout=n / rate + 20.0),
                        "only %d images within the timeout" % len(collector.images))
        time.sleep(0.5)  # camera_info travels on its own connection: let the last ones land
        with collector.lock:
            images = list(collector.images)[:n]
            infos = list(collector.infos)
        period = 1.0 / rate
        stamps = [m.header.stamp.to_sec() for _, m in images]
        # Stamps strictly increasing and evenly spaced at the folder rate (they are the due
        # instants of the schedule, not the publishing times).
        for a, b in zip(stamps, stamps[1:]):
            self.assertAlmostEqual(b - a, period, delta=0.002, msg="stamp step %.4f s" % (b - a))
        # Arrival rate matches too (a real-time check, so loosely).
        arrival = [t for t, _ in images]
        measured = (len(arrival) - 1) / (arrival[-1] - arrival[0])
        self.assertAlmostEqual(measured, rate, delta=0.15 * rate)
        steps = [b - a for a, b in zip(stamps, stamps[1:])]
        ages = [t - m.header.stamp.to_sec() for t, m in images]
        print("%s: %d images, arrival %.2f Hz (nominal %.2f), stamp step %.5f..%.5f s, "
              "age at arrival %.1f..%.1f ms" % (encoding, len(images), measured, rate, min(steps),
                                                max(steps), 1e3 * min(ages), 1e3 * max(ages)))
        # Stamps are recent (not stale, not in the future).
        for (t, m) in images:
            age = t - m.header.stamp.to_sec()
            self.assertGreater(age, -0.01)
            self.assertLess(age, 0.5)
        # Format, size, frame, and content in filename order, looping.
        first = None
        for i, (_, m) in enumerate(images):
            self.assertEqual(m.encoding, encoding)
            self.assertEqual((m.width, m.height), (width, height))
            self.assertEqual(m.step, width * channels)
            self.assertEqual(len(m.data), width * height * channels)
            self.assertEqual(m.header.frame_id, frame_id)
            pixel = tuple(bytearray(m.data[(height // 2 * width + width // 2) * channels:][:channels]))
            k = [expected(j) for j in range(N_FRAMES)].index(pixel)
            if first is None:
                first = k
            self.assertEqual(k, (first + i) % N_FRAMES, "image %d shows frame %d" % (i, k))
        # camera_info with every image, same stamp, same frame, image size, and the calibration
        # only where it is for this size.
        info_by_stamp = {c.header.stamp: c for c in infos}
        for _, m in images:
            self.assertIn(m.header.stamp, info_by_stamp, "no camera_info with stamp %s" % m.header.stamp)
            info = info_by_stamp[m.header.stamp]
            self.assertEqual(info.header.frame_id, frame_id)
            self.assertEqual((info.width, info.height), (width, height))
            self.assertEqual(list(info.K), K)

    def test_colour_folder(self):
        # PNG RGB (v, 255-v, 7) arrives as bgr8 (7, 255-v, v).
        self.check_stream(self.colour, 20.0, 40, 30, "bgr8", 3, "test_camera_optical_frame",
                          lambda k: (7, 255 - colour_value(k), colour_value(k)),
                          K=[35.0, 0.0, 19.5, 0.0, 36.0, 14.5, 0.0, 0.0, 1.0])

    def test_grey_folder(self):
        self.check_stream(self.grey, 12.5, 24, 16, "mono8", 1, "camera_optical_frame",
                          lambda k: (grey_value(k),), K=[0.0] * 9)

    def test_diagnostics(self):
        self.assertTrue(self.colour.wait_for(N_FRAMES, timeout=30.0))
        deadline = time.time() + 10.0
        seen = {}
        while time.time() < deadline and len(seen) < 2:
            for array in list(self.diagnostics):
                for s in array.status:
                    if s.name.startswith("camera_node: ") and s.level == DiagnosticStatus.OK:
                        seen[s.name] = {kv.key: kv.value for kv in s.values}
            time.sleep(0.2)
        self.assertIn("camera_node: camera/image_raw topic status", seen)
        self.assertIn("camera_node: camera source", seen)
        source = seen["camera_node: camera source"]
        self.assertEqual(source["source"], "folder")
        self.assertEqual(source["images"], str(N_FRAMES))
        self.assertEqual(source["frame_id"], "test_camera_optical_frame")

    def test_calibration_with_a_non_finite_value_is_left_out(self):
        self.assertTrue(self.calibrated.wait_for(1, timeout=30.0))
        rospy.wait_for_service("/calib/camera/set_camera_info", timeout=10.0)
        set_info = rospy.ServiceProxy("/calib/camera/set_camera_info", SetCameraInfo)

        def calibration(fy):
            c = CameraInfo(width=24, height=16, distortion_model="plumb_bob", D=[0.0] * 5)
            c.K = [30.0, 0.0, 11.5, 0.0, fy, 7.5, 0.0, 0.0, 1.0]
            c.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
            c.P = [30.0, 0.0, 11.5, 0.0, 0.0, fy, 7.5, 0.0, 0.0, 0.0, 1.0, 0.0]
            return c

        def infos_after(t, count):
            deadline = time.time() + 10.0
            while time.time() < deadline:
                with self.calibrated.lock:
                    later = [m for m in self.calibrated.infos if m.header.stamp.to_sec() > t]
                if len(later) >= count:
                    return later
                time.sleep(0.05)
            self.fail("no camera_info after the calibration was set")

        def source_status(t):
            deadline = time.time() + 10.0
            while time.time() < deadline:
                for array in list(self.diagnostics):
                    for s in array.status:
                        if s.name == "calib/camera_node: camera source" and array.header.stamp.to_sec() > t:
                            return s
                time.sleep(0.1)
            self.fail("no diagnostics from the calibrated node")

        # camera_info_manager answers the service and stores NaN as it comes.
        self.assertTrue(set_info(calibration(float("nan"))).success)
        t = rospy.get_time() + 0.2
        for info in infos_after(t, 3):
            self.assertEqual(list(info.K), [0.0] * 9)
        status = source_status(t)
        self.assertEqual(status.level, DiagnosticStatus.WARN)
        self.assertIn("K[4] is nan", status.message)
        # A good calibration for the images' size is then published, and stored whole where the
        # next start reads it (written by the node through a temporary file; camera_info_manager's
        # writer truncated the file in place and answered success whatever the write did).
        answer = set_info(calibration(31.0))
        self.assertTrue(answer.success, answer.status_message)
        path = rospy.get_param("/calib/camera_node/camera_info_url")[len("file://"):]
        self.assertIn("stored in " + path, answer.status_message)
        with open(path) as f:
            stored = yaml.safe_load(f)
        self.assertEqual(stored["camera_matrix"]["data"][4], 31.0)
        self.assertEqual((stored["image_width"], stored["image_height"]), (24, 16))
        self.assertEqual([n for n in os.listdir(os.path.dirname(path))
                          if os.path.basename(path) in n and n != os.path.basename(path)], [])
        # Into a .ini URL: the INI format, which camera_info_manager reads back there.
        rospy.wait_for_service("/calib_ini/camera/set_camera_info", timeout=10.0)
        answer = rospy.ServiceProxy("/calib_ini/camera/set_camera_info", SetCameraInfo)(calibration(31.0))
        self.assertTrue(answer.success, answer.status_message)
        ini = rospy.get_param("/calib_ini/camera_node/camera_info_url")[len("file://"):]
        with open(ini) as f:
            text = f.read()
        self.assertIn("[image]", text)
        self.assertNotIn("camera_matrix:", text)
        os.remove(ini)
        t = rospy.get_time() + 0.2
        for info in infos_after(t, 3):
            self.assertEqual(info.K[4], 31.0)
        status = source_status(t + 1.0)
        self.assertEqual(status.level, DiagnosticStatus.OK, status.message)

    def test_a_calibration_file_the_parser_cannot_read_is_refused_and_reported(self):
        for ns, reason in (("badurl", "camera_calibration_folder.yaml is a directory, not a calibration file"),
                           ("badyaml", "camera_calibration_4x3.yaml: camera_matrix is 4x3, CameraInfo's is 3x3")):
            collector = self.refused[ns]
            self.assertTrue(collector.wait_for(3, timeout=30.0), "%s: no images (did the node end?)" % ns)
            time.sleep(0.3)
            with collector.lock:
                infos = list(collector.infos)
            self.assertTrue(infos, ns)
            for info in infos:
                self.assertEqual((info.width, info.height), (24, 16))
                self.assertEqual(list(info.K), [0.0] * 9)
            deadline = time.time() + 10.0
            found = None
            while time.time() < deadline and found is None:
                for array in list(self.diagnostics):
                    for s in array.status:
                        if s.name == ns + "/camera_node: camera source" and s.level == DiagnosticStatus.WARN:
                            found = s
                time.sleep(0.2)
            self.assertIsNotNone(found, "%s: no WARN in diagnostics" % ns)
            self.assertIn("camera_info without calibration: calibration file refused", found.message)
            self.assertIn(reason, found.message)
            values = {kv.key: kv.value for kv in found.values}
            self.assertIn(reason, values["calibration"])
        # A calibration committed to the node whose ~camera_info_url is a folder: refused, as it
        # cannot be stored where the next start reads it (it was stored at the default URL, with
        # success, and lost at the next start).
        rospy.wait_for_service("/badurl/camera/set_camera_info", timeout=10.0)
        c = CameraInfo(width=24, height=16, distortion_model="plumb_bob", D=[0.0] * 5)
        c.K = [30.0, 0.0, 11.5, 0.0, 30.0, 7.5, 0.0, 0.0, 1.0]
        c.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        c.P = [30.0, 0.0, 11.5, 0.0, 0.0, 30.0, 7.5, 0.0, 0.0, 0.0, 1.0, 0.0]
        answer = rospy.ServiceProxy("/badurl/camera/set_camera_info", SetCameraInfo)(c)
        self.assertFalse(answer.success, answer.status_message)

    def test_a_folder_of_unreadable_images_is_reopened_with_a_backoff(self):
        # After its images appeared: opened, failed a round later (3 images: 2 unreadable frames,
        # then the failure), reopened after a backoff growing to 5 s: a few failures in 8 s.
        # Counted over the 8 s from 2 s after they appeared (the failed opens while the folder was
        # missing came before, as many as the test's start took).
        # (Until 11.5 s: a report stamped after 9.5 s has come by then, at one a second.)
        time.sleep(max(0.0, self.garbage_written + 11.5 - time.time()))
        key = "source failures (device lost, reopen failed, recording unreadable)"

        def counts(since):
            statuses = [s for array in list(self.diagnostics) for s in array.status
                        if s.name == "garbage/camera_node: camera source" and array.header.stamp.to_sec() > since]
            self.assertTrue(statuses, "no diagnostics from the node reading unreadable images")
            values = {kv.key: kv.value for kv in statuses[0].values}
            return statuses, int(values[key]), int(values["unreadable frames"])

        _, failures_then, unreadable_then = counts(self.garbage_written + 2.0)
        statuses, failures_now, unreadable_now = counts(self.garbage_written + 9.5)
        values = {kv.key: kv.value for kv in statuses[-1].values}
        failures = failures_now - failures_then
        self.assertGreaterEqual(failures, 1, values)
        self.assertLessEqual(failures, 8, values)
        self.assertLessEqual(unreadable_now - unreadable_then, 24, values)
        self.assertEqual(values["published"], "0")
        self.assertTrue(any(s.level == DiagnosticStatus.ERROR and "failed, opening again: " in s.message and
                            "no image readable any more" in s.message for s in statuses),
                        [s.message for s in statuses])

    def test_absent_v4l2_device_is_reported(self):
        deadline = time.time() + 15.0
        found = None
        while time.time() < deadline and found is None:
            for array in list(self.diagnostics):
                for s in array.status:
                    if s.name == "absent/camera_node: camera source":
                        found = s
            time.sleep(0.2)
        self.assertIsNotNone(found, "no diagnostics from the node without a camera")
        self.assertEqual(found.level, DiagnosticStatus.ERROR)
        self.assertIn("/dev/clothwind_no_such_camera: cannot open: No such file or directory",
                      found.message)
        values = {kv.key: kv.value for kv in found.values}
        self.assertEqual(values["source"], "v4l2")
        self.assertEqual(values["published"], "0")
        # Its diagnostics keep coming about once a second while the open backoff grows to 5 s
        # (the node used to sleep through the backoff, leaving 5 s holes a monitor reads as stale).
        time.sleep(max(0.0, self.started + 18.0 - time.time()))
        stamps = sorted(array.header.stamp.to_sec() for array in list(self.diagnostics)
                        for s in array.status if s.name == "absent/camera_node: camera source")
        late = [t for t in stamps if t > stamps[0] + 8.0]  # backoff 0.25+0.5+1+2+4 s by then
        self.assertGreaterEqual(len(late), 5, stamps)
        gaps = [b - a for a, b in zip(late, late[1:])]
        self.assertLess(max(gaps), 2.5, gaps)


if __name__ == "__main__":
    rostest.rosrun("clothwind", "camera_node_folder", CameraFolderTest, sys.argv)
