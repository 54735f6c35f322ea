"""tools/sheet_quality.py's zig-zag measure tells a fold the grid resolves from a crinkle at the
grid's own scale, and its crossing count tells a sheet folded onto itself from one passing
through itself, on sheets made here."""

import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools"))
import sheet_quality  # noqa: E402


def sheet(m, n, height):
    k, l = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
    r = np.zeros((m, n, 3))
    r[..., 0] = k * 0.01
    r[..., 2] = l * 0.01
    r[..., 1] = height(k, l)
    return r


class ZigZag(unittest.TestCase):
    def test_a_resolved_fold_has_the_share_of_its_wavelength(self):
        # A fold 20 nodes long: share sin²(π/20) = 0.024 (the docstring), amplitude its
        # third difference, (2 sin(π/20))³ 0.05 / 8 = 2.3e-4 m, far below a crinkle's.
        r = sheet(41, 41, lambda k, l: 0.05 * np.sin(2 * np.pi * k / 20.0))
        amplitude, share = sheet_quality.zigzag(r)
        self.assertAlmostEqual(share, np.sin(np.pi / 20.0) ** 2, delta=0.1 * 0.0245)
        self.assertLess(amplitude, 3e-4)

    def test_a_crinkle_at_the_grid_scale_is_measured_by_its_amplitude(self):
        a = 2e-3
        r = sheet(41, 41, lambda k, l: 0.05 * np.sin(2 * np.pi * k / 20.0) + a * (-1.0) ** l)
        amplitude, share = sheet_quality.zigzag(r)
        self.assertAlmostEqual(amplitude, a, delta=1e-3 * a)
        self.assertGreater(share, 0.5)

    def test_a_flat_sheet_has_none(self):
        amplitude, share = sheet_quality.zigzag(sheet(10, 10, lambda k, l: 0.0 * k))
        self.assertLess(amplitude, 1e-15)
        self.assertIsNone(share)

    def test_rounding_noise_on_a_flat_sheet_has_no_share(self):
        # A flat sheet 1 m up, its heights off by a few ulps at random: the second differences
        # are rounding noise, mostly at the grid's scale, and must not read as a crinkle.
        noise = np.random.default_rng(1).integers(-2, 3, size=(20, 20)) * np.spacing(1.0)
        amplitude, share = sheet_quality.zigzag(sheet(20, 20, lambda k, l: 1.0 + noise[k, l]))
        self.assertLess(amplitude, 1e-15)
        self.assertIsNone(share)



def folded(m, n, gap):
    """A sheet folded in two along l = n // 2: the second half lies `gap` above the first,
    turned back over it (a U), through it where the gap goes negative."""
    k, l = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
    half = n // 2
    r = np.zeros((m, n, 3))
    r[..., 0] = k * 0.1
    r[..., 2] = np.where(l <= half, l, 2 * half - l) * 0.1
    r[..., 1] = np.where(l <= half, 0.0, gap(l - half))
    return r


class Crossings(unittest.TestCase):
    def test_a_sheet_folded_onto_itself_does_not_cross(self):
        # The layers 5 mm apart, then the whole turned and moved: still no crossing.
        r = folded(21, 21, lambda d: 0.005 + 0.0 * d)
        self.assertEqual(sheet_quality.crossings(r), (0, 0))
        c, s = np.cos(0.7), np.sin(0.7)
        turned = r @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) + [3.0, -1.0, 2.0]
        self.assertEqual(sheet_quality.crossings(turned), (0, 0))

    def test_a_fold_through_itself_crosses_along_a_line(self):
        # The upper half slants down through the lower one: they cross along a line across
        # the sheet, inside one cell of each layer in every column of cells (0.31 keeps the
        # line off the nodes, where touching does not count).
        m = 21
        r = folded(m, 21, lambda d: 0.31 - 0.06 * d)
        pairs, cells = sheet_quality.crossings(r)
        self.assertEqual(cells, 2 * (m - 1))
        self.assertGreaterEqual(pairs, m - 1)

    def test_a_node_thrown_through_the_sheet_is_found(self):
        # One node of the upper layer of the U pulled 5 m down through the lower layer: its
        # triangles are the largest of the sheet, found by the search for large triangles.
        r = folded(21, 21, lambda d: 0.005 + 0.0 * d)
        r[10, 15, 1] -= 5.0
        pairs, cells = sheet_quality.crossings(r)
        self.assertGreater(pairs, 0)
        self.assertGreater(cells, 0)


class Proximity(unittest.TestCase):
    def test_layers_closer_than_half_the_thickness_are_counted(self):
        # The U's layers 1 mm apart (h = 0.1 m): every node of the upper half more than 3 rows
        # from the fold lies over one of the lower half, 1 mm away: below half of t = 3 mm,
        # not below half of t = 1.5 mm; without a thickness, no count.
        m, n = 11, 21
        r = folded(m, n, lambda d: 0.001 + 0.0 * d)
        over = sum(1 for l in range(n // 2 + 1, n) if (l - (n - 1 - l)) > 3) * m
        below_h, _, none = sheet_quality.proximity(r, 0.1)
        self.assertIsNone(none)
        self.assertEqual(sheet_quality.proximity(r, 0.1, 0.003)[2], over)
        self.assertEqual(sheet_quality.proximity(r, 0.1, 0.0015)[2], 0)
        self.assertGreaterEqual(below_h, over)


if __name__ == "__main__":
    unittest.main()
