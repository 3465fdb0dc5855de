#!/usr/bin/python3
"""Tests of scripts/track-oracle on a small dataset of generated tracks whose motion encodes the
wind: the trees learn it from the train split and read held-out simulations; windows, mirrors and
per-clip means are eval's; bad input is refused naming the file and field."""
import argparse
import importlib.machinery
import importlib.util
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, 'scripts', 'track-oracle')
_loader = importlib.machinery.SourceFileLoader('track_oracle', SCRIPT)
oracle = importlib.util.module_from_spec(importlib.util.spec_from_loader('track_oracle', _loader))
_loader.exec_module(oracle)

GRID, FRAMES, SIZE = (3, 2), 60, 128


def read_json(path):
    with open(path) as f:
        return json.load(f)


def write_json(path, value):
    with open(path, 'w') as f:
        json.dump(value, f)


def flag_tracks(speed, view, rng):
    """A 3x2 grid whose points swing at a frequency and amplitude that grow with the wind, seen by a
    camera offset per view: {'xy': [frames][12], 'world': [frames][18]}."""
    t = np.arange(FRAMES) / 25.0
    freq, amp = 0.5 + 0.3 * speed, 0.05 + 0.02 * speed
    phase = rng.uniform(0, 2 * np.pi)
    world = np.zeros((FRAMES, GRID[0] * GRID[1], 3))
    for p in range(GRID[0] * GRID[1]):
        along = (p // GRID[1] + 1) / GRID[0]
        world[:, p, 0] = 3.0 * along
        world[:, p, 1] = along * amp * np.sin(2 * np.pi * freq * t + phase - 2.0 * along)
        world[:, p, 2] = 5.0 + 0.3 * (p % GRID[1]) - 0.1 * (10 - speed) * along
    offset = np.array([30.0 + 5 * view, 40.0])
    xy = offset + 25.0 * world[:, :, [0, 2]] * np.array([1.0, -1.0]) + np.array([0.0, 150.0])
    xy[:, :, 0] += 40.0 * world[:, :, 1]
    return {'xy': xy.reshape(FRAMES, -1).round(2).tolist(), 'world': world.reshape(FRAMES, -1).round(4).tolist()}


def make_dataset(folder, sims_per_split=(24, 6, 6), views=2, seed=3):
    rng = np.random.RandomState(seed)
    clips, sim = [], 0
    for split, count in zip(('train', 'val', 'test'), sims_per_split):
        for _ in range(count):
            speed = float(rng.uniform(0, 10))
            for view in range(views):
                name = f'flag-{sim:06d}-v{view}'
                os.makedirs(os.path.join(folder, name))
                tracks = {'format': 'clothwind-tracks', 'version': 1, 'grid': list(GRID), 'width': SIZE,
                          'height': SIZE, **flag_tracks(speed, view, rng)}
                write_json(os.path.join(folder, name, 'tracks.json'), tracks)
                clips.append({'name': name, 'simulation': sim, 'view': view, 'split': split, 'wind_speed': speed})
            sim += 1
    write_json(os.path.join(folder, 'index.json'), {'format': 'clothwind-dataset', 'clips': clips})
    return clips


class TrackOracleTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.data = os.path.join(self.tmp.name, 'data')

    def tearDown(self):
        self.tmp.cleanup()

    def run_oracle(self, *extra):
        env = dict(os.environ, OMP_NUM_THREADS='1')
        return subprocess.run(['/usr/bin/python3', SCRIPT, '--data', self.data, '--max-trees', '150',
                               '--leaves', '7', *extra], capture_output=True, text=True, env=env)

    def test_learns_the_wind_from_the_train_split_and_reads_held_out_simulations(self):
        clips = make_dataset(self.data)
        predictions = os.path.join(self.tmp.name, 'pred.dat')
        for coords in ('image', 'world'):
            done = self.run_oracle('--coords', coords, '--windows', '3', '--predictions', predictions)
            self.assertEqual(done.returncode, 0, done.stderr)
            with open(predictions) as f:
                first = f.readline()
                rows = [line.split() for line in f if not line.startswith('#')]
            # eval's protocol line: compare-evals refuses to pair it with a one-window evaluation.
            self.assertEqual(first, '# protocol windows 3 mirror 0 mirror_clips 0 flag_flies right\n')
            test = [c for c in clips if c['split'] == 'test']
            self.assertEqual([r[3] for r in rows], [c['name'] for c in test])
            truth = np.array([float(r[0]) for r in rows])
            # The true speed first (RMSE is symmetric: the columns swapped passed every figure).
            np.testing.assert_allclose(truth, [c['wind_speed'] for c in test], atol=1e-4)
            error = np.array([float(r[1]) for r in rows]) - truth
            # A guess of the mean wind would err by the spread of the speeds; the tracks say more.
            self.assertLess(np.sqrt((error ** 2).mean()), 0.5 * truth.std(), coords)
            self.assertIn('| 12 |', done.stdout)  # 6 test simulations x 2 views, one row
            self.assertIn('(6) |', done.stdout)   # per-simulation RMSE over the 6 simulations

    def test_test_clips_give_one_row_per_window(self):
        # --windows 3 reads three windows of each test clip (eval's starts), one window reads one;
        # the protocol line alone echoed the option, and a script reading one window passed.
        clips = make_dataset(self.data, sims_per_split=(1, 1, 1), views=1)
        args = argparse.Namespace(coords='image', features='motion', track_noise=0.0, track_size=64, window=30,
                                  windows=3, stride=5, bins=6, seed=1)
        test = [c for c in clips if c['split'] == 'test']
        _, _, owner = oracle.rows_of(test, self.data, args, True)
        self.assertEqual(list(owner), [0, 0, 0])
        args.windows = 1
        _, _, owner = oracle.rows_of(test, self.data, args, True)
        self.assertEqual(list(owner), [0])

    def test_image_tracks_scale_to_the_unit_square_and_mirror_as_the_flip(self):
        make_dataset(self.data, sims_per_split=(1, 1, 1), views=1)
        path = os.path.join(self.data, 'flag-000000-v0', 'tracks.json')
        # Frames wider than high: x scales by the width, y by the height (square frames hid them swapped).
        t = read_json(path)
        t['width'], t['height'] = 160, 120
        write_json(path, t)
        image = oracle.read_tracks(path, 'image')
        world = oracle.read_tracks(path, 'world')
        self.assertEqual(image.shape, (FRAMES, 6, 2))
        self.assertEqual(world.shape, (FRAMES, 6, 3))
        raw = np.array(read_json(path)['xy']).reshape(FRAMES, 6, 2)
        np.testing.assert_allclose(image, raw / np.array([160.0, 120.0]) * 2 - 1)
        np.testing.assert_allclose(oracle.mirrored(image, 'image')[..., 0], -image[..., 0])
        np.testing.assert_allclose(oracle.mirrored(world, 'world')[..., 1], -world[..., 1])
        np.testing.assert_allclose(oracle.mirrored(world, 'world')[..., [0, 2]], world[..., [0, 2]])

    def test_jitter_is_a_tracker_error_of_the_pixels_asked_for(self):
        make_dataset(self.data, sims_per_split=(1, 1, 1), views=1)
        tracks = oracle.read_tracks(os.path.join(self.data, 'flag-000000-v0', 'tracks.json'), 'image')
        args = type('Args', (), {'track_noise': 0.5, 'track_size': 64, 'seed': 1})()
        noisy = oracle.jittered(tracks, args, 7)
        # 0.5 px of a 64-px frame is 1/64 of the [-1, 1] span; 720 draws pin the std to ~3 %.
        self.assertAlmostEqual(float((noisy - tracks).std()) * 64, 1.0, delta=0.1)
        np.testing.assert_array_equal(noisy, oracle.jittered(tracks, args, 7))  # seeded by the clip
        self.assertFalse(np.array_equal(noisy, oracle.jittered(tracks, args, 8)))
        args.track_noise = 0
        self.assertIs(oracle.jittered(tracks, args, 7), tracks)

    def test_shape_features_are_the_window_mean_positions(self):
        w = np.random.RandomState(2).normal(size=(30, 6, 2))
        shape = type('Args', (), {'features': 'shape', 'bins': 6})()
        motion = type('Args', (), {'features': 'motion', 'bins': 6})()
        np.testing.assert_allclose(oracle.describe(w, shape), w.mean(axis=0).reshape(-1))
        # motion: mean 12, std 12, 6 bins x 12 powers, 3 bins x 6 points x 1 other coordinate x (re, im)
        self.assertEqual(oracle.describe(w, motion).shape, (12 + 12 + 72 + 36,))

    def test_a_clip_is_the_mean_of_its_windows(self):
        np.testing.assert_allclose(oracle.per_clip(np.array([1.0, 2.0, 6.0, 4.0]), np.array([0, 0, 1, 1]), 2),
                                   [1.5, 5.0])

    def test_bad_tracks_are_refused_naming_the_file_and_field(self):
        make_dataset(self.data, sims_per_split=(1, 1, 1), views=1)
        path = os.path.join(self.data, 'flag-000001-v0', 'tracks.json')
        t = read_json(path)
        t['xy'] = [row[:-2] for row in t['xy']]
        write_json(path, t)
        done = self.run_oracle()
        self.assertNotEqual(done.returncode, 0)
        self.assertIn(path, done.stderr)
        self.assertIn('"xy": expected [frames][12]', done.stderr)
        del t['world']
        write_json(path, t)
        done = self.run_oracle('--coords', 'world')
        self.assertIn('no "world" field', done.stderr)
        del t['width']
        write_json(path, t)
        done = self.run_oracle()
        self.assertNotEqual(done.returncode, 0)
        self.assertIn(path, done.stderr)
        self.assertIn('"width"', done.stderr)
        self.assertNotIn('Traceback', done.stderr)

    def test_ragged_or_missing_tracks_and_incomplete_clips_are_named(self):
        make_dataset(self.data, sims_per_split=(1, 1, 1), views=1)
        path = os.path.join(self.data, 'flag-000002-v0', 'tracks.json')
        t = read_json(path)
        t['xy'][7] = t['xy'][7][:-2]  # one frame short of a point

        def refused(text, *extra):
            done = self.run_oracle(*extra)
            self.assertNotEqual(done.returncode, 0)
            self.assertIn(text, done.stderr)
            self.assertNotIn('Traceback', done.stderr)

        write_json(path, t)
        refused(f'{path}: "xy": expected [frames][12] numbers, got rows of 10, 12 entries')
        t['world'][3] = t['world'][3] + [1.0]
        write_json(path, t)
        refused(f'{path}: "world": expected [frames][18] numbers, got rows of 18, 19 entries', '--coords', 'world')
        t['xy'][7] = ['x'] * 12
        write_json(path, t)
        refused(f'{path}: "xy": expected [frames][12] numbers, got entries that are not numbers')
        del t['xy']
        write_json(path, t)
        refused(f'{path}: no "xy" field')
        index_path = os.path.join(self.data, 'index.json')
        index = read_json(index_path)
        del index['clips'][1]['simulation']
        write_json(index_path, index)
        refused(f'{index_path}: clips[1] (flag-000001-v0): expected "simulation", an integer, got None')
        index['clips'][1]['simulation'] = 1
        index['clips'][2]['wind_speed'] = '3.5'
        write_json(index_path, index)
        refused(f"{index_path}: clips[2] (flag-000002-v0): expected \"wind_speed\", a number, got '3.5'")

    def test_a_dataset_without_a_split_is_refused(self):
        clips = make_dataset(self.data, sims_per_split=(1, 1, 0), views=1)
        self.assertFalse(any(c['split'] == 'test' for c in clips))
        done = self.run_oracle()
        self.assertNotEqual(done.returncode, 0)
        self.assertIn('index.json: no clip in split "test"', done.stderr)


if __name__ == '__main__':
    unittest.main()
