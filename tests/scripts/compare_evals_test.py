#!/usr/bin/python3
"""Tests of scripts/compare-evals on generated evaluations: the difference and its interval find a
real gap and hold 0 for none, resampling by simulation widens the interval when views share their
errors, and bad input is refused naming the file and line."""
import importlib.machinery
import importlib.util
import math
import os
import random
import subprocess
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, 'scripts', 'compare-evals')
_loader = importlib.machinery.SourceFileLoader('compare_evals', SCRIPT)
ce = importlib.util.module_from_spec(importlib.util.spec_from_loader('compare_evals', _loader))
_loader.exec_module(ce)


def clips(sims, views, shared, own, seed):
    """Clips of `sims` simulations seen `views` times each: [(name, true, error)], where each
    error is a simulation's shared part (sd `shared`) plus the view's own (sd `own`)."""
    rng = random.Random(seed)
    out = []
    for s in range(sims):
        true, common = rng.uniform(0, 10), rng.gauss(0, shared)
        for v in range(views):
            out.append((f'flag-{s:06d}-v{v}', true, common + rng.gauss(0, own)))
    return out


def write_dat(path, rows):
    """Writes rows [(name, true, predicted)] as `clothwind eval --plot` writes X.png.dat."""
    with open(path, 'w') as f:
        f.write('# true_speed predicted_speed predicted_std name\n')
        for name, true, pred in rows:
            f.write(f'{true:.6g} {pred:.6g} 0.3 {name}\n')


def rows_of(a, b):
    """compare()'s rows for two models' errors on the same clips."""
    return [(ce.simulation_of(n), t, t + ea, t + eb) for (n, t, ea), (_, _, eb) in zip(a, b)]


class CompareTest(unittest.TestCase):
    def test_the_same_predictions_differ_by_nothing(self):
        a = clips(300, 4, 0.2, 0.2, 1)
        r = ce.compare(rows_of(a, a), resamples=500)
        self.assertEqual(r['diff'], 0.0)
        self.assertEqual((r['lo'], r['hi']), (0.0, 0.0))
        self.assertAlmostEqual(r['corr'], 1.0, places=12)
        self.assertEqual((r['clips'], r['groups']), (1200, 300))

    def test_halved_errors_are_found_with_an_interval_around_the_gap(self):
        a = clips(600, 4, 0.2, 0.2, 2)
        b = [(n, t, e / 2) for n, t, e in a]
        r = ce.compare(rows_of(a, b), resamples=1000)
        self.assertAlmostEqual(r['rmse_b'], r['rmse_a'] / 2, places=12)
        self.assertAlmostEqual(r['diff'], -r['rmse_a'] / 2, places=12)
        self.assertLess(r['hi'], 0.0)
        self.assertLess(r['lo'], r['diff'])
        self.assertGreater(r['hi'], r['diff'])

    def test_two_equally_good_models_are_not_told_apart(self):
        a = clips(600, 4, 0.25, 0.15, 3)
        rng = random.Random(4)
        # The same simulation-shared error, fresh per-view noise of the same size: equally good.
        b = [(n, t, e + rng.gauss(0, 0.1)) for n, t, e in a]
        a2 = [(n, t, e + rng.gauss(0, 0.1)) for n, t, e in a]
        r = ce.compare(rows_of(a2, b), resamples=1000)
        self.assertLessEqual(r['lo'], 0.0)
        self.assertGreaterEqual(r['hi'], 0.0)
        self.assertGreater(r['corr'], 0.6)

    def test_views_that_share_their_errors_widen_the_interval(self):
        # Errors shared by a simulation's views: resampling clips alone would count each
        # simulation's error four times as evidence; resampling simulations does not.
        a = clips(400, 4, 0.3, 0.02, 5)
        rng = random.Random(6)
        b = []
        for i in range(0, len(a), 4):
            shift = rng.gauss(0, 0.3)
            b += [(n, t, e * 0.5 + shift) for n, t, e in a[i:i + 4]]
        rows = rows_of(a, b)
        by_sim = ce.compare(rows, resamples=1000)
        by_clip = ce.compare([(f'c{i}',) + r[1:] for i, r in enumerate(rows)], resamples=1000)
        self.assertEqual(by_clip['groups'], 1600)
        self.assertAlmostEqual(by_sim['diff'], by_clip['diff'], places=12)
        self.assertGreater(by_sim['hi'] - by_sim['lo'], 1.5 * (by_clip['hi'] - by_clip['lo']))

    def test_acc05_counts_errors_within_half_a_metre_per_second(self):
        rows = [('s0', 5.0, 5.4, 5.6), ('s1', 5.0, 4.4, 5.0), ('s2', 2.0, 2.5, 1.0), ('s3', 1.0, 1.0, 1.0)]
        r = ce.compare(rows, resamples=100)
        self.assertEqual((r['acc_a'], r['acc_b']), (0.75, 0.5))  # 0.5 itself counts
        self.assertAlmostEqual(r['rmse_a'], math.sqrt((0.16 + 0.36 + 0.25) / 4), places=12)

    def test_simulation_of_a_flagsim_view_and_of_other_clips(self):
        self.assertEqual(ce.simulation_of('flag-000123-v2'), 'flag-000123')
        self.assertEqual(ce.simulation_of('cloth-000007-v10'), 'cloth-000007')
        self.assertEqual(ce.simulation_of('clip-20231114-221319.999-000000'), 'clip-20231114-221319.999-000000')


class CommandTest(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([SCRIPT, *args], capture_output=True, text=True)

    def test_prints_both_models_and_the_difference(self):
        with tempfile.TemporaryDirectory() as d:
            a = clips(200, 4, 0.2, 0.2, 7)
            pa, pb = os.path.join(d, 'a.png.dat'), os.path.join(d, 'b.png.dat')
            write_dat(pa, [(n, t, t + e) for n, t, e in a])
            write_dat(pb, [(n, t, t + e / 2) for n, t, e in reversed(a)])  # order does not matter
            r = self.run_script(pa, pb, '--resamples', '500')
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn('800 clips in 200 simulations', r.stdout)
            self.assertIn('B - A: RMSE -0.', r.stdout)
            self.assertNotIn('do not tell the two apart', r.stdout)
            r = self.run_script(pa, pa, '--resamples', '500')
            self.assertIn('B - A: RMSE +0.0000', r.stdout)
            self.assertIn('do not tell the two apart', r.stdout)

    def test_bad_input_names_the_file_and_line(self):
        with tempfile.TemporaryDirectory() as d:
            good, bad = os.path.join(d, 'good.dat'), os.path.join(d, 'bad.dat')
            write_dat(good, [('flag-000000-v0', 1.0, 1.1), ('flag-000000-v1', 1.0, 0.9)])
            with open(bad, 'w') as f:
                f.write('# header\n1.0 1.1 0.3 flag-000000-v0\n1.0 0.9 flag-000000-v1\n')
            r = self.run_script(good, bad)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(f'{bad}:3: expected 4 fields', r.stderr)
            with open(bad, 'w') as f:
                f.write('1.0 x 0.3 flag-000000-v0\n')
            # Each refused: a failing exit, the message naming what is wrong.
            def refused(r, text):
                self.assertNotEqual(r.returncode, 0, r.stdout)
                self.assertIn(text, r.stderr)
            refused(self.run_script(good, bad), f'{bad}:1: true and predicted speed must be numbers')
            write_dat(bad, [('flag-000000-v0', 1.0, 1.1)])
            refused(self.run_script(good, bad), f'1 clips of {good} are not in {bad} (first: flag-000000-v1)')
            write_dat(bad, [('flag-000000-v0', 1.0, 1.1), ('flag-000000-v1', 2.0, 0.9)])
            refused(self.run_script(good, bad), 'clip flag-000000-v1: true speed 1.0')
            refused(self.run_script(good, os.path.join(d, 'missing.dat')), 'missing.dat')

    def test_non_finite_speeds_are_refused_naming_the_file_and_line(self):
        # float() reads these: a nan or inf clip once gave "RMSE nan" and exit 0.
        with tempfile.TemporaryDirectory() as d:
            good, bad = os.path.join(d, 'good.dat'), os.path.join(d, 'bad.dat')
            write_dat(good, [('flag-000000-v0', 1.0, 1.1), ('flag-000000-v1', 1.0, 0.9)])
            for true, pred in (('1.0', 'nan'), ('1.0', 'inf'), ('-inf', '0.9'), ('NaN', '0.9')):
                with open(bad, 'w') as f:
                    f.write(f'# header\n1.0 1.1 0.3 flag-000000-v0\n{true} {pred} 0.3 flag-000000-v1\n')
                for a, b in ((good, bad), (bad, good)):
                    r = self.run_script(a, b, '--resamples', '100')
                    self.assertNotEqual(r.returncode, 0, r.stdout)
                    self.assertIn(f'{bad}:3: true and predicted speed must be finite, got {true} {pred}', r.stderr)

    def test_speeds_beyond_any_wind_and_binary_files_are_refused_by_name(self):
        # 1e200 squared is inf: the RMSE and its interval came out inf with exit 0; a binary file
        # ended in a UnicodeDecodeError traceback naming no file.
        with tempfile.TemporaryDirectory() as d:
            good, bad = os.path.join(d, 'good.dat'), os.path.join(d, 'bad.dat')
            write_dat(good, [('flag-000000-v0', 1.0, 1.1), ('flag-000000-v1', 1.0, 0.9)])
            with open(bad, 'w') as f:
                f.write('# header\n1.0 1.1 0.3 flag-000000-v0\n1.0 1e200 0.3 flag-000000-v1\n')
            r = self.run_script(good, bad, '--resamples', '100')
            self.assertNotEqual(r.returncode, 0, r.stdout)
            self.assertIn(f'{bad}:3: speeds must be wind speeds', r.stderr)
            with open(bad, 'wb') as f:
                f.write(b'\xff\xfe\x00binary')
            r = self.run_script(good, bad, '--resamples', '100')
            self.assertNotEqual(r.returncode, 0, r.stdout)
            self.assertIn(f'{bad}: not a text file', r.stderr)
            self.assertNotIn('Traceback', r.stderr)

    def test_evaluations_read_two_ways_are_not_paired(self):
        # One window against three windows per clip: the protocol, not the model, would differ.
        with tempfile.TemporaryDirectory() as d:
            rows = [('flag-000000-v0', 1.0, 1.1), ('flag-000000-v1', 1.0, 0.9), ('flag-000001-v0', 2.0, 2.2)]
            one, three, old = (os.path.join(d, n) for n in ('one.dat', 'three.dat', 'old.dat'))
            for path, protocol in ((one, 'windows 1 mirror 0 mirror_clips 0 flag_flies right'),
                                   (three, 'windows 3 mirror 0 mirror_clips 0 flag_flies right')):
                write_dat(path, rows)
                with open(path) as f:
                    text = f.read()
                with open(path, 'w') as f:
                    f.write(f'# protocol {protocol}\n' + text)
            write_dat(old, rows)  # written before eval recorded its protocol
            r = self.run_script(one, three, '--resamples', '100')
            self.assertNotEqual(r.returncode, 0, r.stdout)
            self.assertIn('"windows 3 mirror 0 mirror_clips 0 flag_flies right"', r.stderr)
            self.assertEqual(self.run_script(one, one, '--resamples', '100').returncode, 0)
            self.assertEqual(self.run_script(one, old, '--resamples', '100').returncode, 0)


if __name__ == '__main__':
    unittest.main()
