#!/usr/bin/python3
"""Unit tests of scripts/window-oracle's geometry and window features, its reuse of earlier
simulations and its stop at a failed one (no simulation needed)."""
import argparse
import importlib.machinery
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from unittest import mock

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
_loader = importlib.machinery.SourceFileLoader('window_oracle', os.path.join(ROOT, 'scripts', 'window-oracle'))
_spec = importlib.util.spec_from_loader('window_oracle', _loader)
oracle = importlib.util.module_from_spec(_spec)
_loader.exec_module(oracle)


class MotionFeaturesTest(unittest.TestCase):
    W, P, BINS = 30, 4, 6

    def wave(self, bin_, lag):
        """P points whose lateral y oscillates at DFT bin `bin_`, each `lag` rad behind the last."""
        t = np.arange(self.W)
        w = np.zeros((self.W, self.P, 3))
        for p in range(self.P):
            w[:, p, 1] = 0.3 * np.sin(2 * np.pi * bin_ * t / self.W - lag * (p - (self.P - 1)))
            w[:, p, 2] = 1.0 + 0.1 * p + 0.05 * np.sin(2 * np.pi * bin_ * t / self.W - lag * (p - (self.P - 1)))
        return w

    def split(self, f):
        p, b = self.P, self.BINS
        mean, std = f[:3 * p].reshape(p, 3), f[3 * p:6 * p].reshape(p, 3)
        power = f[6 * p:6 * p + 3 * b * p].reshape(b, p, 3)
        rest = f[6 * p + 3 * b * p:]
        re, im = rest[:len(rest) // 2].reshape(3, p, 2), rest[len(rest) // 2:].reshape(3, p, 2)
        return mean, std, power, re + 1j * im

    def test_periodogram_peaks_at_the_oscillation_bin(self):
        for bin_ in (1, 2, 4):
            _, _, power, _ = self.split(oracle.motion_features(self.wave(bin_, 0.4), self.BINS, 2))
            np.testing.assert_array_equal(np.argmax(power[:, :, 1], axis=0) + 1, [bin_] * self.P)

    def test_mean_and_std(self):
        w = self.wave(2, 0.4)
        mean, std, _, _ = self.split(oracle.motion_features(w, self.BINS, 2))
        np.testing.assert_allclose(mean[:, 2], 1.0 + 0.1 * np.arange(self.P), atol=1e-12)
        np.testing.assert_allclose(std[:, 1], 0.3 / np.sqrt(2), rtol=1e-9)

    def test_phases_are_relative_to_the_reference_and_independent_of_the_start(self):
        lag = 0.4
        w = self.wave(2, lag)
        _, _, _, rel = self.split(oracle.motion_features(w, self.BINS, 2))
        # y (kept column 1 after deleting z) against the fly corner's z, in phase with it: the lag.
        np.testing.assert_allclose(np.angle(rel[1, :, 1]), -lag * (np.arange(self.P) - (self.P - 1)), atol=1e-9)
        shifted = np.concatenate([w[7:], w[:7]])  # the same periodic motion, started 7 frames later
        _, _, _, rel2 = self.split(oracle.motion_features(shifted, self.BINS, 2))
        np.testing.assert_allclose(rel2[1], rel[1], atol=1e-9)


class ProjectTest(unittest.TestCase):
    def flag(self):
        """A flat 3 m x 2 m flag flying straight out along +x, hoist on the z axis."""
        u, v = np.meshgrid(np.linspace(0, 3, 7), np.linspace(0, 2, 5))
        return np.stack([u.ravel(), np.zeros(u.size), v.ravel()], axis=-1)[None]

    def test_the_box_centre_is_the_image_centre_and_the_box_fits(self):
        w = 3 * self.flag()  # 9 m x 6 m at 4-6 m: the field of view must widen past 45 deg to fit
        box = (w.min(axis=(0, 1)), w.max(axis=(0, 1)))
        for seed in range(20):
            img, camera = oracle.project(np.array([[0.5 * (box[0] + box[1])]]), box, np.random.RandomState(seed), 'clip')
            np.testing.assert_allclose(img, 0.0, atol=1e-12)
            img, camera = oracle.project(w, box, np.random.RandomState(seed), 'clip')
            self.assertLessEqual(np.abs(img).max(), 0.95 + 1e-9)
            self.assertGreater(np.abs(img).max(), 0.95 - 1e-6)  # widened just enough
            height, radius, angle, fov = camera
            self.assertTrue(0.2 <= height <= 3 and 4 <= radius <= 6 and -15 <= angle <= 15 and fov > 45)

    def test_a_camera_below_sees_lateral_motion_as_vertical(self):
        # Looking up at the flag, moving it across the line of sight (y) moves it in the picture's
        # vertical; a level camera would not. This is the ambiguity the image oracle measures.
        w = self.flag()
        box = (w.min(axis=(0, 1)), w.max(axis=(0, 1)))
        swung = w + np.array([0.0, 0.3, 0.0])
        for framing in ('clip', 'fixed'):
            a, _ = oracle.project(w, box, np.random.RandomState(3), framing)
            b, _ = oracle.project(swung, box, np.random.RandomState(3), framing)
            self.assertGreater(np.abs(b[..., 1] - a[..., 1]).mean(), 0.01)

    def test_fixed_framing_aims_at_the_rest_centre_as_the_datasets_camera(self):
        # make-dataset's camera (render/camera.cc MeshCentre, PlaceCamera) looks at the flying
        # flag's rest centre (w/2, 0, h/2) above the mast foot with a 45 deg field of view,
        # whatever the clip: that point is the picture's centre for every camera drawn.
        centre = np.array([[[1.5, 0.0, 1.0]]])
        drooping = self.flag() - np.array([0.0, 0.0, 0.7])  # a clip whose own box is elsewhere
        box = (drooping.min(axis=(0, 1)), drooping.max(axis=(0, 1)))
        for seed in range(20):
            img, camera = oracle.project(centre, box, np.random.RandomState(seed), 'fixed')
            np.testing.assert_allclose(img, 0.0, atol=1e-12)
            self.assertEqual(camera[3], 45.0)

    def test_only_fixed_framing_shows_where_the_flag_hangs(self):
        # A flag drooping 0.4 m lower moves down in the fixed picture; framed on its own box, its
        # box centre stays the picture's centre, so the droop's height is lost.
        w = self.flag()
        low = w - np.array([0.0, 0.0, 0.4])
        for seed in range(10):
            boxes = [(x.min(axis=(0, 1)), x.max(axis=(0, 1))) for x in (w, low)]
            centres = [0.5 * (b[0] + b[1])[None, None] for b in boxes]
            fixed = [oracle.project(c, b, np.random.RandomState(seed), 'fixed')[0] for c, b in zip(centres, boxes)]
            clip = [oracle.project(c, b, np.random.RandomState(seed), 'clip')[0] for c, b in zip(centres, boxes)]
            self.assertGreater(fixed[1][..., 1].item() - fixed[0][..., 1].item(), 0.05)  # image y is down
            np.testing.assert_allclose(clip[0], clip[1], atol=1e-12)

    def test_fixed_framing_clamps_what_leaves_the_picture(self):
        far = self.flag() + np.array([0.0, 0.0, -8.0])  # far below the frame's bottom edge
        img, _ = oracle.project(far, (far.min(axis=(0, 1)), far.max(axis=(0, 1))), np.random.RandomState(1), 'fixed')
        np.testing.assert_allclose(img[..., 1], 1.0)



class ClipWindowsTest(unittest.TestCase):
    """--clip-windows reads a simulation as FlagSim clips: one camera per clip, K windows each."""

    def args(self, k):
        class A:
            pass
        a = A()
        a.seed, a.window, a.clip, a.clip_windows, a.warmup = 1, 30, 60, k, 0.0
        a.coords, a.framing, a.camera_known, a.features, a.bins = 'image', 'fixed', True, 'shape', 6
        a.track_noise, a.track_size = 0.0, 64
        return a

    def loaded(self, frames=180, points=4):
        t = np.arange(frames)[:, None, None]
        pts = np.zeros((frames, points, 3))
        pts[:, :, 0] = np.linspace(0.5, 3.0, points)
        pts[:, :, 2] = -0.5 + 0.1 * np.sin(0.3 * t[:, :, 0])
        return 0.04, pts, pts

    def test_window_starts_are_those_of_clothwind_eval(self):
        # learn::EvenWindowStarts (dataset_test.cc): {15}, {0, 30}, {0, 15, 30}, {0, 3, 7, 10}.
        self.assertEqual(oracle.clip_window_starts(0, 60, 30, 1), [15])
        self.assertEqual(oracle.clip_window_starts(0, 60, 30, 2), [0, 30])
        self.assertEqual(oracle.clip_window_starts(60, 60, 30, 3), [60, 75, 90])
        self.assertEqual(oracle.clip_window_starts(0, 40, 30, 4), [0, 3, 7, 10])

    def test_the_windows_of_a_clip_share_its_camera_and_clips_do_not(self):
        clips = oracle.clip_windows_of(0, self.loaded(), self.args(3))
        self.assertEqual([c for c, _ in clips], [0, 60, 120])
        cameras = [[f[-4:] for f in feats] for _, feats in clips]
        for per_clip in cameras:
            self.assertEqual(len(per_clip), 3)
            for cam in per_clip[1:]:
                np.testing.assert_array_equal(cam, per_clip[0])
        self.assertFalse(np.allclose(cameras[0][0], cameras[1][0]))
        # The windows themselves differ (the flag moves between them).
        self.assertFalse(np.allclose(clips[0][1][0], clips[0][1][1]))

    def test_track_noise_is_pixels_of_the_frame_and_repeats_with_the_camera(self):
        # Shape features are the window-mean image positions (then the camera): jitter of sigma
        # pixels per frame moves a mean of W frames by sigma / sqrt(W), in image units 2 / size.
        a, loaded = self.args(1), self.loaded(frames=40, points=400)
        a.camera_known = False
        clean = oracle.window_features(loaded, a, 0, False, [1, 0, 0, 0])
        a.track_noise, a.track_size = 2.0, 64
        noisy = oracle.window_features(loaded, a, 0, False, [1, 0, 0, 0])
        expected = 2.0 * 2.0 / 64 / np.sqrt(a.window)
        self.assertAlmostEqual(np.std(noisy - clean) / expected, 1.0, delta=0.1)
        self.assertAlmostEqual(np.mean(noisy - clean) / expected, 0.0, delta=0.1)
        # Deterministic for one camera seed, other jitter for another.
        np.testing.assert_array_equal(noisy, oracle.window_features(loaded, a, 0, False, [1, 0, 0, 0]))
        quiet = self.args(1)
        quiet.camera_known = False
        jitter = noisy - clean
        other = (oracle.window_features(loaded, a, 0, False, [1, 0, 5, 0]) -
                 oracle.window_features(loaded, quiet, 0, False, [1, 0, 5, 0]))
        self.assertLess(abs(np.corrcoef(jitter, other)[0, 1]), 0.2)

    def test_train_seconds_keep_the_windows_inside_the_first_seconds(self):
        # 180 frames at 25 Hz, no warm-up: 2.4 s are frames 0-59, whose 30-frame windows every 5
        # frames start at 0 ... 30 (7); without the limit they run to 150 (31).
        a, loaded = self.args(1), self.loaded()
        self.assertEqual(len(oracle.windows_of(0, loaded, a, 5, False, 2.4)), 7)
        self.assertEqual(len(oracle.windows_of(0, loaded, a, 5, False)), 31)
        np.testing.assert_array_equal(oracle.windows_of(0, loaded, a, 5, False, 2.4)[6],
                                      oracle.windows_of(0, loaded, a, 5, False)[6])

    def test_a_clips_estimate_is_the_mean_of_its_windows(self):
        errors = oracle.clip_errors([(0, 0)] * 3 + [(1, 0)] * 3, [2.0] * 3 + [5.0] * 3,
                                    [2.3, 2.6, 1.9, 5.0, 4.4, 4.6])
        np.testing.assert_allclose([t for t, _ in errors], [2.0, 5.0])
        np.testing.assert_allclose([e for _, e in errors], [0.2667, -0.3333], atol=1e-3)


class ReuseTest(unittest.TestCase):
    """An earlier simulation in DIR is reused only when it is this call's: its wind, length, every
    bending entry and mesh (the scene's when this call sets neither)."""

    SPEED = 3.21

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        # window-oracle's defaults: 5 s warm-up, 19.2 s after it, the scene's mesh.
        self.args = argparse.Namespace(out=self.tmp.name, warmup=5.0, seconds=19.2, max_edge=0.0)
        theta = {f'bending_d{d}_c{c}': 1e-3 * (1 + d + 0.1 * c) for d in range(3) for c in range(5)}
        self.base = {'theta': dict(theta, area_weight=1.0, wind_speed=0.0), 'max_edge_m': 0.3}

    def tearDown(self):
        self.tmp.cleanup()

    def write_summary(self, bending_scale=1.0, edge=0.3, theta=None, speed=None, seconds=None):
        folder = os.path.join(self.tmp.name, 's0')
        os.makedirs(folder, exist_ok=True)
        theta = theta or {n: v * (bending_scale if n.startswith('bending_') else 1)
                          for n, v in self.base['theta'].items()}
        with open(os.path.join(folder, 'summary.json'), 'w') as f:
            json.dump({'wind': {'velocity': [round(self.SPEED if speed is None else speed, 4), 0, 0]},
                       'cloths': [{'simulated_seconds': self.args.warmup + self.args.seconds
                                   if seconds is None else seconds,
                                   'max_edge_m': edge, 'theta': theta}]}, f)

    def simulated(self, bending=None):
        """Whether simulate() ran clothwind for simulation 0 (else it reused s0)."""
        done = subprocess.CompletedProcess([], 0, '', '')
        with mock.patch.object(oracle.subprocess, 'run', return_value=done) as run:
            self.assertEqual(oracle.simulate(self.args, 0, self.SPEED, bending or {}, self.base),
                             os.path.join(self.tmp.name, 's0'))
        return run.called

    def test_the_same_simulation_is_reused(self):
        self.write_summary()
        self.assertFalse(self.simulated())

    def test_another_wind_or_length_is_simulated_again(self):
        # Every summary above had this call's wind and length, so neither clause was ever needed.
        self.write_summary(speed=3.3)
        self.assertTrue(self.simulated())
        self.write_summary(seconds=20.0)
        self.assertTrue(self.simulated())

    def test_other_bending_is_simulated_again_without_a_spread(self):
        # This call has the scene's bending (no --bending-spread): a run with bending x3.7 is not it.
        self.write_summary(bending_scale=3.7)
        self.assertTrue(self.simulated())

    def test_another_mesh_is_simulated_again_without_max_edge(self):
        # --max-edge 0: the scene's mesh (0.3 m here); a run made with --max-edge 0.2 is not it.
        self.assertEqual(self.args.max_edge, 0)
        self.write_summary(edge=0.2)
        self.assertTrue(self.simulated())

    def test_drawn_bending_must_match_every_entry(self):
        drawn = {n: 2.0 * v for n, v in self.base['theta'].items() if n.startswith('bending_')}
        self.write_summary(bending_scale=2.0)
        self.assertFalse(self.simulated(drawn))
        theta = {n: v * 2.0 for n, v in self.base['theta'].items()}
        theta['bending_d2_c4'] *= 1.5  # one entry other than drawn
        self.write_summary(theta=theta)
        self.assertTrue(self.simulated(drawn))


class MainTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def main(self, *argv):
        with mock.patch.object(sys, 'argv', ['window-oracle', '--out', self.tmp.name, *argv]):
            oracle.main()

    def test_one_failed_simulation_stops_the_queued_ones(self):
        calls, lock = [], threading.Lock()

        def simulate(args, i, *_):
            with lock:
                calls.append(i)
            if i == 0:
                sys.exit('window-oracle: clothwind simulate failed')
            time.sleep(0.5)  # long enough for the failure to be seen before the worker is free again
            return os.path.join(args.out, f's{i}')

        with mock.patch.object(oracle, 'simulate', simulate), self.assertRaises(SystemExit) as e:
            self.main('--sims', '20', '--jobs', '1')
        self.assertIn('failed', str(e.exception.code))
        # The one worker may have taken the next simulation before the failure was seen; no more.
        self.assertLessEqual(len(calls), 2, calls)

    def test_folds_must_be_between_2_and_the_simulations(self):
        for sims, folds in (('4', '8'), ('4', '1'), ('4', '0')):
            with mock.patch.object(oracle, 'simulate') as simulate, self.assertRaises(SystemExit) as e:
                self.main('--estimator', 'boost', '--features', 'motion', '--sims', sims, '--folds', folds)
            self.assertIn(f'--folds: expected 2 .. --sims (4) with --estimator boost, got {folds}', str(e.exception.code))
            self.assertFalse(simulate.called)  # refused before anything is simulated

    def test_settings_that_fail_after_the_simulations_are_refused_before_them(self):
        # Each ended in a traceback (or a table of NaN with status 0) after every simulation ran.
        for extra, said in ((('--seconds', '0.4', '--warmup', '0.4'), '--seconds: expected at least one window'),
                            (('--estimator', 'boost', '--features', 'motion', '--folds', '2', '--stride', '0'),
                             '--stride: expected >= 1'),
                            (('--k', '0'), '--k: expected at least 1')):
            with mock.patch.object(oracle, 'simulate') as simulate, self.assertRaises(SystemExit) as e:
                self.main('--sims', '4', *extra)
            self.assertIn(said, str(e.exception.code))
            self.assertFalse(simulate.called)
        # --bins are the motion features': a shape run with a window of 4 frames is not refused by them.
        with mock.patch.object(oracle, 'simulate', side_effect=SystemExit('simulated')) as simulate, \
                self.assertRaises(SystemExit) as e:
            self.main('--sims', '4', '--window', '4')
        self.assertEqual(str(e.exception.code), 'simulated')


if __name__ == '__main__':
    unittest.main()
