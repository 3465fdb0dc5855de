#!/usr/bin/python3
"""Tests of scripts/head-oracle on generated rows files in `clothwind eval --track-head-rows`'
layout: the trees read the wind from the column group and targets asked for (exact truth reads
better than a noisy head, positions alone read what they hold), and bad rows are refused naming
the file and line."""
import importlib.machinery
import importlib.util
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, 'scripts', 'head-oracle')
POINTS, PER_POINT = 3, 12
_loader = importlib.machinery.SourceFileLoader('head_oracle', SCRIPT)
oracle = importlib.util.module_from_spec(importlib.util.spec_from_loader('head_oracle', _loader))
_loader.exec_module(oracle)


def targets(speed, rng, wind_in='means'):
    """One window's targets of 3 points. wind_in 'means': the means droop with the wind, the
    amplitudes (which then hold nothing of it) are noise; 'amplitudes': the first log amplitude
    of each point grows with the wind and the means are noise."""
    t = rng.normal(0.0, 0.3, (POINTS, PER_POINT))
    for p in range(POINTS):
        t[p, 0] = -0.5 + 0.4 * p
        if wind_in == 'means':
            t[p, 1] = 0.8 - 0.06 * speed * (p + 1) / POINTS
        else:
            t[p, 1] = 0.8 + rng.normal(0.0, 0.3)
            t[p, 2] = -3.0 + 0.3 * speed
    return t.ravel()


def write_rows(folder, head_noise, seed=5, sims=(120, 30, 30), wind_in='means'):
    """PREFIX-{train,val,test}.tsv and index.json; the head's columns are the truth plus noise."""
    rng = np.random.RandomState(seed)
    clips, sim = [], 0
    outputs = POINTS * PER_POINT
    for split, count in zip(('train', 'val', 'test'), sims):
        lines = [f'# name\twind [m/s]\tpredicted[{outputs}]\ttruth[{outputs}]  (TrackTargets\' order, '
                 f'{POINTS} points, input 64 px, 30 frames)']
        for _ in range(count):
            speed = float(rng.uniform(0, 10))
            name = f'flag-{sim:06d}-v0'
            truth = targets(speed, rng, wind_in)
            predicted = truth + rng.normal(0.0, head_noise, truth.shape)
            lines.append('\t'.join([name, f'{speed:.4f}'] + [f'{v:.6f}' for v in np.concatenate([predicted, truth])]))
            clips.append({'name': name, 'simulation': sim, 'split': split, 'wind_speed': speed})
            sim += 1
        with open(os.path.join(folder, f'rows-{split}.tsv'), 'w') as f:
            f.write('\n'.join(lines) + '\n')
    with open(os.path.join(folder, 'index.json'), 'w') as f:
        json.dump({'format': 'clothwind-dataset', 'clips': clips}, f)


def rmse_of(output):
    """The RMSE column of the report's table row."""
    row = [line for line in output.splitlines() if line.startswith('| ') and line[2].isdigit()][0]
    return float(row.split('|')[2])


class HeadOracleTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def run_oracle(self, *extra):
        env = dict(os.environ, OMP_NUM_THREADS='1')
        return subprocess.run(['/usr/bin/python3', SCRIPT, '--data', self.dir, '--rows',
                               os.path.join(self.dir, 'rows'), '--max-trees', '200', '--leaves', '7', *extra],
                              capture_output=True, text=True, env=env)

    def test_exact_targets_read_the_wind_and_a_noisy_heads_read_it_worse(self):
        write_rows(self.dir, head_noise=0.08)
        results = {}
        for columns in ('truth', 'predicted'):
            for which in ('positions', 'all'):
                done = self.run_oracle('--columns', columns, '--targets', which)
                self.assertEqual(done.returncode, 0, done.stderr)
                results[columns, which] = rmse_of(done.stdout)
        # The means droop by up to 0.6 over 10 m/s: exact ones read the wind to a few tenths.
        self.assertLess(results['truth', 'positions'], 0.6)
        # Noise of 0.08 on each mean is about 1.3 m/s of droop on one point: clearly worse.
        self.assertGreater(results['predicted', 'positions'], results['truth', 'positions'] + 0.2)
        # The amplitudes hold nothing here: adding them does not help the exact reading much.
        self.assertLess(results['truth', 'all'], results['truth', 'positions'] + 0.5)

    def test_all_targets_read_a_wind_the_amplitudes_alone_hold(self):
        # The means hold nothing, the amplitudes the wind: positions read no better than the
        # spread of winds (uniform over 0-10 m/s: 2.9 m/s), all reads it (a script that read the
        # positions whatever --targets said passed the test above, with its 0.5 m/s to spare).
        write_rows(self.dir, head_noise=0.0, wind_in='amplitudes')
        results = {}
        for which in ('positions', 'all'):
            done = self.run_oracle('--columns', 'truth', '--targets', which)
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertIn(f'truth {which} targets', done.stdout)
            results[which] = rmse_of(done.stdout)
        self.assertGreater(results['positions'], 2.0)
        self.assertLess(results['all'], 1.0)

    def test_position_noise_is_pixels_of_the_input_on_the_means_only(self):
        write_rows(self.dir, head_noise=0.0)
        path = os.path.join(self.dir, 'rows-test.tsv')
        _, _, exact = oracle.read_rows(path, 'truth', 'all')
        _, _, noisy = oracle.read_rows(path, 'truth', 'all', 2.0, np.random.RandomState(1))
        change = noisy - exact
        means = [p * PER_POINT + k for p in range(POINTS) for k in (0, 1)]
        others = [i for i in range(POINTS * PER_POINT) if i not in means]
        self.assertAlmostEqual(float(change[:, means].std()) * 64 / 2, 2.0, delta=0.3)  # 2 px of 64
        self.assertTrue(np.all(change[:, others] == 0))
        # As much noise on the exact means as the noisy head has reads about as the head does.
        write_rows(self.dir, head_noise=0.08)
        exact = rmse_of(self.run_oracle('--columns', 'truth', '--targets', 'positions').stdout)
        noisy = rmse_of(self.run_oracle('--columns', 'truth', '--targets', 'positions',
                                        '--position-noise', str(0.08 * 32)).stdout)
        self.assertGreater(noisy, exact + 0.2)

    def test_amplitudes_can_come_from_the_other_group(self):
        write_rows(self.dir, head_noise=0.1)
        path = os.path.join(self.dir, 'rows-train.tsv')
        _, _, head = oracle.read_rows(path, 'predicted', 'all')
        _, _, exact = oracle.read_rows(path, 'truth', 'all')
        _, _, mixed = oracle.read_rows(path, 'truth', 'all', amplitudes_from='predicted')
        means = [p * PER_POINT + k for p in range(POINTS) for k in (0, 1)]
        others = [i for i in range(POINTS * PER_POINT) if i not in means]
        np.testing.assert_array_equal(mixed[:, means], exact[:, means])
        np.testing.assert_array_equal(mixed[:, others], head[:, others])
        self.assertFalse(np.allclose(head, exact))
        # Exact positions of chosen points only, the rest of the row the head's.
        chosen = oracle.read_rows(path, 'predicted', 'all', exact_points=[1])[2]
        point1 = [PER_POINT, PER_POINT + 1]
        np.testing.assert_array_equal(chosen[:, point1], exact[:, point1])
        rest = [i for i in range(POINTS * PER_POINT) if i not in point1]
        np.testing.assert_array_equal(chosen[:, rest], head[:, rest])
        with self.assertRaisesRegex(ValueError, r'rows-train.tsv:1: --exact-points 3: the rows hold points 0..2'):
            oracle.read_rows(path, 'predicted', 'all', exact_points=[3])

    def test_points_keeps_those_points_targets_only(self):
        write_rows(self.dir, head_noise=0.1)
        path = os.path.join(self.dir, 'rows-train.tsv')
        _, _, every = oracle.read_rows(path, 'truth', 'all')
        _, _, two = oracle.read_rows(path, 'truth', 'all', points_kept=[0, 2])
        np.testing.assert_array_equal(two, every[:, list(range(PER_POINT)) + list(range(2 * PER_POINT, 3 * PER_POINT))])
        # With the positions only, and with a kept point's positions exact among the head's.
        _, _, head = oracle.read_rows(path, 'predicted', 'positions')
        _, _, mixed = oracle.read_rows(path, 'predicted', 'positions', exact_points=[2], points_kept=[1, 2])
        _, _, exact = oracle.read_rows(path, 'truth', 'positions')
        np.testing.assert_array_equal(mixed, np.concatenate([head[:, 2:4], exact[:, 4:6]], axis=1))
        with self.assertRaisesRegex(ValueError, r'rows-train.tsv:1: --points 5: the rows hold points 0..2'):
            oracle.read_rows(path, 'truth', 'all', points_kept=[5])
        # Through the head's noise the point that droops least reads the wind worse alone than
        # beside the other two (exact, any one point would read it as well as all three).
        all_three = rmse_of(self.run_oracle('--targets', 'positions').stdout)
        first = self.run_oracle('--targets', 'positions', '--points', '0')
        self.assertEqual(first.returncode, 0, first.stderr)
        self.assertIn("1 points' targets only", first.stdout)
        self.assertGreater(rmse_of(first.stdout), all_three)
        self.assertIn('--points: expected comma-separated', self.run_oracle('--points', 'a,b').stderr)

    def test_predictions_file_has_each_test_clip(self):
        write_rows(self.dir, head_noise=0.0)
        out = os.path.join(self.dir, 'pred.dat')
        done = self.run_oracle('--predictions', out)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(out) as f:
            lines = f.read().splitlines()
        # eval's protocol line (one window: the head's rows are one window a clip), its header,
        # then one line a clip.
        self.assertEqual(lines[0], '# protocol windows 1 mirror 0 mirror_clips 0 flag_flies right')
        self.assertEqual(len(lines), 2 + 30)
        self.assertTrue(lines[2].endswith('flag-000150-v0'))

    def test_bad_rows_are_refused_naming_the_file_and_line(self):
        write_rows(self.dir, head_noise=0.0)
        path = os.path.join(self.dir, 'rows-val.tsv')
        with open(path) as f:
            lines = f.read().splitlines()
        lines[3] = '\t'.join(lines[3].split('\t')[:-1])
        with open(path, 'w') as f:
            f.write('\n'.join(lines) + '\n')
        done = self.run_oracle()
        self.assertNotEqual(done.returncode, 0)
        self.assertIn(f'{path}:4: expected {2 + 2 * POINTS * PER_POINT} tab-separated fields', done.stderr)
        with open(path, 'w') as f:
            f.write('name wind\n')
        done = self.run_oracle()
        self.assertNotEqual(done.returncode, 0)
        self.assertIn(f'{path}:1: expected the header', done.stderr)
        self.assertNotIn('Traceback', done.stderr)


if __name__ == '__main__':
    unittest.main()
