"""tools/sheet_quality.py's zig-zag measure tells a fold the grid resolves from a crinkle at the
grid's own scale, on sheets made here."""

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


if __name__ == "__main__":
    unittest.main()
