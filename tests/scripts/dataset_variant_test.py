#!/usr/bin/python3
"""Tests of scripts/dataset-variant on a toy dataset: per-clip splits, fewer training views, links,
refusals."""
import errno
import importlib.machinery
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import unittest
from unittest import mock

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, 'scripts', 'dataset-variant')
_loader = importlib.machinery.SourceFileLoader('dataset_variant', SCRIPT)
variant = importlib.util.module_from_spec(importlib.util.spec_from_loader('dataset_variant', _loader))
_loader.exec_module(variant)


def make_dataset(folder, sims, views=4, val=0.1, test=0.2):
    """A clothwind-dataset index whose splits are per simulation, as make-dataset writes them."""
    clips = []
    for s in range(sims):
        split = ('train', 'train', 'val', 'test')[(s // 4) % 4]
        for v in range(views):
            name = f'flag-{s:06d}-v{v}'
            os.makedirs(os.path.join(folder, name))
            for f in ('000.jpg', 'label.json'):
                with open(os.path.join(folder, name, f), 'w') as out:
                    out.write(name)
            clips.append({'name': name, 'wind_speed': 0.01 * s, 'split': split, 'simulation': s, 'view': v})
    index = {'format': 'clothwind-dataset', 'version': 1, 'count': sims,
             'dataset': {'views': views, 'val_fraction': val, 'test_fraction': test}, 'clips': clips}
    with open(os.path.join(folder, 'index.json'), 'w') as out:
        json.dump(index, out)
    return index


def run(*args):
    return subprocess.run([SCRIPT, *args], capture_output=True, text=True)


class DatasetVariantTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.src = os.path.join(self.tmp.name, 'src')
        self.source_index = make_dataset(self.src, sims=250)

    def tearDown(self):
        self.tmp.cleanup()

    def resplit(self, name='dst', change=('--split-by-clip',)):
        dst = os.path.join(self.tmp.name, name)
        r = run(self.src, dst, *change)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(dst, 'index.json')) as f:
            return dst, json.load(f)

    def test_splits_are_drawn_per_clip_with_the_source_fractions(self):
        _, index = self.resplit()
        self.assertEqual(index['dataset']['variant'], 'split_by_clip')
        splits = [c['split'] for c in index['clips']]
        self.assertEqual(len(splits), 1000)
        # Binomial(1000, p) counts: 5 standard deviations either side.
        self.assertLess(abs(splits.count('test') - 200), 5 * 12.7)
        self.assertLess(abs(splits.count('val') - 100), 5 * 9.5)
        # Per clip, not per simulation: many simulations' views straddle splits.
        by_sim = {}
        for c in index['clips']:
            by_sim.setdefault(c['simulation'], set()).add(c['split'])
        self.assertGreater(sum(len(s) > 1 for s in by_sim.values()), 100)
        # Everything but the split is the source's.
        for old, new in zip(self.source_index['clips'], index['clips']):
            self.assertEqual({k: v for k, v in old.items() if k != 'split'},
                             {k: v for k, v in new.items() if k != 'split'})

    def test_the_fractions_are_the_sources_own(self):
        # Other fractions than the script's defaults (make-dataset's 0.1 and 0.2, which every
        # source here had, so fractions fixed in the script passed).
        src = os.path.join(self.tmp.name, 'src2')
        make_dataset(src, sims=250, val=0.3, test=0.15)
        dst = os.path.join(self.tmp.name, 'dst2')
        r = run(src, dst, '--split-by-clip')
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(dst, 'index.json')) as f:
            splits = [c['split'] for c in json.load(f)['clips']]
        self.assertLess(abs(splits.count('val') - 300), 5 * 14.5)   # Binomial(1000, 0.3)
        self.assertLess(abs(splits.count('test') - 150), 5 * 11.3)  # Binomial(1000, 0.15)

    def test_the_draw_is_reproducible(self):
        _, a = self.resplit('a')
        _, b = self.resplit('b')
        self.assertEqual([c['split'] for c in a['clips']], [c['split'] for c in b['clips']])

    def test_examples_are_hard_links_of_the_source(self):
        dst, _ = self.resplit()
        for f in ('000.jpg', 'label.json'):
            a = os.stat(os.path.join(self.src, 'flag-000007-v2', f))
            b = os.stat(os.path.join(dst, 'flag-000007-v2', f))
            self.assertEqual((a.st_dev, a.st_ino), (b.st_dev, b.st_ino))
        self.assertFalse(os.path.exists(dst + '.tmp'))

    def test_train_views_keeps_n_views_of_each_training_simulation_in_rotation(self):
        dst, index = self.resplit(change=('--train-views', '1'))
        self.assertEqual(index['dataset']['variant'], 'train_views_1')
        train = [c for c in index['clips'] if c['split'] == 'train']
        sims = [c['simulation'] for c in train]
        self.assertEqual(len(sims), len(set(sims)))  # one view each
        self.assertEqual(len(sims), sum((s // 4) % 4 < 2 for s in range(250)))  # every training simulation
        # Views rotate with the simulation, so each camera-angle stratum keeps a quarter.
        self.assertEqual({c['view'] for c in train}, {0, 1, 2, 3})
        for c in train:
            self.assertEqual(c['view'], c['simulation'] % 4)
        # val and test keep all their views; dropped training views are not copied.
        for split in ('val', 'test'):
            self.assertEqual(sum(c['split'] == split for c in index['clips']),
                             sum(c['split'] == split for c in self.source_index['clips']))
        self.assertFalse(os.path.exists(os.path.join(dst, 'flag-000000-v1')))
        self.assertTrue(os.path.exists(os.path.join(dst, 'flag-000008-v3')))  # a val simulation
        _, index3 = self.resplit('three', ('--train-views', '3'))
        self.assertEqual(sum(c['split'] == 'train' for c in index3['clips']), 3 * len(sims))

    def test_refuses_an_existing_destination_a_bad_index_and_bad_options(self):
        dst, _ = self.resplit()
        r = run(self.src, dst, '--split-by-clip')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('exists', r.stderr)
        bad = os.path.join(self.tmp.name, 'bad')
        os.makedirs(bad)
        with open(os.path.join(bad, 'index.json'), 'w') as f:
            json.dump({'format': 'something-else', 'clips': []}, f)
        r = run(bad, os.path.join(self.tmp.name, 'out'), '--split-by-clip')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('index.json', r.stderr)
        self.assertIn('clothwind-dataset', r.stderr)
        r = run(self.src, os.path.join(self.tmp.name, 'out'), '--train-views', '5')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('--train-views must be in [1, 4]', r.stderr)
        os.makedirs(os.path.join(self.tmp.name, 'busy.tmp'))  # another run's, or a killed one's
        r = run(self.src, os.path.join(self.tmp.name, 'busy'), '--split-by-clip')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('busy.tmp: exists', r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.tmp.name, 'busy')))
        r = run(self.src, os.path.join(self.tmp.name, 'out'))  # no change named
        self.assertNotEqual(r.returncode, 0)
        self.assertFalse(os.path.exists(os.path.join(self.tmp.name, 'out')))
        # A DST whose parent is not there: said naming it (a FileNotFoundError traceback).
        r = run(self.src, os.path.join(self.tmp.name, 'nodir', 'x'), '--split-by-clip')
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn('nodir/x.tmp: cannot create it', r.stderr)
        self.assertNotIn('Traceback', r.stderr)

    def edit_index(self, change):
        path = os.path.join(self.src, 'index.json')
        with open(path) as f:
            index = json.load(f)
        change(index)
        with open(path, 'w') as f:
            json.dump(index, f)

    def test_a_clip_without_a_split_takes_its_labels(self):
        # A hand-made index: the split read as train reads it (the index's, else label.json's), and
        # every check made before DST.tmp exists (a KeyError came after DST was renamed into place).
        self.edit_index(lambda index: [c.pop('split') for c in index['clips'] if c['name'] in
                                       ('flag-000000-v1', 'flag-000008-v0')])
        dst = os.path.join(self.tmp.name, 'dst')
        r = run(self.src, dst, '--train-views', '1')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"{os.path.join(self.src, 'flag-000000-v1', 'label.json')}: cannot read the label, "
                      f"where clips[1] of {os.path.join(self.src, 'index.json')} has no split", r.stderr)
        self.assertNotIn('Traceback', r.stderr)
        self.assertFalse(os.path.exists(dst) or os.path.exists(dst + '.tmp'))
        for name, split in (('flag-000000-v1', 'holdout'), ('flag-000008-v0', 'val')):
            with open(os.path.join(self.src, name, 'label.json'), 'w') as f:
                json.dump({'split': split}, f)
        r = run(self.src, dst, '--train-views', '1')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"flag-000000-v1/label.json: field 'split' (clips[1] of {self.src}/index.json has none) "
                      'must be "train", "val" or "test", got "holdout"', r.stderr)
        self.assertFalse(os.path.exists(dst) or os.path.exists(dst + '.tmp'))
        with open(os.path.join(self.src, 'flag-000000-v1', 'label.json'), 'w') as f:
            json.dump({'split': 'train'}, f)
        dst, index = self.resplit(change=('--train-views', '1'))
        names = [c['name'] for c in index['clips']]
        self.assertNotIn('flag-000000-v1', names)  # a training view, dropped as its index said "train"
        self.assertIn('flag-000008-v0', names)  # a val clip, kept with its siblings
        self.assertNotIn('split', index['clips'][names.index('flag-000008-v0')])  # the index as it was
        expected = run(self.src, os.path.join(self.tmp.name, 'again'), '--train-views', '1').stdout
        self.assertIn(f'{sum((s // 4) % 4 < 2 for s in range(250))} train clips', expected)
        self.assertIn(f'{sum((s // 4) % 4 == 2 for s in range(250)) * 4} val', expected)

    def test_a_malformed_index_is_refused_before_anything_is_written(self):
        dst = os.path.join(self.tmp.name, 'dst')
        index_path = os.path.join(self.src, 'index.json')
        for change, expected in [
                (lambda index: index['clips'].__setitem__(3, 5), 'clips[3] must be an object, got 5'),
                (lambda index: index['clips'][3].__setitem__('split', ['x']),
                 'clips[3].split must be "train", "val" or "test", got ["x"]'),
                (lambda index: index.__setitem__('dataset', [1]), "field 'dataset' must be an object"),
                (lambda index: index['dataset'].__setitem__('views', 'four'),
                 'fields dataset.views, dataset.val_fraction and dataset.test_fraction must be numbers, got "four"')]:
            with self.subTest(expected=expected):
                with open(index_path) as f:
                    good = f.read()
                self.edit_index(change)
                r = run(self.src, dst, '--train-views', '1')
                with open(index_path, 'w') as f:
                    f.write(good)
                self.assertNotEqual(r.returncode, 0)
                self.assertIn(f'{index_path}: {expected}', r.stderr)
                self.assertNotIn('Traceback', r.stderr)
                self.assertFalse(os.path.exists(dst) or os.path.exists(dst + '.tmp'))

    def test_a_variant_is_not_a_source(self):
        # Its header would name one change where the copy differs from the original by two.
        dst, _ = self.resplit()
        again = os.path.join(self.tmp.name, 'again')
        r = run(dst, again, '--train-views', '1')
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"{os.path.join(dst, 'index.json')}: dataset.variant is 'split_by_clip'", r.stderr)
        self.assertFalse(os.path.exists(again) or os.path.exists(again + '.tmp'))

    def test_a_copy_failing_half_way_leaves_nothing(self):
        # A DST on another filesystem: hard links fail with EXDEV, here after a few have been made.
        dst = os.path.join(self.tmp.name, 'elsewhere')
        real_link, calls = os.link, []

        def link(a, b, **kw):
            calls.append(a)
            if len(calls) > 5:
                raise OSError(errno.EXDEV, os.strerror(errno.EXDEV), a, None, b)
            return real_link(a, b, **kw)

        with mock.patch.object(sys, 'argv', ['dataset-variant', self.src, dst, '--split-by-clip']), \
                mock.patch.object(variant.os, 'link', link), self.assertRaises(SystemExit) as e:
            variant.main()
        message = str(e.exception.code)
        self.assertIn(f'{calls[-1]} -> {os.path.join(dst + ".tmp", os.path.relpath(calls[-1], self.src))}', message)
        self.assertIn("DST must be on SRC's filesystem", message)
        self.assertIn(f'{dst}.tmp removed', message)
        self.assertFalse(os.path.exists(dst) or os.path.exists(dst + '.tmp'))
        # The source keeps every file.
        self.assertEqual(sorted(os.listdir(os.path.join(self.src, 'flag-000000-v0'))), ['000.jpg', 'label.json'])
        r = run(self.src, dst, '--split-by-clip')  # and a run that can link is not in its way
        self.assertEqual(r.returncode, 0, r.stderr)


if __name__ == '__main__':
    unittest.main()
