#!/usr/bin/python3
"""tools/render.py and the fields it colours by (docs/rendering.md).

    test_render.py COSSERAT_EXECUTABLE [unittest options]

The fields are checked on sheets whose answer is known; the renderer end to end on a tiny run
of the real executable (a held line, a load, a floor and a box), which must give a PNG for
every field, a GIF with one frame per stored frame, and exit status 2 for a frame it lacks.
A GIF needs only Pillow (a matplotlib dependency), so the test runs without ffmpeg.
"""

import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

TOOLS = Path(__file__).resolve().parents[2] / "tools"
sys.path.insert(0, str(TOOLS))

import cloth_fields  # noqa: E402
from scene_constraints import Constraints  # noqa: E402

COSSERAT = None

SCENE = """
title = "render test"

[grid]
nodes = [8, 8]
size = [1.0, 1.0]

[material]
preset = "cotton-10m"

[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.5

[time]
dt = 0.001
steps = 400
output_every = 40

[[fix]]
nodes = [[0, 0], [0, 7]]

[[load]]
nodes = [[7, 7]]
force = [0.0, 0.0, 0.05]
end = 200

[[solid]]
name = "block"
shape = "box"
center = [0.7, -0.5, 0.5]
half_extents = [0.1, 0.1, 0.1]

[[solid]]
name = "floor"
shape = "plane"
point = [0.0, -1.2, 0.0]
normal = [0.0, 1.0, 0.0]
"""


def flat_grid(m, n, spacing=1.0):
    k, l = np.meshgrid(np.arange(m) * spacing, np.arange(n) * spacing, indexing="ij")
    return np.stack([k, l, np.zeros_like(k)], axis=-1)


class Fields(unittest.TestCase):
    def test_rigid_motion_is_no_deformation(self):
        rest = flat_grid(6, 9)
        angle = 0.7
        turn = np.array([[np.cos(angle), 0.0, np.sin(angle)], [0.0, 1.0, 0.0],
                         [-np.sin(angle), 0.0, np.cos(angle)]])
        moved = rest @ turn.T + np.array([3.0, -2.0, 5.0])
        self.assertLess(cloth_fields.deformation(moved, rest), 1e-12)
        sagged = rest.copy()
        sagged[..., 2] = 0.1 * np.sin(np.pi * rest[..., 0] / 5.0)
        self.assertGreater(cloth_fields.deformation(sagged, rest), 0.01)

    def test_area_strain_of_a_uniform_stretch(self):
        rest = flat_grid(5, 5)
        stretched = rest * np.array([1.2, 1.0, 1.0])
        np.testing.assert_allclose(cloth_fields.area_strain(stretched, rest), 0.2, rtol=1e-12)

    def test_mean_curvature_of_a_cylinder(self):
        # A sheet rolled round a cylinder of radius R, lengths kept: |H| = 1 / (2 R).
        radius, spacing = 2.0, 0.05
        rest = flat_grid(30, 10, spacing)
        angle = rest[..., 0] / radius
        rolled = np.stack([radius * np.sin(angle), rest[..., 1], radius * (1 - np.cos(angle))],
                          axis=-1)
        np.testing.assert_allclose(cloth_fields.mean_curvature(rolled, rest), 0.25, rtol=1e-3)
        self.assertLess(np.abs(cloth_fields.mean_curvature(rest, rest)).max(), 1e-12)

    def test_speed_of_a_translation(self):
        rest = flat_grid(4, 4)
        np.testing.assert_allclose(cloth_fields.speed(rest, rest + [0.3, 0.4, 0.0], 0.5), 1.0)


class SceneConstraints(unittest.TestCase):
    def test_windows_regions_and_lines(self):
        constraints = Constraints("""
            [[fix]]
            nodes = [[0, 0], [0, 5]]
            [[fix]]
            region = { rect = [2, 2, 3, 3] }
            start = 10
            [[load]]
            region = { row = 1 }
            force = [1.0, 0.0, 0.0]
            end_time = 0.5
            """, (6, 6))
        self.assertEqual(len(constraints.held(0, 0.0)), 2)
        self.assertEqual(len(constraints.held(10, 0.0)), 6)
        ends = constraints.lines(0, 0.0)
        self.assertEqual([tuple(map(tuple, pair)) for pair in ends], [((0, 0), (0, 5))])
        nodes, forces = constraints.forces(0, 0.4)
        self.assertEqual(sorted(nodes[:, 0]), list(range(6)))
        self.assertTrue(np.all(nodes[:, 1] == 1))
        self.assertEqual(len(constraints.forces(0, 0.6)[0]), 0)


class Renderer(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.directory = tempfile.TemporaryDirectory()
        cls.folder = Path(cls.directory.name)
        scene = cls.folder / "tiny.toml"
        scene.write_text(SCENE)
        cls.run_file = cls.folder / "tiny.h5"
        subprocess.run([COSSERAT, "run", str(scene), "--output", str(cls.run_file), "--quiet",
                        "--threads", "1"], check=True, cwd=cls.folder)

    @classmethod
    def tearDownClass(cls):
        cls.directory.cleanup()

    def render(self, *arguments):
        return subprocess.run([sys.executable, str(TOOLS / "render.py"), str(self.run_file),
                               *map(str, arguments)], capture_output=True, text=True)

    def test_a_picture_for_every_field(self):
        for field in ("height", "strain", "curvature", "speed", "energy_density", "none"):
            with self.subTest(field=field):
                picture = self.folder / f"{field}.png"
                result = self.render("--field", field, "--output", picture)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(picture.read_bytes()[:8], b"\x89PNG\r\n\x1a\n")

    def test_fields_are_computed_when_the_run_wrote_none(self):
        scene = self.folder / "tiny.toml"
        bare = self.folder / "bare.h5"
        subprocess.run([COSSERAT, "run", str(scene), "--output", str(bare), "--quiet",
                        "--threads", "1", "--set", "output.fields=[]"], check=True,
                       cwd=self.folder)
        for field in ("strain", "curvature", "speed"):
            with self.subTest(field=field):
                picture = self.folder / f"bare_{field}.png"
                result = subprocess.run([sys.executable, str(TOOLS / "render.py"), str(bare),
                                         "--field", field, "--output", str(picture)],
                                        capture_output=True, text=True)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertTrue(picture.exists())
        picture = self.folder / "bare_energy.png"
        result = subprocess.run([sys.executable, str(TOOLS / "render.py"), str(bare), "--field",
                                 "energy_density", "--output", str(picture)],
                                capture_output=True, text=True)
        self.assertEqual(result.returncode, 2)
        self.assertIn("no /fields/energy_density", result.stderr)
        self.assertFalse(picture.exists())

    def test_stored_fields_are_the_ones_drawn(self):
        import h5py
        sys.path.insert(0, str(TOOLS))
        import render
        with h5py.File(self.run_file, "r") as h5:
            run = render.Run(h5, self.run_file)
            frame = run.frames - 1
            curvature = render.Sheet(run, "curvature").values(frame)
            nodes = np.abs(h5["fields/curvature"][frame])
            np.testing.assert_allclose(curvature, cloth_fields.cell_means(nodes), rtol=1e-12)
            strain = render.Sheet(run, "strain").values(frame)
            ratio = h5["fields/area_ratio"][frame]
            np.testing.assert_allclose(strain, cloth_fields.cell_means(100.0 * (ratio - 1.0)),
                                       rtol=1e-12)

    def test_a_gif_of_every_frame(self):
        from PIL import Image
        picture, movie = self.folder / "still.png", self.folder / "movie.gif"
        result = self.render("--time", 0.2, "--output", picture, "--animate", movie)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.split(), [str(picture), str(movie)])
        with Image.open(movie) as gif:
            self.assertEqual(gif.format, "GIF")
            self.assertEqual(gif.n_frames, 11)

    def test_a_missing_frame_is_bad_input(self):
        result = self.render("--frame", 11, "--output", self.folder / "none.png")
        self.assertEqual(result.returncode, 2)
        self.assertIn("no frame 11", result.stderr)
        self.assertFalse((self.folder / "none.png").exists())


if __name__ == "__main__":
    if len(sys.argv) < 2 or not os.access(sys.argv[1], os.X_OK):
        sys.exit("usage: test_render.py COSSERAT_EXECUTABLE [unittest options]")
    COSSERAT = sys.argv.pop(1)
    unittest.main()
