#!/usr/bin/env python3
"""Checks the clips clip_buffer_node makes from a replayed session against the bag itself.

Expected values are recomputed here from the bag's own messages (camera/image_raw stamps and
pixels, anemometer/raw MWV sentences), independently of the C++ core: the 25 fps grid anchored at
the first frame, nearest-frame choice, clips of 30 every 30 frames, the centred square crop, and
mean/std/count/circular mean over [last frame - window, last frame] of the sentences' speeds."""
import glob
import json
import math
import os
import shutil
import sys
import time
import unittest

import rosbag
import rospy
import rostest
from sensor_msgs.msg import Image
from clothwind.msg import Clip

RATE = 25.0
NUM_FRAMES = 30
STRIDE = 30
SIZE = 300
GAP_TOLERANCE = 0.1


def parse_mwv(sentence):
    """(speed m/s, angle deg) of "$WIMWV,<angle>,R,<speed>,M,A*hh" (checksum verified)."""
    body, checksum = sentence[1:].split('*')
    x = 0
    for c in body:
        x ^= ord(c)
    assert x == int(checksum, 16), sentence
    f = body.split(',')
    assert f[0].endswith('MWV') and f[4] == 'M' and f[5] == 'A', sentence
    return float(f[3]), float(f[1])


def expected_ticks(stamps):
    """[(tick stamp, index of the nearest frame)] per unbroken segment, as the resampler defines."""
    segments, seg = [], []
    anchor, k, prev = None, 0, None
    for i, t in enumerate(stamps):
        if prev is not None and t - stamps[prev] > GAP_TOLERANCE:
            segments.append(seg)
            seg, anchor = [], None
        if anchor is None:
            anchor, k = t, 0
        while anchor + k / RATE <= t + 1e-6:
            tau = anchor + k / RATE
            use_prev = prev is not None and seg and (tau - stamps[prev]) <= (t - tau) + 1e-6
            seg.append((tau, prev if use_prev else i))
            k += 1
        prev = i
    segments.append(seg)
    return segments


class ReplayTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('replay_check')
        cls.bag_path = rospy.get_param('~bag')
        cls.window = rospy.get_param('~label_window', 60.0)
        cls.expected_clips = rospy.get_param('~expected_clips', -1)        # -1: not fixed
        cls.expected_readings = rospy.get_param('~expected_readings', -1)
        cls.min_segments = rospy.get_param('~min_segments', 1)             # > 1: gaps expected
        cls.max_segments = rospy.get_param('~max_segments', 1)
        cls.record_dir = rospy.get_param('~record_dir', '')
        # What the clip buffer was told (config/clip_buffer.yaml, or the test's override).
        cls.colour = bool(rospy.get_param('/clip_buffer/colour', False))
        cls.encoding = 'bgr8' if cls.colour else 'mono8'
        cls.clips, cls.previews = [], []
        rospy.Subscriber('clips', Clip, cls.clips.append, queue_size=100)
        rospy.Subscriber('clips/preview', Image, cls.previews.append, queue_size=10)
        # The bag is read once the player plays it (/clock has started): a bag made again by the
        # player's launch-prefix (the CLI was rebuilt) must not be read in its old version.
        deadline = time.time() + 120
        while (not os.path.exists(cls.bag_path) or rospy.get_time() == 0) and time.time() < deadline:
            time.sleep(0.2)
        assert os.path.exists(cls.bag_path), 'bag %s never appeared' % cls.bag_path
        assert rospy.get_time() > 0, 'the player never started /clock'
        cls.frame_stamps, cls.readings, cls.frames = [], [], {}
        with rosbag.Bag(cls.bag_path) as bag:
            # Topic names with or without their leading slash (make-session writes them resolved,
            # as rosbag record does; older bags did not).
            topics = ['camera/image_raw', 'anemometer/raw', '/camera/image_raw', '/anemometer/raw']
            for topic, msg, t in bag.read_messages(topics=topics):
                topic = topic.lstrip('/')
                stamp = msg.header.stamp.to_sec()
                assert abs(t.to_sec() - stamp) < 1e-6, 'bag time != header stamp on ' + topic
                if topic == 'camera/image_raw':
                    cls.frame_stamps.append(stamp)
                    cls.frames[len(cls.frame_stamps) - 1] = msg
                else:
                    speed, angle = parse_mwv(msg.data)
                    cls.readings.append((stamp, speed, angle))
        cls.segments = expected_ticks(cls.frame_stamps)
        cls.expected = []  # per clip: list of (tick stamp, frame index)
        for seg in cls.segments:
            for end in range(NUM_FRAMES, len(seg) + 1, STRIDE):
                cls.expected.append(seg[end - NUM_FRAMES:end])
        # Wait for every clip: the last ones come after the clip buffer's flush_after of silence.
        deadline = time.time() + 180
        while len(cls.clips) < len(cls.expected) and time.time() < deadline and not rospy.is_shutdown():
            time.sleep(0.2)
        time.sleep(1.0)  # anything extra would show up now

    @classmethod
    def tearDownClass(cls):
        if cls.record_dir:
            shutil.rmtree(cls.record_dir, ignore_errors=True)

    def test_session_is_as_generated(self):
        self.assertGreater(len(self.frame_stamps), 500)
        if self.expected_readings >= 0:
            self.assertEqual(len(self.readings), self.expected_readings)
        # Unbroken stretches of camera frames (a hole longer than the gap tolerance splits them).
        self.assertGreaterEqual(len(self.segments), self.min_segments)
        self.assertLessEqual(len(self.segments), self.max_segments)

    def test_clip_count_and_sequence(self):
        if self.expected_clips >= 0:
            self.assertEqual(len(self.expected), self.expected_clips)
        self.assertGreater(len(self.expected), 0)
        self.assertEqual(len(self.clips), len(self.expected))
        self.assertEqual([c.sequence for c in self.clips], list(range(len(self.clips))))

    def test_frame_timing(self):
        for clip, exp in zip(self.clips, self.expected):
            self.assertEqual(clip.num_frames, NUM_FRAMES)
            self.assertAlmostEqual(clip.frame_rate, RATE)
            stamps = [s.to_sec() for s in clip.frame_stamps]
            self.assertEqual(len(stamps), NUM_FRAMES)
            for got, (tau, _) in zip(stamps, exp):
                self.assertAlmostEqual(got, tau, delta=2e-6)
            for a, b in zip(stamps, stamps[1:]):
                self.assertAlmostEqual(b - a, 1.0 / RATE, delta=2e-6)
            self.assertAlmostEqual(stamps[-1] - stamps[0], (NUM_FRAMES - 1) / RATE, delta=2e-6)
            self.assertAlmostEqual(clip.header.stamp.to_sec(), stamps[0], delta=2e-6)
            self.assertEqual(clip.header.frame_id, 'camera_optical_frame')
        # Back to back within an unbroken stretch: each clip starts one frame period after the
        # previous one ends; across a gap, later than that (never stitched over the hole).
        for a, b in zip(self.clips, self.clips[1:]):
            self.assertGreaterEqual((b.frame_stamps[0] - a.frame_stamps[-1]).to_sec(), 1.0 / RATE - 2e-6)
            if len(self.segments) == 1:
                self.assertAlmostEqual((b.frame_stamps[0] - a.frame_stamps[-1]).to_sec(), 1.0 / RATE, delta=2e-6)
        # No clip spans a hole in the camera stream.
        holes = [(a, b) for a, b in zip(self.frame_stamps, self.frame_stamps[1:]) if b - a > GAP_TOLERANCE]
        for clip in self.clips:
            start, end = clip.frame_stamps[0].to_sec(), clip.frame_stamps[-1].to_sec()
            for a, b in holes:
                self.assertFalse(start <= a and b <= end, 'clip %d spans the hole %.3f..%.3f' % (clip.sequence, a, b))

    def test_frames_are_cropped_grey_and_resized(self):
        # mono8 clips, or bgr8 with the clip buffer's ~colour; either way the luma is checked.
        channels = 3 if self.colour else 1
        for clip, exp in zip(self.clips, self.expected):
            self.assertEqual((clip.width, clip.height, clip.encoding), (SIZE, SIZE, self.encoding))
            self.assertEqual(len(clip.data), NUM_FRAMES * SIZE * SIZE * channels)
            self.assertEqual((clip.roi.x_offset, clip.roi.y_offset, clip.roi.width), (40, 0, 240))
            self.assertEqual((clip.source_width, clip.source_height), (320, 240))
            # The first frame's mean brightness is that of the centred 240x240 crop of the nearest
            # camera frame in luma (resizing keeps the mean).
            src = self.frames[exp[0][1]]
            self.assertEqual(src.encoding, 'bgr8')
            data, total = src.data, 0.0
            for r in range(0, 240):
                row = r * src.step
                for c in range(40, 280):
                    p = row + 3 * c
                    total += 0.114 * data[p] + 0.587 * data[p + 1] + 0.299 * data[p + 2]
            frame0 = luma(clip.data[:SIZE * SIZE * channels], channels)
            self.assertAlmostEqual(sum(frame0) / (SIZE * SIZE), total / (240 * 240), delta=1.0)
            # The flag moves within a clip.
            middle = luma(clip.data[15 * SIZE * SIZE * channels:16 * SIZE * SIZE * channels], channels)
            self.assertGreater(sum(abs(a - b) for a, b in zip(frame0, middle)), SIZE * SIZE)

    def test_labels_match_the_anemometer_by_stamp(self):
        self.assertGreater(len(self.clips), 0)
        for clip in self.clips:
            end = clip.frame_stamps[-1].to_sec()
            inside = [(s, v, a) for s, v, a in self.readings if end - self.window <= s <= end]
            self.assertAlmostEqual(clip.label_window, self.window)
            self.assertEqual(clip.wind_count, len(inside), 'clip %d' % clip.sequence)
            mean = sum(v for _, v, _ in inside) / len(inside)
            std = math.sqrt(sum((v - mean) ** 2 for _, v, _ in inside) / len(inside))
            self.assertAlmostEqual(clip.wind_mean, mean, delta=1e-9)
            self.assertAlmostEqual(clip.wind_std, std, delta=1e-9)
            # MWV angles are where the wind comes FROM, clockwise: direction = pi - angle (msg docs).
            sx = sum(math.sin(math.pi - math.radians(a)) for _, _, a in inside)
            cx = sum(math.cos(math.pi - math.radians(a)) for _, _, a in inside)
            diff = math.remainder(clip.wind_direction_mean - math.atan2(sx, cx), 2 * math.pi)
            self.assertLess(abs(diff), 1e-6)
        # The label drifts with the generated wind: not every clip has the same one.
        self.assertGreater(len({round(c.wind_mean, 6) for c in self.clips}), 1)

    def test_recorded_dataset(self):
        if not self.record_dir:
            self.skipTest('not recording')
        # The clip buffer rewrites the index at most every ~index_interval, and once input has
        # stopped for ~flush_after: the last clips are listed within seconds of the last publish.
        deadline = time.time() + 15
        while True:
            with open(os.path.join(self.record_dir, 'index.json')) as f:
                index = json.load(f)
            if len(index['clips']) >= len(self.clips) or time.time() > deadline:
                break
            time.sleep(0.2)
        self.assertEqual(index['format'], 'clothwind-dataset')
        self.assertEqual(len(index['clips']), len(self.clips))
        # No temporaries left (the writer's lock file, .lock, stays: it is held, not written).
        self.assertEqual([p for p in glob.glob(os.path.join(self.record_dir, '.*')) if not p.endswith('/.lock')], [])
        for entry, clip in zip(index['clips'], self.clips):
            folder = os.path.join(self.record_dir, entry['name'])
            with open(os.path.join(folder, 'label.json')) as f:
                label = json.load(f)
            self.assertEqual(label['sequence'], clip.sequence)
            self.assertEqual(label['num_frames'], NUM_FRAMES)
            self.assertAlmostEqual(label['wind']['mean'], clip.wind_mean, delta=1e-9)
            self.assertEqual(label['wind']['count'], clip.wind_count)
            self.assertEqual(label['roi'], {'x': 40, 'y': 0, 'size': 240})
            self.assertEqual(label['encoding'], 'rgb8' if self.colour else 'mono8')
            for got, want in zip(label['frame_stamps'], clip.frame_stamps):
                self.assertAlmostEqual(got, want.to_sec(), delta=2e-6)
            for i in range(NUM_FRAMES):
                with open(os.path.join(folder, '%03d.jpg' % i), 'rb') as f:
                    self.assertEqual(f.read(2), b'\xff\xd8')  # JPEG start of image

    def test_preview_is_published(self):
        self.assertGreater(len(self.previews), 0)
        p = self.previews[-1]
        self.assertEqual((p.width, p.height, p.encoding), (SIZE, SIZE, self.encoding))


def luma(data, channels):
    """The grey of one frame's bytes: as they are for mono8, BT.601 of B, G, R for bgr8."""
    if channels == 1:
        return list(data)
    return [0.114 * data[i] + 0.587 * data[i + 1] + 0.299 * data[i + 2] for i in range(0, len(data), 3)]


if __name__ == '__main__':
    rostest.rosrun('clothwind', 'replay_clips', ReplayTest, sys.argv)
