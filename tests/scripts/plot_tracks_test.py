#!/usr/bin/python3
"""Tests of scripts/plot-tracks on a tiny example: a picture per frame named, refusals naming the file."""
import json
import os
import struct
import subprocess
import tempfile
import unittest
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, 'scripts', 'plot-tracks')


def write_png(path, width, height, grey):
    """An 8-bit RGB PNG of one grey level (the standard library's zlib, no image module)."""
    def chunk(kind, data):
        return struct.pack('>I', len(data)) + kind + data + struct.pack('>I', zlib.crc32(kind + data))
    rows = b''.join(b'\x00' + bytes([grey, grey, grey]) * width for _ in range(height))
    with open(path, 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', width, height, 8, 2, 0, 0, 0)) +
                chunk(b'IDAT', zlib.compress(rows)) + chunk(b'IEND', b''))


def png_size(path):
    with open(path, 'rb') as f:
        head = f.read(24)
    assert head[:8] == b'\x89PNG\r\n\x1a\n', path
    return struct.unpack('>II', head[16:24])


class PlotTracksTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.example = os.path.join(self.tmp.name, 'flag-000000-v0')
        os.makedirs(self.example)
        for k in range(4):
            write_png(os.path.join(self.example, f'{k:03d}.png'), 48, 32, 40 * k)  # wider than high
        self.tracks = {'format': 'clothwind-tracks', 'version': 1, 'grid': [1, 2], 'width': 48, 'height': 32,
                       'vertices': [0, 1], 'xy': [[10 + k, 8, 10 + k, 24] for k in range(4)]}
        self.write_tracks()

    def tearDown(self):
        self.tmp.cleanup()

    def write_tracks(self):
        with open(os.path.join(self.example, 'tracks.json'), 'w') as f:
            json.dump(self.tracks, f)

    def run_script(self, *args):
        return subprocess.run([SCRIPT, self.example, *args], capture_output=True, text=True)

    def test_one_panel_per_frame(self):
        out = os.path.join(self.tmp.name, 'a.png')
        r = self.run_script(out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png_size(out), (900, 330))  # first, middle, last: three 300-px panels
        r = self.run_script(out, '--frames', '2,3')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png_size(out), (600, 330))

    def test_each_panel_shows_its_own_frame_and_points(self):
        # The PNG's size says only how many panels there are: a script plotting frames 0 and 1 for
        # --frames 2,3, or no points at all, passed. A gnuplot stub keeps the script and its data.
        stub, capture = os.path.join(self.tmp.name, 'bin'), os.path.join(self.tmp.name, 'capture')
        os.makedirs(stub)
        os.makedirs(capture)
        with open(os.path.join(stub, 'gnuplot'), 'w') as f:
            f.write('#!/usr/bin/python3\n'
                    'import os, re, shutil, sys\n'
                    'text = sys.stdin.read()\n'
                    'cap = os.environ["CAPTURE"]\n'
                    'open(os.path.join(cap, "script.gp"), "w").write(text)\n'
                    'for path in re.findall(r"\'([^\']*\\.dat)\'", text):\n'
                    '    shutil.copy(path, cap)\n'
                    'open(re.search(r"set output \'([^\']*)\'", text).group(1), "w").write("stub")\n')
        os.chmod(os.path.join(stub, 'gnuplot'), 0o755)
        out = os.path.join(self.tmp.name, 'a.png')
        r = subprocess.run([SCRIPT, self.example, out, '--frames', '2,3'], capture_output=True, text=True,
                           env=dict(os.environ, CAPTURE=capture, PATH=stub + os.pathsep + os.environ['PATH']))
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(capture, 'script.gp')) as f:
            script = f.read()
        # The picture's axes: x across its width, y down its height (an upward y axis, or the two
        # swapped, plotted every point off its place; square frames hid the swap).
        self.assertIn('set xrange [0:48]; set yrange [32:0]', script)
        titles = [line for line in script.splitlines() if line.startswith('set title')]
        self.assertEqual(titles, ["set title 'frame 2'", "set title 'frame 3'"])
        self.assertIn(os.path.join(self.example, '002.png'), script)
        self.assertIn(os.path.join(self.example, '003.png'), script)
        self.assertNotIn('000.png', script)
        for k in (2, 3):  # frame k's two points: (10 + k, 8) and (10 + k, 24)
            with open(os.path.join(capture, f'{k}.dat')) as f:
                self.assertEqual(f.read(), f'{10 + k} 8\n{10 + k} 24\n')
        with open(os.path.join(capture, 'paths.dat')) as f:  # each point's path over all 4 frames
            self.assertEqual(f.read(), ''.join(f'{10 + k} 8\n' for k in range(4)) + '\n' +
                             ''.join(f'{10 + k} 24\n' for k in range(4)) + '\n')

    def test_refusals_name_what_is_wrong(self):
        out = os.path.join(self.tmp.name, 'b.png')
        r = self.run_script(out, '--frames', '0,4')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('frame 4 outside 0..3', r.stderr)
        self.tracks['format'] = 'clothwind-dataset'
        self.write_tracks()
        r = self.run_script(out)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("tracks.json: field 'format'", r.stderr)
        os.remove(os.path.join(self.example, 'tracks.json'))
        r = self.run_script(out)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(os.path.join(self.example, 'tracks.json'), r.stderr)
        self.assertFalse(os.path.exists(out))

    def test_a_missing_or_malformed_field_is_named(self):
        # Each ended in a traceback (KeyError, IndexError) instead of naming the field.
        out = os.path.join(self.tmp.name, 'e.png')
        path = os.path.join(self.example, 'tracks.json')
        good = json.loads(json.dumps(self.tracks))
        for field, change, expected in [
                ('xy', lambda t: t.pop('xy'), "field 'xy' must be a list of frames"),
                ('width', lambda t: t.pop('width'), "field 'width' must be a positive number of pixels; it is missing"),
                ('grid', lambda t: t.pop('grid'), "field 'grid' must be [cols, rows]"),
                ('grid', lambda t: t.update(grid=[2]), "field 'grid' must be [cols, rows], positive integers; got [2]"),
                ('xy', lambda t: t['xy'][2].pop(), "field 'xy' frame 2 must be 4 numbers"),
                ('xy', lambda t: t['xy'][1].__setitem__(3, 'a'), 'got entry 3 "a"')]:
            with self.subTest(field=field, expected=expected):
                self.tracks = json.loads(json.dumps(good))
                change(self.tracks)
                self.write_tracks()
                r = self.run_script(out)
                self.assertNotEqual(r.returncode, 0)
                self.assertIn(f'{path}: ', r.stderr)
                self.assertIn(expected, r.stderr)
                self.assertNotIn('Traceback', r.stderr)
                self.assertFalse(os.path.exists(out))

    def test_a_malformed_frame_list_is_named(self):
        out = os.path.join(self.tmp.name, 'f.png')
        r = self.run_script(out, '--frames', '1,,2')  # a ValueError traceback
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--frames '1,,2': expected frame numbers separated by commas", r.stderr)
        self.assertNotIn('Traceback', r.stderr)
        self.assertFalse(os.path.exists(out))

    def test_paths_with_quotes_and_newlines_reach_gnuplot(self):
        # '{path}' in the gnuplot script: a quote in the example's or OUT's name ended the string.
        example = os.path.join(self.tmp.name, "it's a \"flag\"\nexample")
        os.rename(self.example, example)
        self.example = example
        folder = os.path.join(self.tmp.name, "o'ut")
        os.makedirs(folder)
        out = os.path.join(folder, "a'b.png")
        r = self.run_script(out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png_size(out), (900, 330))
        self.assertEqual(os.listdir(folder), ["a'b.png"])  # no temporary left

    def test_a_missing_folder_is_named(self):
        # gnuplot could not open OUT there and wrote the PNG's bytes to stdout (a decoding traceback).
        folder = os.path.join(self.tmp.name, 'no-such-folder')
        r = subprocess.run([SCRIPT, self.example, os.path.join(folder, 'a.png')], capture_output=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f'no folder {folder}'.encode(), r.stderr)
        self.assertNotIn(b'Traceback', r.stderr)
        self.assertEqual(r.stdout, b'')
        self.assertFalse(os.path.exists(folder))

    def test_a_failed_plot_leaves_no_partial_picture(self):
        out = os.path.join(self.tmp.name, 'c.png')
        with open(out, 'w') as f:
            f.write('an earlier picture')
        with open(os.path.join(self.example, '001.png'), 'wb') as f:
            f.write(b'not a PNG')  # gnuplot fails on the second panel, after opening its output
        r = self.run_script(out)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('gnuplot failed', r.stderr)
        with open(out, 'rb') as f:
            self.assertEqual(f.read(), b'an earlier picture')  # not a partial PNG
        self.assertEqual(sorted(os.listdir(self.tmp.name)), ['c.png', 'flag-000000-v0'])  # no temporary left

    def test_the_picture_gets_the_usual_permissions(self):
        out = os.path.join(self.tmp.name, 'd.png')
        old = os.umask(0o022)
        try:
            r = self.run_script(out)
        finally:
            os.umask(old)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(os.stat(out).st_mode & 0o777, 0o644)


if __name__ == '__main__':
    unittest.main()
