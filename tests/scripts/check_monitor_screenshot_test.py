#!/usr/bin/python3
"""Tests of scripts/check-monitor-screenshot's reading of the PPM that ImageMagick's `convert`
gives it (a stand-in `convert` on PATH prints a prepared PPM, so ImageMagick is not needed): the
pixels start right after the header's one whitespace byte, whatever their values."""
import os
import random
import subprocess
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, 'scripts', 'check-monitor-screenshot')
W, H = 128, 96


def screenshot_pixels(first, estimate_pixels=400):
    """W x H RGB bytes that pass every check: random colours (thousands, every tile busy), 400
    pixels of each wind plot series' colour (`estimate_pixels` of the estimate's), and `first` as
    the first pixel."""
    rng = random.Random(5)
    pixels = [(rng.randrange(256), rng.randrange(256), rng.randrange(256)) for _ in range(W * H)]
    pixels[0] = first
    for i in range(estimate_pixels):
        pixels[1000 + i] = (255, 140, 0)    # estimate orange
    for i in range(400):
        pixels[3000 + i] = (0, 110, 200)    # anemometer blue
    return b''.join(bytes(p) for p in pixels)


class CheckMonitorScreenshotTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.ppm = os.path.join(self.tmp.name, 'shot.ppm')
        stub = os.path.join(self.tmp.name, 'bin')
        os.makedirs(stub)
        with open(os.path.join(stub, 'convert'), 'w') as f:
            f.write(f'#!/bin/sh\ncat "{self.ppm}"\n')  # convert SHOT.png -depth 8 ppm:-
        os.chmod(os.path.join(stub, 'convert'), 0o755)
        self.env = dict(os.environ, PATH=stub + os.pathsep + os.environ['PATH'])

    def tearDown(self):
        self.tmp.cleanup()

    def check(self, ppm):
        with open(self.ppm, 'wb') as f:
            f.write(ppm)
        return subprocess.run([SCRIPT, 'shot.png'], capture_output=True, text=True, env=self.env)

    def test_a_first_pixel_of_whitespace_bytes_is_a_pixel(self):
        # (32, 32, 32) is three spaces: a split at whitespace took them for the header's end.
        for first in ((32, 32, 32), (10, 9, 13), (200, 10, 30)):
            r = self.check(f'P6\n{W} {H}\n255\n'.encode() + screenshot_pixels(first))
            self.assertEqual(r.returncode, 0, f'{first}: {r.stdout}{r.stderr}')
            self.assertIn(f'shot.png: {W}x{H}, ', r.stdout)
            self.assertIn('OK', r.stdout)

    def test_header_whitespace_and_comments(self):
        pixels = screenshot_pixels((32, 32, 32))
        r = self.check(f'P6 # made by a test\n{W}\t{H}\r\n# a comment\n255 '.encode() + pixels)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn(f'{W}x{H}', r.stdout)

    def test_a_plot_without_its_estimate_series_fails(self):
        # A monitor with no estimate showed 135 orange pixels (the legend's swatch, rviz's status
        # labels) and passed a threshold of 40.
        r = self.check(f'P6\n{W} {H}\n255\n'.encode() + screenshot_pixels((32, 32, 32), estimate_pixels=135))
        self.assertNotEqual(r.returncode, 0, r.stdout)
        self.assertIn('estimate-coloured pixels (expected >= 300', r.stderr)

    def test_what_is_not_an_8_bit_p6_is_refused_naming_the_file(self):
        pixels = screenshot_pixels((32, 32, 32))
        for ppm, message in ((b'P3\n2 2\n255\n1 2 3', 'convert gave no P6 image'),
                             (f'P6\n{W} {H}\n65535\n'.encode() + pixels, 'expected 8-bit samples (maxval 255), got maxval 65535'),
                             (f'P6\n{W} {H}\n255\n'.encode() + pixels[:-1], 'truncated pixel data')):
            r = self.check(ppm)
            self.assertNotEqual(r.returncode, 0, message)
            self.assertIn(f'shot.png: {message}', r.stderr)
            self.assertNotIn('Traceback', r.stderr)


if __name__ == '__main__':
    unittest.main()
