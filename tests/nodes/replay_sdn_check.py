#!/usr/bin/env python3
"""Checks that sdn_node, fed by a replayed session's clip buffer, answers every clip once with an
estimate that refers to that clip (sequence, first/last frame stamps, anemometer label)."""
import math
import time
import unittest

import rospy
import rostest
from clothwind.msg import Clip, WindEstimate


class ReplaySdnTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('replay_sdn_check')
        cls.expected = rospy.get_param('~expected_clips')
        cls.clips, cls.estimates = {}, []
        rospy.Subscriber('clips', Clip, lambda c: cls.clips.__setitem__(c.sequence, c), queue_size=100)
        rospy.Subscriber('wind/estimate', WindEstimate, cls.estimates.append, queue_size=100)
        # Until every expected clip has its estimate, then a little longer to catch duplicates.
        deadline = time.time() + 200
        while time.time() < deadline and not rospy.is_shutdown():
            if len(cls.clips) >= cls.expected and len(cls.estimates) >= len(cls.clips):
                break
            time.sleep(0.2)
        time.sleep(2.0)

    def test_every_clip_gets_one_estimate(self):
        self.assertGreaterEqual(len(self.clips), self.expected)
        sequences = sorted(e.clip_sequence for e in self.estimates)
        self.assertEqual(sequences, sorted(self.clips.keys()))

    def test_estimates_refer_to_their_clip(self):
        for e in self.estimates:
            c = self.clips[e.clip_sequence]
            self.assertEqual(e.clip_start, c.frame_stamps[0])
            self.assertEqual(e.clip_end, c.frame_stamps[-1])
            self.assertEqual(e.header.stamp, c.frame_stamps[-1])
            self.assertEqual(e.header.frame_id, c.header.frame_id)
            if c.wind_count > 0:
                self.assertAlmostEqual(e.reference_speed, c.wind_mean, places=9)
            else:
                self.assertTrue(math.isnan(e.reference_speed))

    def test_estimates_are_plausible(self):
        # The shipped model was trained on 0-10 m/s; an estimate far outside means a broken input path.
        for e in self.estimates:
            self.assertTrue(math.isfinite(e.speed), e)
            self.assertGreater(e.speed, -2.0)
            self.assertLess(e.speed, 15.0)
            self.assertTrue(math.isfinite(e.speed_std) and e.speed_std > 0, e.speed_std)
            self.assertIn('models/sdn.pt', e.model)
        # Blank or garbled frames would give one speed for every clip: the session's wind drifts,
        # and the estimates must move with something.
        speeds = [e.speed for e in self.estimates]
        self.assertGreaterEqual(len(speeds), 2)
        self.assertGreater(max(speeds) - min(speeds), 0.05, speeds)


if __name__ == '__main__':
    rostest.rosrun('clothwind', 'replay_sdn_estimates', ReplaySdnTest)
