#!/usr/bin/python3
"""tools/export_mesh.py (docs/export.md) on a tiny run of the real executable.

    test_export_mesh.py COSSERAT_EXECUTABLE [unittest options]

Each written mesh is read back: one vertex per node, one quad (or two triangles) per cell
turning from a1 to a2, positions and fields equal to the file's bit for bit (PLY, binary and
ASCII) or to the 17 digits that round-trip a double (OBJ); a frame the file lacks is exit
status 2 with nothing written.
"""

import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

TOOLS = Path(__file__).resolve().parents[2] / "tools"
COSSERAT = None

SCENE = """
title = "export test"

[grid]
nodes = [7, 5]
size = [1.0, 0.6]

[material]
preset = "cotton-10m"

[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.5

[time]
dt = 0.001
steps = 150
output_every = 50

[[fix]]
nodes = [[0, 0], [0, 4]]

[[solid]]
name = "block"
shape = "box"
center = [0.5, -0.4, 0.3]
half_extents = [0.1, 0.1, 0.1]
"""
M, N, FRAMES = 7, 5, 4


def read_ply(path):
    """(vertex properties {name: values}, faces [F, corners], comments) of a PLY file whose
    vertex properties are doubles and whose faces all have the same number of corners."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert header[0] == "ply", header[0]
    binary = header[1] == "format binary_little_endian 1.0"
    names, counts, comments = [], {}, []
    for line in header:
        words = line.split()
        if words[0] == "element":
            counts[words[1]] = int(words[2])
        elif words[0] == "property" and words[1] == "double":
            names.append(words[2])
        elif words[0] == "comment":
            comments.append(line[len("comment "):])
    vertices, faces = counts["vertex"], counts["face"]
    if binary:
        table = np.frombuffer(data, dtype=[(name, "<f8") for name in names], count=vertices,
                              offset=end)
        rest = data[end + table.nbytes:]
        corners = rest[0]
        rows = np.frombuffer(rest, dtype=[("count", "u1"), ("indices", "<i4", corners)])
        assert len(rows) == faces and np.all(rows["count"] == corners)
        return {name: table[name] for name in names}, rows["indices"], comments
    lines = data[end:].decode("ascii").splitlines()
    table = np.array([[float(x) for x in line.split()] for line in lines[:vertices]])
    face_rows = np.array([[int(x) for x in line.split()] for line in lines[vertices:]])
    assert len(face_rows) == faces and np.all(face_rows[:, 0] == face_rows.shape[1] - 1)
    return {name: table[:, i] for i, name in enumerate(names)}, face_rows[:, 1:], comments


def read_obj(path):
    vertices, faces = [], []
    for line in path.read_text().splitlines():
        if line.startswith("v "):
            vertices.append([float(x) for x in line.split()[1:]])
        elif line.startswith("f "):
            faces.append([int(x) - 1 for x in line.split()[1:]])
    return np.array(vertices), np.array(faces)


class ExportMesh(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.directory = tempfile.TemporaryDirectory()
        cls.folder = Path(cls.directory.name)
        scene = cls.folder / "tiny.toml"
        scene.write_text(SCENE)
        cls.run_file = cls.folder / "tiny.h5"
        subprocess.run([COSSERAT, "run", str(scene), "--output", str(cls.run_file), "--quiet",
                        "--threads", "1"], check=True, cwd=cls.folder)
        with h5py.File(cls.run_file, "r") as h5:
            cls.positions = h5["positions"][...]
            cls.fields = {name: h5["fields"][name][...] for name in h5["fields"]}
            cls.box = h5["solids/0/world_vertices"][...], h5["solids/0/triangles"][...]

    @classmethod
    def tearDownClass(cls):
        cls.directory.cleanup()

    def export(self, *arguments):
        return subprocess.run([sys.executable, str(TOOLS / "export_mesh.py"), str(self.run_file),
                               *map(str, arguments)], capture_output=True, text=True)

    def assert_faces_tile_the_grid(self, faces, corners):
        self.assertEqual(faces.shape, ((M - 1) * (N - 1) * (2 if corners == 3 else 1), corners))
        # Every cell's corners, and a first face turning from a1 (along k) to a2 (along l).
        self.assertEqual(sorted(set(faces.ravel())), list(range(M * N)))
        self.assertEqual(list(faces[0][:3]), [0, N, N + 1])

    def test_ply_holds_positions_and_fields_bit_for_bit(self):
        for form in ("binary", "ascii"):
            with self.subTest(form=form):
                folder = self.folder / f"ply_{form}"
                extra = ["--ascii"] if form == "ascii" else []
                result = self.export("-o", folder, *extra)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(result.stdout.strip(), str(folder))
                files = sorted(folder.glob("tiny_*.ply"))
                self.assertEqual([f.name for f in files],
                                 [f"tiny_{frame:04d}.ply" for frame in range(FRAMES)])
                for frame, path in enumerate(files):
                    properties, faces, comments = read_ply(path)
                    points = np.stack([properties[a] for a in "xyz"], axis=1)
                    np.testing.assert_array_equal(points, self.positions[frame].reshape(-1, 3))
                    velocity = np.stack([properties[f"v{a}"] for a in "xyz"], axis=1)
                    np.testing.assert_array_equal(
                        velocity, self.fields["velocity"][frame].reshape(-1, 3))
                    for name in ("area_ratio", "curvature", "energy_density"):
                        np.testing.assert_array_equal(properties[name],
                                                      self.fields[name][frame].ravel())
                    self.assert_faces_tile_the_grid(faces, 4)
                    self.assertIn(f"frame {frame}", comments[0])

    def test_obj_triangles_and_solids(self):
        folder = self.folder / "obj"
        result = self.export("-o", folder, "--format", "obj", "--triangles", "--frames", "-1",
                             "--solids")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(sorted(f.name for f in folder.iterdir()),
                         ["tiny_0003.obj", "tiny_solid0_0003.obj"])
        points, faces = read_obj(folder / "tiny_0003.obj")
        np.testing.assert_array_equal(points, self.positions[-1].reshape(-1, 3))
        self.assert_faces_tile_the_grid(faces, 3)
        surface, triangles = read_obj(folder / "tiny_solid0_0003.obj")
        np.testing.assert_array_equal(surface, self.box[0][-1])
        np.testing.assert_array_equal(triangles, self.box[1])

    def test_frames_are_chosen_by_index_and_slice(self):
        folder = self.folder / "some"
        result = self.export("-o", folder, "--frames", "0,::2,-1")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(sorted(f.name for f in folder.iterdir()),
                         ["tiny_0000.ply", "tiny_0002.ply", "tiny_0003.ply"])

    def test_a_missing_frame_is_bad_input(self):
        folder = self.folder / "none"
        result = self.export("-o", folder, "--frames", "4")
        self.assertEqual(result.returncode, 2)
        self.assertIn("no frame 4", result.stderr)
        self.assertFalse(folder.exists())
        missing = subprocess.run([sys.executable, str(TOOLS / "export_mesh.py"),
                                  str(self.folder / "absent.h5")], capture_output=True, text=True)
        self.assertEqual(missing.returncode, 2)
        self.assertIn("absent.h5: no such file", missing.stderr)


if __name__ == "__main__":
    if len(sys.argv) < 2 or not os.access(sys.argv[1], os.X_OK):
        sys.exit("usage: test_export_mesh.py COSSERAT_EXECUTABLE [unittest options]")
    COSSERAT = sys.argv.pop(1)
    unittest.main()
