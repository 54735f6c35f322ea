#!/usr/bin/python3
"""tools/paraview_render.py (docs/paraview.md) on a tiny run of the real executable, through
ParaView's pvpython on a virtual X server of its own; registered only where both are installed.

    test_paraview_render.py COSSERAT PVPYTHON XVFB [unittest options]

The X server picks a free display itself (-displayfd), and does not reset when its last client
leaves (-noreset): ParaView opens and closes one connection before it opens its window's, and
on a loaded machine the window's connection arrived while the server was resetting and was
hung up ("bad X server connection", 7 of 8 tries beside the MPI tests,
against 0 of 8 with -noreset).

The picture of a field must show the cloth in the colour map's colours on the white
background: curvature, signed, in both the blue and the red of Cool to Warm. A field the run did
not write and a frame it lacks are exit status 2 with nothing written.
"""

import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np
from PIL import Image

TOOLS = Path(__file__).resolve().parents[2] / "tools"
COSSERAT = None
PVPYTHON = None
XVFB = None

SCENE = """
title = "paraview test"

[grid]
nodes = [12, 10]
size = [1.0, 1.0]

[material]
preset = "cotton-10m"

[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.5

[time]
dt = 0.001
steps = 400
output_every = 100

[[fix]]
nodes = [[0, 0], [0, 9]]
"""


class ParaViewRender(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # A 24-bit screen: on xvfb-run's default 8-bit one ParaView fails (GLXBadContext).
        read, write = os.pipe()
        cls.xvfb = subprocess.Popen([XVFB, "-displayfd", str(write), "-screen", "0",
                                     "1280x1024x24", "-noreset", "-nolisten", "tcp"],
                                    pass_fds=[write], stderr=subprocess.DEVNULL)
        os.close(write)
        with os.fdopen(read) as display:
            os.environ["DISPLAY"] = ":" + display.readline().strip()
        cls.directory = tempfile.TemporaryDirectory()
        cls.folder = Path(cls.directory.name)
        scene = cls.folder / "tiny.toml"
        scene.write_text(SCENE)
        for name, extra in (("tiny", []), ("bare", ["--set", "output.fields=[]"])):
            subprocess.run([COSSERAT, "run", str(scene), "--output", str(cls.folder / f"{name}.h5"),
                            "--quiet", "--threads", "1", *extra], check=True, cwd=cls.folder)

    @classmethod
    def tearDownClass(cls):
        cls.directory.cleanup()
        cls.xvfb.terminate()
        cls.xvfb.wait()

    def render(self, xmf, *arguments):
        return subprocess.run([PVPYTHON, str(TOOLS / "paraview_render.py"), str(xmf),
                               *map(str, arguments)], capture_output=True, text=True)

    def test_a_field_colours_the_cloth(self):
        picture = self.folder / "curvature.png"
        result = self.render(self.folder / "tiny.xmf", "--field", "curvature", "--size", 400,
                             300, "-o", picture)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.split()[-1], str(picture))
        pixels = np.asarray(Image.open(picture).convert("RGB"), dtype=int)
        self.assertEqual(pixels.shape, (300, 400, 3))
        red, green, blue = pixels[..., 0], pixels[..., 1], pixels[..., 2]
        # Cool to Warm's ends: blue (bending away from n) and red (towards it), both present in
        # a sheet that sags between two held corners; white is the background and H = 0.
        reddish = np.count_nonzero((red > blue + 60) & (red > green + 40))
        bluish = np.count_nonzero((blue > red + 60) & (blue > green + 20))
        self.assertGreater(reddish, 200)
        self.assertGreater(bluish, 200)

    def test_a_field_the_run_did_not_write_is_bad_input(self):
        picture = self.folder / "missing.png"
        result = self.render(self.folder / "bare.xmf", "--field", "energy_density", "-o",
                             picture)
        self.assertEqual(result.returncode, 2)
        self.assertIn("has no field 'energy_density'", result.stderr)
        self.assertFalse(picture.exists())
        self.assertEqual(self.render(self.folder / "bare.xmf", "--field", "none", "-o",
                                     picture).returncode, 0)

    def test_a_missing_frame_is_bad_input(self):
        picture = self.folder / "frame.png"
        result = self.render(self.folder / "tiny.xmf", "--frame", 5, "-o", picture)
        self.assertEqual(result.returncode, 2)
        self.assertIn("no frame 5; the run holds 5", result.stderr)
        self.assertFalse(picture.exists())


if __name__ == "__main__":
    if len(sys.argv) < 4 or not all(os.access(p, os.X_OK) for p in sys.argv[1:4]):
        sys.exit("usage: test_paraview_render.py COSSERAT_EXECUTABLE PVPYTHON XVFB "
                 "[unittest options]")
    COSSERAT = sys.argv.pop(1)
    PVPYTHON = sys.argv.pop(1)
    XVFB = sys.argv.pop(1)
    unittest.main()
