#!/usr/bin/python3
"""tools/rest_report.py (docs/contact.md, "Resting contact") on tiny runs of the executable.

    test_rest_report.py COSSERAT_EXECUTABLE [unittest options]

The report's total energy at the last frame (kinetic + gravitational + elastic, from the
file's fields) must be the solver's own, the run summary's kinetic_energy +
gravitational_energy + elastic_energy at the same step, whether the sheet's mass is given as
`mass`, as `density` or by a preset (read back through --summary). A node mass other than the
solver's lumped μ₀h₁h₂ (M/(mn) was once used) weights the kinetic and gravitational parts
wrongly and shows as energy rising in a sheet that loses it.
"""

import json
import os
import re
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[2] / "tools"
COSSERAT = None

# A 7 x 5 sheet hung by two corners, a third of a second: it swings and stretches, so the
# kinetic, gravitational and elastic parts are all far from zero at the end.
SCENE = """
title = "rest report test"

[grid]
nodes = [7, 5]
size = [1.0, 0.6]

[material]
{material}

[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.5

[time]
dt = 0.001
steps = 300
output_every = 100

[[fix]]
nodes = [[0, 0], [6, 0]]
"""

MODULI = "zeta = 50.0\nxi = 1e-3\nphi = 1e-3"
MATERIALS = {
    "mass": "mass = 0.3\n" + MODULI,
    "density": "density = 0.5\n" + MODULI,
    "preset": 'preset = "cotton-10m"',
}


class RestReportEnergy(unittest.TestCase):
    def check(self, material):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            (tmp / "s.toml").write_text(SCENE.format(material=MATERIALS[material]))
            subprocess.run([COSSERAT, "run", str(tmp / "s.toml"), "--threads", "1",
                            "--output", str(tmp / "s.h5"), "--summary", str(tmp / "s.json")],
                           check=True, capture_output=True)
            report = subprocess.run(
                [sys.executable, str(TOOLS / "rest_report.py"), str(tmp / "s.h5"),
                 "--summary", str(tmp / "s.json"), "--table"],
                check=True, capture_output=True, text=True).stdout
            summary = json.loads((tmp / "s.json").read_text())
        totals = re.findall(r"  total (-?[0-9][-+0-9.e]*)", report)
        self.assertEqual(len(totals), 4, report)
        solver = (summary["kinetic_energy"] + summary["gravitational_energy"]
                  + summary["elastic_energy"])
        self.assertGreater(abs(summary["kinetic_energy"]), 1e-3 * abs(solver))
        # The table prints 8 digits.
        self.assertAlmostEqual(float(totals[-1]) / solver, 1.0, delta=1e-6, msg=report)

    def test_mass(self):
        self.check("mass")

    def test_density(self):
        self.check("density")

    def test_preset(self):
        self.check("preset")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    COSSERAT = sys.argv.pop(1)
    os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
    unittest.main()
