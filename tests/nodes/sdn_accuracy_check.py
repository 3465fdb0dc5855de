#!/usr/bin/env python3
"""rostest: sdn_node with a model trained on the toy dataset estimates the wind speed of toy
clips generated here (the same law: stripes over 3/4 of a 32x32 frame travelling at
f = 1 + 0.5 v Hz, on a textured noisy background)."""
import math
import random
import sys
import threading
import unittest

import rospy
import rostest
from clothwind.msg import Clip, WindEstimate

SIZE = 32
RATE = 25.0


def toy_clip(seq, speed, rng, frames=30):
    f = 1.0 + 0.5 * speed
    phase = rng.uniform(0, 2 * math.pi)
    patch = 3 * SIZE // 4
    x0 = rng.randint(1, SIZE - patch - 1)
    y0 = rng.randint(1, SIZE - patch - 1)
    wavelength = patch / 3.0
    data = bytearray(frames * SIZE * SIZE)
    for t in range(frames):
        for y in range(SIZE):
            for x in range(SIZE):
                v = 80 + 10 * math.sin(0.3 * x + 0.2 * y)
                if x0 <= x < x0 + patch and y0 <= y < y0 + patch:
                    v = 140 + 60 * math.sin(2 * math.pi * (f * t / RATE - (x - x0) / wavelength) + phase)
                v += rng.gauss(0, 3)
                data[(t * SIZE + y) * SIZE + x] = max(0, min(255, int(round(v))))
    clip = Clip()
    start = rospy.Time(1700000000 + 10 * seq, 0)
    clip.header.frame_id = "camera_optical"
    clip.header.stamp = start
    clip.sequence = seq
    clip.frame_stamps = [start + rospy.Duration.from_sec(i / RATE) for i in range(frames)]
    clip.frame_rate = RATE
    clip.num_frames = frames
    clip.height = SIZE
    clip.width = SIZE
    clip.encoding = "mono8"
    clip.data = bytes(data)
    clip.label_window = 60.0
    clip.wind_mean = speed
    clip.wind_std = 0.0
    clip.wind_count = 1
    clip.wind_direction_mean = 0.0
    return clip


class SdnAccuracyTest(unittest.TestCase):
    def test_accuracy(self):
        speeds = rospy.get_param("~speeds")
        max_rmse = rospy.get_param("~max_rmse", 1.5)
        lock = threading.Lock()
        estimates = {}

        def on_estimate(msg):
            with lock:
                estimates[msg.clip_sequence] = msg

        rospy.Subscriber("wind/estimate", WindEstimate, on_estimate, queue_size=100)
        pub = rospy.Publisher("clips", Clip, queue_size=100)
        deadline = rospy.get_time() + 200
        while pub.get_num_connections() == 0 and rospy.get_time() < deadline and not rospy.is_shutdown():
            rospy.sleep(0.2)  # the node subscribes after its model is trained and loaded
        self.assertGreater(pub.get_num_connections(), 0, "sdn_node never subscribed to clips")
        rospy.sleep(0.5)
        rng = random.Random(5)
        for seq, v in enumerate(speeds):
            pub.publish(toy_clip(seq, v, rng))
        deadline = rospy.get_time() + 60
        while rospy.get_time() < deadline and not rospy.is_shutdown():
            with lock:
                if len(estimates) == len(speeds):
                    break
            rospy.sleep(0.1)
        with lock:
            got = dict(estimates)
        self.assertEqual(sorted(got), list(range(len(speeds))))
        se = 0.0
        for seq, v in enumerate(speeds):
            e = got[seq]
            self.assertAlmostEqual(e.reference_speed, v)
            rospy.loginfo("speed %.2f -> estimate %.2f +- %.2f (%.1f ms)", v, e.speed, e.speed_std, 1e3 * e.latency)
            se += (e.speed - v) ** 2
        rmse = math.sqrt(se / len(speeds))
        spread = math.sqrt(sum((v - sum(speeds) / len(speeds)) ** 2 for v in speeds) / len(speeds))
        self.assertLess(rmse, max_rmse, "RMSE %.2f m/s over speeds of spread %.2f m/s" % (rmse, spread))


if __name__ == "__main__":
    rospy.init_node("sdn_accuracy_check")
    rostest.rosrun("clothwind", "sdn_node_accuracy", SdnAccuracyTest, sys.argv)
