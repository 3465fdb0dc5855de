#!/usr/bin/python3
"""Tests of scripts/track-spectrum on tracks of known motion: a sine's frequency and amplitude come
back, the window and split are the ones asked for, and bad input is refused naming what is wrong."""
import importlib.machinery
import importlib.util
import json
import math
import os
import struct
import subprocess
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, 'scripts', 'track-spectrum')
_loader = importlib.machinery.SourceFileLoader('track_spectrum', SCRIPT)
spectrum = importlib.util.module_from_spec(importlib.util.spec_from_loader('track_spectrum', _loader))
_loader.exec_module(spectrum)


def png_size(path):
    with open(path, 'rb') as f:
        head = f.read(24)
    assert head[:8] == b'\x89PNG\r\n\x1a\n', path
    return struct.unpack('>II', head[16:24])


class TrackSpectrumTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.data = os.path.join(self.tmp.name, 'data')
        self.out = os.path.join(self.tmp.name, 'spectrum.png')

    def tearDown(self):
        self.tmp.cleanup()

    def add(self, name, wind, split, xy):
        """An example folder with a label and tracks (no frames: the script reads none)."""
        folder = os.path.join(self.data, name)
        os.makedirs(folder)
        with open(os.path.join(folder, 'label.json'), 'w') as f:
            json.dump({'wind_speed': wind, 'split': split}, f)
        with open(os.path.join(folder, 'tracks.json'), 'w') as f:
            json.dump({'format': 'clothwind-tracks', 'version': 1, 'grid': [2, 1], 'width': 64,
                       'height': 64, 'vertices': [0, 1], 'xy': xy}, f)
        return folder

    @staticmethod
    def sine(frames, cycles_per_frame, amplitude, start_phase=0.3):
        """Two points 20 px apart, both moving in x as one sine: xy per frame."""
        return [[20 + amplitude * math.sin(2 * math.pi * cycles_per_frame * n + start_phase), 32,
                 40 + amplitude * math.sin(2 * math.pi * cycles_per_frame * n + start_phase), 32]
                for n in range(frames)]

    def run_script(self, *args):
        return subprocess.run([SCRIPT, self.data, self.out, *args], capture_output=True, text=True)

    def table(self, stdout):
        """The band rows: {band: (n, centroid, peak, bin-1 share, amplitude)}."""
        rows = {}
        for line in stdout.splitlines():
            parts = line.split()
            if len(parts) == 6 and '-' in parts[0] and parts[1].isdigit():
                rows[parts[0]] = (int(parts[1]), *map(float, parts[2:]))
        return rows

    def test_a_sine_on_a_bin_returns_its_frequency_and_amplitude(self):
        # Two cycles per 30-frame window at 25 fps: bin 2, 1.667 Hz. The window is centred in
        # 60 frames (frames 15..44), and 2/30 cycles a frame is whole cycles in any 30 frames.
        self.add('flag-000000-v0', 3.2, 'test', self.sine(60, 2 / 30, 4.0))
        r = self.run_script('--band', '1')
        self.assertEqual(r.returncode, 0, r.stderr)
        n, centroid, peak, bin1, amplitude = self.table(r.stdout)['3-4']
        self.assertEqual(n, 1)
        self.assertAlmostEqual(peak, 2 * 25 / 30, places=2)
        self.assertAlmostEqual(centroid, 2 * 25 / 30, delta=0.03)  # Hann leaks to bins 1 and 3 alike
        # rms of a sine of amplitude 4 over whole cycles, over a flag 10 px in rms radius
        self.assertAlmostEqual(amplitude, 4 / math.sqrt(2) / 10, delta=0.002)
        self.assertLess(bin1, 0.3)
        self.assertEqual(png_size(self.out), (1000, 420))

    def test_a_faster_wind_band_reads_a_higher_frequency(self):
        self.add('flag-000000-v0', 1.5, 'test', self.sine(60, 1 / 30, 3.0))
        self.add('flag-000001-v0', 8.5, 'test', self.sine(60, 3 / 30, 3.0))
        self.add('flag-000002-v0', 5.0, 'train', self.sine(60, 5 / 30, 3.0))
        rows = self.table(self.run_script().stdout)
        self.assertEqual(sorted(rows), ['0-2', '8-10'])  # the training example is not read
        self.assertAlmostEqual(rows['0-2'][2], 25 / 30, places=2)
        self.assertAlmostEqual(rows['8-10'][2], 3 * 25 / 30, places=2)
        self.assertGreater(rows['0-2'][3], rows['8-10'][3])  # bin-1 share
        rows = self.table(self.run_script('--split', 'all').stdout)
        self.assertIn('4-6', rows)

    def test_the_window_is_the_one_asked_for(self):
        # Frames 0..29 move at bin 1, frames 30..59 at bin 4: the offset picks which is read.
        xy = self.sine(30, 1 / 30, 3.0) + self.sine(30, 4 / 30, 3.0)
        self.add('flag-000000-v0', 0.5, 'test', xy)
        self.assertAlmostEqual(self.table(self.run_script('--offset', '0').stdout)['0-2'][2], 25 / 30, places=2)
        self.assertAlmostEqual(self.table(self.run_script('--offset', '30').stdout)['0-2'][2], 4 * 25 / 30,
                               places=2)

    def test_refusals_name_what_is_wrong(self):
        folder = self.add('flag-000000-v0', 2.0, 'test', self.sine(40, 2 / 30, 3.0))
        r = self.run_script('--offset', '20')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('tracks.json: 40 frames, window [20, 50) does not fit', r.stderr)
        r = self.run_script('--window', '2')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('--window 2: expected at least 4 frames', r.stderr)
        r = self.run_script('--split', 'val')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("no example of split 'val' with tracks.json", r.stderr)
        with open(os.path.join(folder, 'label.json'), 'w') as f:
            f.write('{"split": "test",')
        r = self.run_script()
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(os.path.join(folder, 'label.json'), r.stderr)
        self.assertFalse(os.path.exists(self.out))

    def test_a_missing_or_malformed_field_is_named(self):
        # Each ended in a traceback (KeyError, IndexError, ValueError) instead of naming the field.
        folder = self.add('flag-000000-v0', 2.0, 'test', self.sine(40, 2 / 30, 3.0))
        tracks_path = os.path.join(folder, 'tracks.json')
        with open(tracks_path) as f:
            good = f.read()
        for change, expected in [
                (lambda t: t.pop('xy'), "tracks.json: field 'xy' must be a list of frames"),
                (lambda t: t['xy'][7].pop(), "tracks.json: field 'xy' frame 7 must be 4 numbers, as frame 0; got 3"),
                (lambda t: t['xy'][3].__setitem__(1, None), "tracks.json: field 'xy' frame 3 must be 4 numbers, "
                                                            'as frame 0; got entry 1 null')]:
            with self.subTest(expected=expected):
                t = json.loads(good)
                change(t)
                with open(tracks_path, 'w') as f:
                    json.dump(t, f)
                r = self.run_script()
                self.assertNotEqual(r.returncode, 0)
                self.assertIn(expected, r.stderr)
                self.assertIn(folder, r.stderr)
                self.assertNotIn('Traceback', r.stderr)
                self.assertFalse(os.path.exists(self.out))
        with open(tracks_path, 'w') as f:
            f.write(good)
        with open(os.path.join(folder, 'label.json'), 'w') as f:
            json.dump({'wind_speed': 'fast', 'split': 'test'}, f)
        r = self.run_script()
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"{folder}/label.json: field 'wind_speed' must be a number", r.stderr)
        for args, expected in [(('--offset', 'x'), "--offset 'x': expected a frame number or 'centred'"),
                               (('--fps', '0'), '--fps 0.0: expected > 0'),
                               (('--max', '-1'), '--max -1: expected >= 0')]:
            r = self.run_script(*args)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(expected, r.stderr)
            self.assertNotIn('Traceback', r.stderr)
        r = subprocess.run([SCRIPT, os.path.join(self.tmp.name, 'no-data'), self.out], capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"{os.path.join(self.tmp.name, 'no-data')}: cannot read the dataset folder", r.stderr)
        self.assertFalse(os.path.exists(self.out))

    def test_paths_with_quotes_and_newlines_reach_gnuplot(self):
        # '{path}' in the gnuplot script: a quote in the dataset's, the split's or OUT's name ended the string.
        self.data = os.path.join(self.tmp.name, "it's a \"dataset\"\nhere")
        self.add('flag-000000-v0', 3.2, "te'st", self.sine(60, 2 / 30, 4.0))
        folder = os.path.join(self.tmp.name, "o'ut")
        os.makedirs(folder)
        self.out = os.path.join(folder, "a'b.png")
        r = self.run_script('--split', "te'st")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png_size(self.out), (1000, 420))
        self.assertEqual(os.listdir(folder), ["a'b.png"])  # no temporary left

    def test_the_window_is_the_sdns_periodic_hann(self):
        # learn/spectral_layer.cc: at::hann_window(n, periodic=true). Through it a sine on bin 2
        # leaks a quarter of its amplitude into bins 1 and 3 and nothing elsewhere: powers 1:4:1,
        # so the centroid is bin 2 exactly and bin 1 holds 1/6 (the symmetric window: 0.181).
        f = spectrum.window_features(self.sine(60, 2 / 30, 4.0), 15, 30, 25.0)
        self.assertAlmostEqual(f['centroid'], 2 * 25 / 30, places=9)
        self.assertAlmostEqual(f['bin1'], 1 / 6, places=9)

    def test_a_missing_folder_is_named_before_reading(self):
        self.add('flag-000000-v0', 3.2, 'test', self.sine(60, 2 / 30, 4.0))
        folder = os.path.join(self.tmp.name, 'no-such-folder')
        r = subprocess.run([SCRIPT, self.data, os.path.join(folder, 'spectrum.png')], capture_output=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f'no folder {folder}'.encode(), r.stderr)
        self.assertNotIn(b'Traceback', r.stderr)
        self.assertNotIn(b'PNG', r.stdout)  # gnuplot wrote the picture to stdout once
        self.assertFalse(os.path.exists(folder))

    def test_a_failed_plot_leaves_no_partial_picture(self):
        # A gnuplot that writes part of its output, then fails (a full disk, a killed process).
        self.add('flag-000000-v0', 3.2, 'test', self.sine(60, 2 / 30, 4.0))
        stub = os.path.join(self.tmp.name, 'bin')
        os.makedirs(stub)
        with open(os.path.join(stub, 'gnuplot'), 'w') as f:
            f.write('#!/bin/sh\n'
                    "out=$(sed -n \"s/^set output '\\(.*\\)'$/\\1/p\")\n"
                    'printf \'\\211PNG partial\' >"$out"\n'
                    'echo "stub gnuplot: failed" >&2; exit 1\n')
        os.chmod(os.path.join(stub, 'gnuplot'), 0o755)
        with open(self.out, 'w') as f:
            f.write('an earlier picture')
        r = subprocess.run([SCRIPT, self.data, self.out], capture_output=True, text=True,
                           env=dict(os.environ, PATH=stub + os.pathsep + os.environ['PATH']))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('gnuplot failed', r.stderr)
        self.assertIn('stub gnuplot: failed', r.stderr)
        with open(self.out, 'rb') as f:
            self.assertEqual(f.read(), b'an earlier picture')  # not a partial PNG
        self.assertEqual(sorted(os.listdir(self.tmp.name)), ['bin', 'data', 'spectrum.png'])  # no temporary left


if __name__ == '__main__':
    unittest.main()
