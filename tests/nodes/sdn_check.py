#!/usr/bin/env python3
"""rostest for sdn_node: publishes synthetic clips (one malformed) and checks the estimates,
their trailing mean, the diagnostics and the spectral images."""
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import threading
import unittest

import rospy
import rostest
from clothwind.msg import Clip, WindEstimate
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sensor_msgs.msg import Image


def make_clip(seq, start, size, frequency, wind_mean, count=30, rate=25.0, encoding="mono8", flag=None,
              wind_direction=0.0, wind_frame="", frame="camera_optical"):
    clip = Clip()
    clip.header.frame_id = frame
    clip.header.stamp = start
    clip.sequence = seq
    clip.frame_stamps = [start + rospy.Duration.from_sec(i / rate) for i in range(count)]
    clip.frame_rate = rate
    clip.num_frames = count
    clip.height = size
    clip.width = size
    clip.encoding = encoding
    # Vertical stripes travelling at `frequency` Hz, brightness 40..220; in bgr8 grey stripes
    # (equal channels) or, with "bgr8-red-green", red against green of one grey. With flag
    # "right" (mono8 only) the stripes grow from nothing at the left edge to full at the right, as
    # a flag's ripples grow from the pole to the fly end; "left" is the mirror image of that clip.
    channels = 1 if encoding == "mono8" else 3
    clip.encoding = "mono8" if channels == 1 else "bgr8"
    data = bytearray(count * size * size * channels)
    wavelength = size / 6.0
    for t in range(count):
        row = bytearray()
        for x in range(size):
            amplitude = 90 * (x / size if flag else 1.0)
            v = int(130 + amplitude * math.sin(2 * math.pi * (frequency * t / rate - x / wavelength)))
            if encoding == "bgr8-red-green":
                row += bytes((0, 150, 0) if v > 130 else (0, 0, 255))  # grey 88 and 76
            else:
                row += bytes([v] * channels)
        if flag == "left":
            row = row[::-1]
        line = size * channels
        base = t * size * line
        for y in range(size):
            data[base + y * line: base + (y + 1) * line] = row
    clip.data = bytes(data)
    clip.source_width = size
    clip.source_height = size
    clip.label_window = 60.0
    clip.wind_mean = wind_mean
    clip.wind_std = 0.3
    clip.wind_count = 60 if not math.isnan(wind_mean) else 0
    clip.wind_direction_mean = wind_direction
    clip.wind_direction_frame_id = wind_frame
    return clip


def read_pgm(path):
    """(width, height, bytes) of a binary 8-bit PGM (P5) file."""
    with open(path, "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P5" or int(fields[3]) != 255:
        raise ValueError("%s: expected an 8-bit binary PGM (P5, maxval 255)" % path)
    width, height = int(fields[1]), int(fields[2])
    pixels = data[pos + 1:pos + 1 + width * height]
    if len(pixels) != width * height:
        raise ValueError("%s: %d bytes of pixels, expected %d" % (path, len(pixels), width * height))
    return width, height, pixels


def flagsim_frames(size=64, count=30):
    """`count` frames (size x size mono8, each bytes) of a flag rendered by FlagSim (clothwind
    make-dataset, seed 1: 7.2 m/s): a real flag flying right of its
    pole, as every FlagSim camera films it. Rendered here, so the test needs no stored data."""
    here = os.path.dirname(os.path.abspath(__file__))
    cli = subprocess.run(["bash", "-c", 'source "$1" && echo "$cli"', "sdn_check",
                          os.path.join(here, "clothwind_cli.sh")],
                         check=True, stdout=subprocess.PIPE, universal_newlines=True).stdout.strip()
    out = tempfile.mkdtemp(prefix="sdn_check_flagsim_")
    try:
        subprocess.run([cli, "make-dataset", "--kind", "flag", "--count", "1", "--views", "1", "--size", str(size),
                        "--frames", str(count), "--format", "pgm", "--seed", "1", "--jobs", "1", "--out", out],
                       check=True, stdout=subprocess.DEVNULL)
        example = sorted(d for d in os.listdir(out) if d.startswith("flag-"))[0]
        frames = []
        for t in range(count):
            width, height, pixels = read_pgm(os.path.join(out, example, "%03d.pgm" % t))
            if (width, height) != (size, size):
                raise ValueError("FlagSim frame %d is %dx%d, expected %dx%d" % (t, width, height, size, size))
            frames.append(pixels)
        return frames
    finally:
        shutil.rmtree(out, ignore_errors=True)


def frames_clip(seq, start, frames, size, mirrored=False, rate=25.0, wind_mean=4.0):
    """A mono8 Clip of `frames` (size x size bytes each), mirrored left to right when asked."""
    clip = make_clip(seq, start, size, 3.0, wind_mean, count=len(frames), rate=rate)
    data = bytearray()
    for f in frames:
        for y in range(size):
            row = f[y * size:(y + 1) * size]
            data += row[::-1] if mirrored else row
    clip.data = bytes(data)
    return clip


def loaded(status):
    """Whether a diagnostic says the node's model loaded: OK, or the WARN of a loaded node that has
    had no clip for 10 s (no ERROR "no model")."""
    return status.level == DiagnosticStatus.OK or (
        status.level == DiagnosticStatus.WARN and "no clip received yet" in status.message)


class SdnNodeTest(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.estimates = []
        self.means = []
        self.statuses = []
        self.colour_statuses = []
        self.colour_estimates = []
        self.power = []
        self.frequency = []
        rospy.Subscriber("wind/estimate", WindEstimate, self.on_estimate, queue_size=100)
        rospy.Subscriber("wind/estimate_mean", WindEstimate, lambda m: self.append(self.means, m), queue_size=100)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=100)
        rospy.Subscriber("sdn/power", Image, lambda m: self.append(self.power, m), queue_size=10)
        rospy.Subscriber("sdn/frequency", Image, lambda m: self.append(self.frequency, m), queue_size=10)
        self.pub = rospy.Publisher("clips", Clip, queue_size=100)
        rospy.Subscriber("colour/wind/estimate", WindEstimate, lambda m: self.append(self.colour_estimates, m),
                         queue_size=10)
        self.colour_pub = rospy.Publisher("colour/clips", Clip, queue_size=10)
        self.no_flip_statuses = []
        self.no_flip_estimates = []
        rospy.Subscriber("no_flip/wind/estimate", WindEstimate, lambda m: self.append(self.no_flip_estimates, m),
                         queue_size=10)
        self.no_flip_pub = rospy.Publisher("no_flip/clips", Clip, queue_size=10)
        self.wind_statuses = []
        self.wind_estimates = []
        rospy.Subscriber("wind/wind/estimate", WindEstimate, lambda m: self.append(self.wind_estimates, m),
                         queue_size=10)
        self.wind_pub = rospy.Publisher("wind/clips", Clip, queue_size=10)
        self.tf_statuses = []
        self.tf_estimates = []
        rospy.Subscriber("tf/wind/estimate", WindEstimate, lambda m: self.append(self.tf_estimates, m),
                         queue_size=10)
        self.tf_pub = rospy.Publisher("tf/clips", Clip, queue_size=10)
        self.tf_messages = []
        rospy.Subscriber("/tf", rospy.AnyMsg, lambda m: self.append(self.tf_messages, m), queue_size=10)
        self.judge_statuses = []
        self.judge_estimates = []
        rospy.Subscriber("judge/wind/estimate", WindEstimate, lambda m: self.append(self.judge_estimates, m),
                         queue_size=10)
        self.judge_pub = rospy.Publisher("judge/clips", Clip, queue_size=10)
        self.bad_judge_statuses = []
        self.bad_judge_estimates = []
        rospy.Subscriber("bad_judge/wind/estimate", WindEstimate,
                         lambda m: self.append(self.bad_judge_estimates, m), queue_size=10)
        self.bad_judge_pub = rospy.Publisher("bad_judge/clips", Clip, queue_size=10)

    def append(self, where, msg):
        with self.lock:
            where.append(msg)

    def on_estimate(self, msg):
        self.append(self.estimates, msg)

    def on_diagnostics(self, msg):
        with self.lock:
            for s in msg.status:
                if s.name.startswith("sdn:"):
                    self.statuses.append(s)
                elif s.name.startswith("colour/"):
                    self.colour_statuses.append(s)
                elif s.name.startswith("no_flip/"):
                    self.no_flip_statuses.append(s)
                elif s.name.startswith("wind/"):
                    self.wind_statuses.append(s)
                elif s.name.startswith("tf/"):
                    self.tf_statuses.append(s)
                elif s.name.startswith("judge/"):
                    self.judge_statuses.append(s)
                elif s.name.startswith("bad_judge/"):
                    self.bad_judge_statuses.append(s)

    def wait_for(self, predicate, timeout, what):
        deadline = rospy.get_time() + timeout
        while not rospy.is_shutdown() and rospy.get_time() < deadline:
            with self.lock:
                if predicate():
                    return
            rospy.sleep(0.1)
        self.fail("timed out waiting for " + what)

    def wait_for_count(self, statuses, key, count, what):
        """The key-value pairs of the first of `statuses` whose `key` counts `count`."""
        def find():
            for s in statuses:
                values = {kv.key: kv.value for kv in s.values}
                if values.get(key) == str(count):
                    return values
            return None

        self.wait_for(lambda: find() is not None, 10, "a diagnostic counting %d %s" % (count, what))
        with self.lock:
            return find()

    def wait_for_turned(self, statuses, count):
        return self.wait_for_count(statuses, "clips turned round (flag flying left)", count, "clips turned round")

    def wait_for_estimates(self, statuses, count):
        return self.wait_for_count(statuses, "estimates", count, "estimates")

    def test_estimates(self):
        n = rospy.get_param("~clips", 6)
        malformed_after = rospy.get_param("~malformed_after", 2)
        size = rospy.get_param("~size", 300)
        frequency = rospy.get_param("~stripe_frequency", 5.0)
        # The node subscribes once its model is loaded and warmed up (it is made first).
        self.wait_for(lambda: self.pub.get_num_connections() > 0, 120, "sdn_node to subscribe to clips")
        self.wait_for(lambda: any(loaded(s) for s in self.statuses), 60, "a diagnostic saying the model loaded")
        # Wait until the node sees our image subscribers, so it computes the maps.
        rospy.sleep(1.0)
        start = rospy.Time(1700000000, 0)
        sent = []
        for i in range(n):
            if i == malformed_after:
                bad = make_clip(1000, start, 16, frequency, 4.0)
                bad.data = bad.data[:-5]  # wrong data length
                self.pub.publish(bad)
            wind = float("nan") if i == 1 else 2.0 + i
            # Each clip its own stripe frequency, so the estimates (and their means) differ.
            clip = make_clip(i, start + rospy.Duration.from_sec(2.0 * i), size, frequency + 0.5 * i, wind)
            sent.append(clip)
            self.pub.publish(clip)
        self.wait_for(lambda: len(self.estimates) >= n and len(self.means) >= n, 90, "%d estimates and means" % n)
        rospy.sleep(1.0)
        with self.lock:
            estimates = list(self.estimates)
            means = list(self.means)
        self.assertEqual(len(estimates), n, "one estimate per good clip, none for the malformed one")
        by_seq = {e.clip_sequence: e for e in estimates}
        self.assertEqual(sorted(by_seq), list(range(n)))
        for clip in sent:
            e = by_seq[clip.sequence]
            self.assertEqual(e.header.stamp, clip.frame_stamps[-1])
            self.assertEqual(e.clip_start, clip.frame_stamps[0])
            self.assertEqual(e.clip_end, clip.frame_stamps[-1])
            self.assertEqual(e.header.frame_id, "camera_optical")
            if math.isnan(clip.wind_mean):
                self.assertTrue(math.isnan(e.reference_speed))
            else:
                self.assertAlmostEqual(e.reference_speed, clip.wind_mean, places=9)
            self.assertTrue(math.isfinite(e.speed))
            self.assertTrue(math.isfinite(e.speed_std) and e.speed_std > 0)
            self.assertTrue(0 < e.latency < 30, e.latency)
            self.assertIn("sdn-k3", e.model)
        # The trailing mean: one per estimate, stamped like it, over the clips that ended within
        # ~mean_window seconds (clips end 2 s apart), its clip_start the oldest one's first frame.
        window = rospy.get_param("~mean_window", 5.0)
        self.assertEqual(len(means), n)
        for m in means:
            e = by_seq[m.clip_sequence]
            self.assertEqual(m.header.stamp, e.header.stamp)
            self.assertEqual(m.clip_end, e.clip_end)
            inside = [o for o in estimates if m.clip_end - rospy.Duration.from_sec(window) < o.clip_end <= m.clip_end]
            self.assertAlmostEqual(m.speed, sum(o.speed for o in inside) / len(inside), places=6)
            self.assertAlmostEqual(m.speed_std, math.sqrt(sum(o.speed_std ** 2 for o in inside) / len(inside)), places=6)
            self.assertEqual(m.clip_start, min(o.clip_start for o in inside))
            self.assertIn("trailing %.0f s mean of %d clips" % (window, len(inside)), m.model)
            self.assertEqual((m.mean_window, m.mean_count), (window, len(inside)))
            self.assertEqual((e.mean_window, e.mean_count), (0.0, 0))  # one clip's estimate
            if math.isnan(e.reference_speed):
                self.assertTrue(math.isnan(m.reference_speed))
            else:
                self.assertEqual(m.reference_speed, e.reference_speed)
        self.assertGreater(len(set(round(m.speed, 6) for m in means)), 1, "the means follow the estimates")
        # The malformed clip raised an ERROR naming the field, and the node carried on.
        self.wait_for(lambda: any(s.level == DiagnosticStatus.ERROR and "data" in s.message for s in self.statuses),
                      10, "an ERROR diagnostic for the malformed clip")
        # ...and its stray number (1000, between clips 1 and 2) made no clip missing: counted before
        # the checks, it read as 998 clips missing.
        values = self.wait_for_estimates(self.statuses, n)
        self.assertEqual(values["clips missing from the sequence (queue or upstream)"], "0", values)
        self.assertEqual(values["malformed clips"], "1", values)
        # Spectral images: colour-mapped at the model's input size, stamped like the estimates.
        self.wait_for(lambda: len(self.power) > 0 and len(self.frequency) > 0, 10, "sdn/power and sdn/frequency")
        with self.lock:
            freq_img = self.frequency[-1]
            power_img = self.power[-1]
        self.assertEqual(freq_img.encoding, "bgr8")
        self.assertEqual((freq_img.width, freq_img.height), (64, 64))
        self.assertIn(freq_img.header.stamp, [c.frame_stamps[-1] for c in sent])
        self.assertEqual(power_img.encoding, "bgr8")
        # Every pixel oscillates at the same frequency: the frequency image is one colour.
        pixels = set(bytes(freq_img.data[i:i + 3]) for i in range(0, len(freq_img.data), 3))
        self.assertEqual(len(pixels), 1, "uniform stripe frequency gives a uniform frequency map")
        # ...and not the colour of 0 Hz or of Nyquist (a map of zeros, or of garbage clipped to the
        # top, is uniform too): OpenCV's jet is (128, 0, 0) BGR at 0 and (0, 0, 128) at the top.
        self.assertNotIn(pixels.pop(), (bytes([128, 0, 0]), bytes([0, 0, 128])), "the frequency map's colour")
        status = [s for s in self.statuses][-1]
        keys = {kv.key: kv.value for kv in status.values}
        self.assertIn("latency mean [s]", keys)
        self.assertIn("rate [clips/s]", keys)
        # A bgr8 clip of grey stripes is, to a grey model, the mono8 clip of the same stripes.
        later = start + rospy.Duration.from_sec(1000.0)
        self.pub.publish(make_clip(200, later, size, frequency, 4.0))
        self.pub.publish(make_clip(201, later, size, frequency, 4.0, encoding="bgr8"))
        self.wait_for(lambda: {200, 201} <= {e.clip_sequence for e in self.estimates}, 30, "the mono8 and bgr8 pair")
        with self.lock:
            pair = {e.clip_sequence: e.speed for e in self.estimates if e.clip_sequence >= 200}
        self.assertAlmostEqual(pair[200], pair[201], places=6)
        # A frozen camera (one frame republished, stripes at 0 Hz): no motion, so no estimate,
        # where the network's answer looked like any other; said in the diagnostics. The next
        # clip that moves is estimated.
        self.pub.publish(make_clip(300, later + rospy.Duration.from_sec(10.0), size, 0.0, 4.0))
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and "clip 300 has no motion" in s.message
                                  for s in self.statuses), 30, "a WARN for the clip without motion")
        self.pub.publish(make_clip(301, later + rospy.Duration.from_sec(12.0), size, frequency, 4.0))
        self.wait_for(lambda: 301 in {e.clip_sequence for e in self.estimates}, 30, "the moving clip after it")
        with self.lock:
            self.assertNotIn(300, {e.clip_sequence for e in self.estimates})
        values = self.wait_for_estimates(self.statuses, len(self.estimates))
        self.assertEqual(values["clips without motion (not estimated)"], "1", values)
        # A covered lens (sensor noise of a few grey levels on black): it moves, but shows no scene,
        # so no estimate, where the network read some wind into the noise; said likewise.
        covered = make_clip(302, later + rospy.Duration.from_sec(14.0), size, frequency, 4.0)
        noise_levels = bytes(1 + b % 7 for b in range(256))  # 1..7: a dark level 4, spread 2
        covered.data = random.Random(7).randbytes(len(covered.data)).translate(noise_levels)
        self.pub.publish(covered)
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and "clip 302 shows no scene" in s.message
                                  for s in self.statuses), 30, "a WARN for the clip without a scene")
        self.pub.publish(make_clip(303, later + rospy.Duration.from_sec(16.0), size, frequency, 4.0))
        self.wait_for(lambda: 303 in {e.clip_sequence for e in self.estimates}, 30, "the clip of a scene after it")
        with self.lock:
            self.assertNotIn(302, {e.clip_sequence for e in self.estimates})
        values = self.wait_for_estimates(self.statuses, len(self.estimates))
        self.assertEqual(values["clips without a scene (not estimated)"], "1", values)

    def test_colour_model(self):
        """A model trained with --colour: bgr8 clips get estimates, a mono8 clip an ERROR that names
        the clip buffer's ~colour parameter (the grey cannot be coloured back)."""
        size = rospy.get_param("~size", 300)
        self.wait_for(lambda: self.colour_pub.get_num_connections() > 0, 120, "the colour sdn_node to subscribe")
        self.wait_for(lambda: any(loaded(s) for s in self.colour_statuses), 60,
                      "a diagnostic from the colour node saying the model loaded")
        start = rospy.Time(1700000000, 0)
        self.colour_pub.publish(make_clip(0, start, size, 3.0, 4.0))
        self.wait_for(lambda: any(s.level == DiagnosticStatus.ERROR and "~colour" in s.message
                                  for s in self.colour_statuses), 30, "an ERROR naming ~colour for the grey clip")
        self.colour_pub.publish(make_clip(1, start + rospy.Duration.from_sec(2.0), size, 3.0, 4.0,
                                          encoding="bgr8-red-green"))
        self.wait_for(lambda: len(self.colour_estimates) > 0, 30, "an estimate of the bgr8 clip")
        with self.lock:
            e = self.colour_estimates[0]
        self.assertEqual(e.clip_sequence, 1, "no estimate for the grey clip")
        self.assertTrue(math.isfinite(e.speed))
        self.assertIn("-ycc", e.model)

    def test_no_flip_model(self):
        """A model trained with --no-flip, ~flag_flies unset (auto): a WARN naming ~flag_flies, and a
        clip of a flag flying left is turned round, so it gets the estimate of its mirror image."""
        size = 256  # 4 pixels to each of the model's 64: area resizing keeps a mirror image exactly mirrored
        self.wait_for(lambda: self.no_flip_pub.get_num_connections() > 0, 120, "the no-flip sdn_node to subscribe")
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and "~flag_flies" in s.message
                                  for s in self.no_flip_statuses), 60, "a WARN naming ~flag_flies")
        start = rospy.Time(1700000000, 0)
        # The flag flying right first: read as filmed (a judge that had the sides the wrong way
        # round would turn it, and turning either clip alone makes the two estimates equal).
        self.no_flip_pub.publish(make_clip(0, start, size, 3.0, 4.0, flag="right"))
        self.wait_for(lambda: len(self.no_flip_estimates) >= 1, 30, "the estimate of the right-flying clip")
        values = self.wait_for_estimates(self.no_flip_statuses, 1)
        self.assertEqual(values["clips turned round (flag flying left)"], "0", values)
        self.no_flip_pub.publish(make_clip(1, start + rospy.Duration.from_sec(2.0), size, 3.0, 4.0, flag="left"))
        self.wait_for(lambda: len(self.no_flip_estimates) >= 2, 30, "estimates of both clips")
        values = self.wait_for_turned(self.no_flip_statuses, 1)
        with self.lock:
            speeds = {e.clip_sequence: e.speed for e in self.no_flip_estimates}
        self.assertEqual(values["flag flies"], "auto")
        self.assertAlmostEqual(speeds[0], speeds[1], places=5)

    def test_no_flip_model_told_by_the_wind(self):
        """~flag_flies wind, the camera looking along +y of the anemometer's frame (+x on its right):
        a flag flying right under a wind toward +x stays, one flying left under a wind toward -x
        is turned round, and a wind along the optical axis keeps the way last known."""
        size = 256
        self.wait_for(lambda: self.wind_pub.get_num_connections() > 0, 120, "the wind-told sdn_node to subscribe")
        start = rospy.Time(1700000000, 0)
        # A clip whose wind has no direction (cups without a vane): read as filmed, and a WARN that
        # the wind has not said the way (it said OK).
        self.wind_pub.publish(make_clip(0, start, size, 3.0, 4.0, flag="right", wind_direction=float("nan")))
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and "no clip's wind has said" in s.message
                                  for s in self.wind_statuses), 30, "a WARN that the wind has not said the way")
        for seq, flag, direction in ((1, "right", 0.0), (2, "left", math.pi), (3, "left", math.pi / 2)):
            self.wind_pub.publish(make_clip(seq, start + rospy.Duration.from_sec(2.0 * seq), size, 3.0, 4.0,
                                            flag=flag, wind_direction=direction))
        self.wait_for(lambda: len(self.wind_estimates) >= 4, 30, "estimates of the four clips")
        with self.lock:
            del self.wind_statuses[:]
        self.wait_for(lambda: any(s.level == DiagnosticStatus.OK for s in self.wind_statuses), 30,
                      "an OK diagnostic from the wind-told node (no WARN: it is told the way)")
        values = self.wait_for_turned(self.wind_statuses, 2)
        with self.lock:
            speeds = {e.clip_sequence: e.speed for e in self.wind_estimates}
        self.assertEqual(values["flag flies"], "wind: left")
        self.assertEqual(values["clips with the wind end-on or unknown"], "2")
        # ~camera_heading given: used, not tf (this node has no /tf subscription).
        self.assertEqual(values["camera heading"], "~camera_heading 1.570796 rad")
        # ~fly_judge beside ~flag_flies wind loads but is never asked: said, not silently kept.
        self.assertTrue(values["fly judge (for auto)"].endswith("models/fly_judge.pt (not asked: ~flag_flies is wind)"),
                        values)
        self.assertAlmostEqual(speeds[1], speeds[2], places=5)
        self.assertAlmostEqual(speeds[1], speeds[3], places=5)

    def test_no_flip_model_told_by_the_wind_and_the_camera_pose_in_tf(self):
        """~flag_flies wind, ~camera_heading unset: the pose of the clips' camera comes from tf, a
        camera facing 60 deg of the anemometer's frame mounted upside down (its picture's right
        toward 150 deg). A flag flying left under a wind toward +x is turned round, where a level
        camera facing the same way would read it as filmed; one flying right under a wind toward
        -x stays; a wind along the axis (60 deg) keeps the way: with the transform taken the wrong
        way round (heading -90 deg) it would not be end-on. A clip naming no wind frame, or one tf does not know, keeps
        the way too, with a WARN saying why."""
        size = 256
        self.wait_for(lambda: self.tf_pub.get_num_connections() > 0, 120, "the tf-told sdn_node to subscribe")
        self.wait_for(lambda: len(self.tf_messages) > 0, 30, "the camera's transform on /tf")
        start = rospy.Time(1700000000, 0)
        self.tf_pub.publish(make_clip(0, start, size, 3.0, 4.0, flag="right", wind_direction=0.0))
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and "the clip names no wind direction frame" in s.message
                                  for s in self.tf_statuses), 30, "a WARN that the clip names no wind frame")
        for seq, flag, direction in ((1, "left", 0.0), (2, "right", math.pi), (3, "right", math.pi / 3)):
            self.tf_pub.publish(make_clip(seq, start + rospy.Duration.from_sec(2.0 * seq), size, 3.0, 4.0,
                                          flag=flag, wind_direction=direction, wind_frame="anemometer"))
        self.wait_for(lambda: len(self.tf_estimates) >= 4, 30, "estimates of the four clips")
        with self.lock:
            del self.tf_statuses[:]
        self.wait_for(lambda: any(s.level == DiagnosticStatus.OK for s in self.tf_statuses), 30,
                      "an OK diagnostic from the tf-told node")
        values = self.wait_for_turned(self.tf_statuses, 1)
        with self.lock:
            speeds = {e.clip_sequence: e.speed for e in self.tf_estimates}
        self.assertEqual(values["flag flies"], "wind: right")
        self.assertEqual(values["camera heading"], "-120.0 deg (tf: 'camera_optical' in 'anemometer')")
        self.assertEqual(values["clips with the wind end-on or unknown"], "2")
        self.assertAlmostEqual(speeds[0], speeds[1], places=5)
        self.assertAlmostEqual(speeds[0], speeds[2], places=5)
        self.assertAlmostEqual(speeds[0], speeds[3], places=5)
        # A frame tf has never heard of: the way kept (this left-flying clip is not turned), said.
        self.tf_pub.publish(make_clip(4, start + rospy.Duration.from_sec(8.0), size, 3.0, 4.0, flag="left",
                                      wind_direction=0.0, wind_frame="elsewhere"))
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and
                                  "no transform from 'camera_optical' to 'elsewhere' in tf" in s.message
                                  for s in self.tf_statuses), 30, "a WARN that tf has no such transform")
        values = self.wait_for_estimates(self.tf_statuses, 5)
        self.assertEqual(values["clips turned round (flag flying left)"], "1")
        self.assertEqual(values["clips with the wind end-on or unknown"], "3")
        # A camera on its side (its picture's right pointing up): no way to tell, kept, said.
        self.tf_pub.publish(make_clip(5, start + rospy.Duration.from_sec(10.0), size, 3.0, 4.0, flag="left",
                                      wind_direction=0.0, wind_frame="anemometer", frame="camera_on_its_side"))
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and
                                  "camera 'camera_on_its_side' lies on its side" in s.message
                                  for s in self.tf_statuses), 30, "a WARN that the camera lies on its side")
        values = self.wait_for_estimates(self.tf_statuses, 6)
        self.assertEqual(values["clips turned round (flag flying left)"], "1")
        self.assertEqual(values["clips with the wind end-on or unknown"], "4")

    def test_no_flip_model_with_the_fly_judge(self):
        """~fly_judge, the shipped judge: no WARN (the judge, not the motion cues, tells the way),
        the judge named in the diagnostics, and a flag rendered by FlagSim read as filmed (it flies
        right) while its mirror image (flying left) is turned round. The judge learned FlagSim's
        flags, not the hand-drawn stripes of make_clip: it reads those the wrong way round."""
        size = 64  # the judge's and the model's side: no resizing, so the mirror image stays exact
        frames = flagsim_frames(size)
        self.wait_for(lambda: self.judge_pub.get_num_connections() > 0, 120, "the judged sdn_node to subscribe")
        # Loaded for over 10 s and no clip yet: a WARN that says so (it said OK "estimating").
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and "no clip received yet" in s.message
                                  for s in self.judge_statuses), 60, "a WARN that no clip has come yet")
        start = rospy.Time(1700000000, 0)
        self.judge_pub.publish(frames_clip(0, start, frames, size))
        self.wait_for(lambda: len(self.judge_estimates) >= 1, 30, "the estimate of the FlagSim clip")
        values = self.wait_for_estimates(self.judge_statuses, 1)
        self.assertEqual(values["clips turned round (flag flying left)"], "0", values)
        self.assertEqual(values["clips the fly judge could not tell (the last way kept)"], "0", values)
        self.judge_pub.publish(frames_clip(1, start + rospy.Duration.from_sec(2.0), frames, size, mirrored=True))
        self.wait_for(lambda: len(self.judge_estimates) >= 2, 30, "estimates of both clips")
        with self.lock:
            del self.judge_statuses[:]
        self.wait_for(lambda: any(s.level == DiagnosticStatus.OK for s in self.judge_statuses), 30,
                      "an OK diagnostic from the node with a fly judge once clips come")
        values = self.wait_for_turned(self.judge_statuses, 1)
        self.assertEqual(values["clips the fly judge could not tell (the last way kept)"], "0", values)
        with self.lock:
            speeds = {e.clip_sequence: e.speed for e in self.judge_estimates}
        self.assertEqual(values["flag flies"], "auto")
        self.assertTrue(values["fly judge (for auto)"].endswith("models/fly_judge.pt"), values)
        self.assertAlmostEqual(speeds[0], speeds[1], places=5)

    def test_fly_judge_that_does_not_load(self):
        """A ~fly_judge file that is not there: a WARN saying so, and the clips still estimated."""
        size = 64
        self.wait_for(lambda: self.bad_judge_pub.get_num_connections() > 0, 120,
                      "the badly judged sdn_node to subscribe")
        self.wait_for(lambda: any(s.level == DiagnosticStatus.WARN and "~fly_judge did not load" in s.message
                                  and "/nonexistent/fly_judge" in s.message for s in self.bad_judge_statuses), 60,
                      "a WARN naming the judge file that did not load")
        start = rospy.Time(1700000000, 0)
        self.bad_judge_pub.publish(make_clip(0, start, size, 3.0, 4.0, flag="right"))
        self.wait_for(lambda: len(self.bad_judge_estimates) >= 1, 30, "an estimate all the same")

        def latest():
            with self.lock:
                s = self.bad_judge_statuses[-1]
            return s, {kv.key: kv.value for kv in s.values}

        status, values = latest()
        self.assertIn("~queue_size must be >= 1", values["parameter errors"])
        self.assertIn("~end_on_angle must be 0 to 90", values["parameter errors"])
        # ~camera_heading without ~flag_flies wind is read but would go unused: said, not silent.
        self.assertIn("~camera_heading is set but ~flag_flies is '', not wind", values["parameter errors"])
        # A clip resampled at another rate than the model's is refused, and the ERROR stays on the
        # periodic diagnostics (not only the one published at once) until a good clip comes.
        self.bad_judge_pub.publish(make_clip(1, start + rospy.Duration.from_sec(2.0), size, 3.0, 4.0, rate=30.0))
        self.wait_for(lambda: any(s.level == DiagnosticStatus.ERROR and "frame_rate" in s.message
                                  for s in self.bad_judge_statuses), 30, "an ERROR naming Clip.frame_rate")
        rospy.sleep(2.5)
        status, values = latest()
        self.assertEqual(status.level, DiagnosticStatus.ERROR, status.message)
        self.assertIn("frame_rate", status.message)
        # Stamps that go back are refused, naming the field.
        back = make_clip(2, start + rospy.Duration.from_sec(4.0), size, 3.0, 4.0)
        back.frame_stamps[5], back.frame_stamps[6] = back.frame_stamps[6], back.frame_stamps[5]
        self.bad_judge_pub.publish(back)
        self.wait_for(lambda: any(s.level == DiagnosticStatus.ERROR and "strictly increasing" in s.message
                                  for s in self.bad_judge_statuses), 30, "an ERROR naming Clip.frame_stamps")
        # A good clip without frame_stamps: estimated, its end its first frame + 29 periods, and the
        # ERROR gone; clips 1-3 never made it into the sequence.
        bare = make_clip(4, start + rospy.Duration.from_sec(6.0), size, 3.0, 4.0)
        bare.frame_stamps = []
        self.bad_judge_pub.publish(bare)
        self.wait_for(lambda: any(e.clip_sequence == 4 for e in self.bad_judge_estimates), 30, "the bare clip's estimate")
        with self.lock:
            e = [e for e in self.bad_judge_estimates if e.clip_sequence == 4][0]
        self.assertEqual(e.clip_start, bare.header.stamp)
        self.assertAlmostEqual((e.clip_end - bare.header.stamp).to_sec(), 29 / 25.0, places=6)
        self.assertEqual(e.header.stamp, e.clip_end)
        rospy.sleep(1.5)
        status, values = latest()
        self.assertNotEqual(status.level, DiagnosticStatus.ERROR, status.message)
        # ...and the clip missing in the last 30 s is a WARN of its own (an OK hid a queue dropping clips).
        self.assertEqual(status.level, DiagnosticStatus.WARN, status.message)
        self.assertIn("1 clip missing from the sequence in the last 30 s", status.message)
        # Clip 3 was never sent; clips 1 and 2 came and are counted as malformed, not missing.
        self.assertEqual(values["clips missing from the sequence (queue or upstream)"], "1")
        self.assertEqual(values["malformed clips"], "2")


if __name__ == "__main__":
    rospy.init_node("sdn_check")
    rostest.rosrun("clothwind", "sdn_node_estimates", SdnNodeTest, sys.argv)
