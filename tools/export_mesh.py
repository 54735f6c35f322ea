#!/usr/bin/python3
"""A cosserat run as a sequence of meshes, one file per frame, for Blender, Houdini and other
tools that read PLY or OBJ (docs/export.md).

    export_mesh.py FILE.h5 [-o FOLDER] [--format ply|obj] [--frames SPEC] [--triangles]
                           [--ascii] [--solids]

Writes FOLDER/STEM_NNNN.ply (or .obj) for each chosen frame, NNNN the frame's index, and prints
the folder. The cloth's nodes are the vertices, node [k, l] the vertex k n + l (0-based), and
each grid cell is a quad, or with --triangles the two triangles (k,l)(k+1,l)(k+1,l+1) and
(k,l)(k+1,l+1)(k,l+1); faces are ordered so that their normal is a1 x a2, the sheet's normal
n. A PLY file carries the fields the run wrote (/fields, docs/output.md) as extra vertex
properties: vx, vy, vz for the velocity and one property per scalar field, named as the field;
OBJ has no place for them. Positions and fields are written as doubles in PLY and with 17
significant digits in OBJ, so they read back exactly. With --solids each rigid solid's surface
is written beside the cloth, placed as at that frame (STEM_solid<i>_NNNN). Exit status 2, with
one line naming what is wrong, for a file that is missing or not a run, or a frame it lacks.

Needs only Debian's python3, numpy and h5py.
"""

import argparse
import os
import sys
from pathlib import Path

# A running simulation holds a lock on its output; reading without HDF5's own lock lets the
# frames of a run in progress be exported (the writer flushes whole frames).
os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")

import h5py  # noqa: E402  (needs the environment above)
import numpy as np  # noqa: E402


class InputError(Exception):
    """Bad input: exit status 2."""


def parse_arguments(argv):
    parser = argparse.ArgumentParser(
        prog="export_mesh.py",
        description="Write the frames of a cosserat output file as PLY or OBJ meshes.")
    parser.add_argument("h5", help="the run's output file")
    parser.add_argument("-o", "--output", help="folder for the meshes (default: STEM_meshes "
                                                "beside the file)")
    parser.add_argument("--format", choices=("ply", "obj"), default="ply",
                        help="ply (default; carries the fields) or obj")
    parser.add_argument("--frames", default=":",
                        help="which frames: indices and Python slices, comma-separated, "
                             "negative from the end (default ':', every frame; e.g. '-1', "
                             "'0,10,20', '::5')")
    parser.add_argument("--triangles", action="store_true",
                        help="two triangles per grid cell instead of one quad")
    parser.add_argument("--ascii", action="store_true",
                        help="ASCII PLY instead of binary (little-endian)")
    parser.add_argument("--solids", action="store_true",
                        help="also write each rigid solid's surface at every chosen frame")
    return parser.parse_args(argv)


def chosen_frames(spec, count):
    """The frame indices `spec` names, in order, each once."""
    chosen = []
    for part in spec.split(","):
        part = part.strip()
        try:
            if ":" in part:
                bounds = [int(b) if b.strip() else None for b in part.split(":")]
                if len(bounds) > 3:
                    raise ValueError
                chosen.extend(range(count)[slice(*bounds)])
            else:
                index = int(part)
                if not -count <= index < count:
                    raise InputError(f"no frame {index}; the file holds {count} (0 to "
                                     f"{count - 1}, or -1 to -{count})")
                chosen.append(index % count)
        except ValueError:
            raise InputError(f"--frames '{spec}': '{part}' is neither an index nor a slice "
                             "such as 0:10:2") from None
    if not chosen:
        raise InputError(f"--frames '{spec}' names no frame of the {count} the file holds")
    return list(dict.fromkeys(chosen))


def grid_faces(m, n, triangles):
    """Vertex indices of each face of an m x n grid, node [k, l] at k n + l: quads
    (k,l)(k+1,l)(k+1,l+1)(k,l+1), turning from a1 to a2, or their two triangles on the
    diagonal (k,l)(k+1,l+1) that docs/equations.md §3 measures the area with."""
    k, l = np.meshgrid(np.arange(m - 1), np.arange(n - 1), indexing="ij")
    here = (k * n + l).ravel()
    along_k, along_kl, along_l = here + n, here + n + 1, here + 1
    if triangles:
        first = np.stack([here, along_k, along_kl], axis=1)
        second = np.stack([here, along_kl, along_l], axis=1)
        return np.stack([first, second], axis=1).reshape(-1, 3)
    return np.stack([here, along_k, along_kl, along_l], axis=1)


def check_fields(fields, count, m, n):
    """Every field a series of the grid's frames, [count, m, n] or [count, m, n, 3]."""
    for name in fields:
        if fields[name].shape not in ((count, m, n), (count, m, n, 3)):
            raise InputError(f"/fields/{name} has shape {fields[name].shape}, not "
                             f"({count}, {m}, {n}) or ({count}, {m}, {n}, 3)")


def vertex_properties(fields, frame):
    """The PLY vertex properties beyond x, y, z: (name, values [m n]) for each field of the
    file at `frame`, the velocity's three components as vx, vy, vz."""
    properties = []
    for name in sorted(fields):
        values = np.asarray(fields[name][frame], dtype="<f8")
        if values.ndim == 3:
            properties += [(f"v{axis}", values[..., i].ravel())
                           for i, axis in enumerate("xyz")]
        else:
            properties.append((name, values.ravel()))
    return properties


def write_ply(path, points, faces, properties, comments, ascii_format):
    """A PLY file of `points` [N, 3], `faces` [F, corners] and vertex `properties`."""
    names = ["x", "y", "z"] + [name for name, _ in properties]
    columns = [points[:, 0], points[:, 1], points[:, 2]] + [values for _, values in properties]
    header = ["ply", f"format {'ascii' if ascii_format else 'binary_little_endian'} 1.0"]
    header += [f"comment {line}" for line in comments]
    header.append(f"element vertex {len(points)}")
    header += [f"property double {name}" for name in names]
    header.append(f"element face {len(faces)}")
    header += ["property list uchar int vertex_indices", "end_header"]
    with open(path, "wb") as out:
        out.write(("\n".join(header) + "\n").encode("ascii"))
        if ascii_format:
            vertex_rows = np.stack(columns, axis=1)
            np.savetxt(out, vertex_rows, fmt="%.17g")
            corners = faces.shape[1]
            np.savetxt(out, np.column_stack([np.full(len(faces), corners), faces]), fmt="%d")
            return
        vertices = np.empty(len(points), dtype=[(name, "<f8") for name in names])
        for name, column in zip(names, columns):
            vertices[name] = column
        out.write(vertices.tobytes())
        corners = faces.shape[1]
        face_rows = np.empty(len(faces), dtype=[("count", "u1"), ("indices", "<i4", corners)])
        face_rows["count"] = corners
        face_rows["indices"] = faces
        out.write(face_rows.tobytes())


def write_obj(path, points, faces, comments):
    """An OBJ file of `points` and `faces` (1-based, as OBJ counts)."""
    with open(path, "w", encoding="ascii") as out:
        for line in comments:
            out.write(f"# {line}\n")
        np.savetxt(out, points, fmt="v %.17g %.17g %.17g")
        np.savetxt(out, faces + 1, fmt="f" + " %d" * faces.shape[1])


def export(arguments):
    source = Path(arguments.h5)
    if not source.is_file():
        raise InputError(f"{source}: no such file")
    try:
        h5 = h5py.File(source, "r")
    except OSError as error:
        raise InputError(f"{source}: not an HDF5 file ({error})") from None
    with h5:
        if "positions" not in h5:
            raise InputError(f"{source}: no /positions dataset: not a cosserat output file")
        positions = h5["positions"]
        count, m, n = positions.shape[:3]
        if count == 0:
            raise InputError(f"{source}: /positions holds no frame")
        frames = chosen_frames(arguments.frames, count)
        times = np.asarray(h5["time"]) if "time" in h5 else np.arange(count, dtype=float)
        steps = np.asarray(h5["step"]) if "step" in h5 else np.arange(count)
        fields = h5["fields"] if "fields" in h5 and arguments.format == "ply" else {}
        check_fields(fields, count, m, n)
        solids = ([h5["solids"][key] for key in sorted(h5["solids"], key=int)]
                  if arguments.solids and "solids" in h5 else [])
        folder = Path(arguments.output) if arguments.output else source.with_name(
            source.stem + "_meshes")
        folder.mkdir(parents=True, exist_ok=True)
        faces = grid_faces(m, n, arguments.triangles)
        digits = max(4, len(str(count - 1)))
        for frame in frames:
            comments = [f"cosserat run {source.name} frame {frame} step {steps[frame]} "
                        f"time {float(times[frame])!r} s",
                        f"grid {m} x {n}, node [k, l] is vertex k*n + l"]
            points = np.asarray(positions[frame], dtype="<f8").reshape(-1, 3)
            stem = folder / f"{source.stem}_{frame:0{digits}d}"
            if arguments.format == "ply":
                write_ply(stem.with_suffix(".ply"), points, faces,
                          vertex_properties(fields, frame), comments, arguments.ascii)
            else:
                write_obj(stem.with_suffix(".obj"), points, faces, comments)
            for index, group in enumerate(solids):
                surface = np.asarray(group["world_vertices"][frame], dtype="<f8")
                triangles = np.asarray(group["triangles"], dtype=np.int64)
                name = group.attrs.get("name", "")
                name = name.decode() if isinstance(name, bytes) else str(name)
                solid_stem = folder / f"{source.stem}_solid{index}_{frame:0{digits}d}"
                solid_comments = [f"solid {index} ({name}) of {source.name} at frame {frame}"]
                if arguments.format == "ply":
                    write_ply(solid_stem.with_suffix(".ply"), surface, triangles, [],
                              solid_comments, arguments.ascii)
                else:
                    write_obj(solid_stem.with_suffix(".obj"), surface, triangles, solid_comments)
    return folder


def main(argv):
    arguments = parse_arguments(argv)
    try:
        print(export(arguments))
    except InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
