#!/usr/bin/python3
"""Render one frame of a cosserat output file (shared/spec/SCENE_FORMAT.md, "Output") to a PNG.

    render.py FILE.h5 [--frame N] [--output PNG] [--elev E --azim A] [--title T] [--mesh]

The cloth is drawn as a surface in one colour, shaded by how squarely each facet faces a light
so that folds show. Scenes put "up" along world y, so world (x, y, z) is drawn as matplotlib
(x, z, y) and the cloth hangs downward in the picture. Exit status 2 when the file or the frame
is missing.
"""

import argparse
import os
import sys
import tomllib
from pathlib import Path

# A running simulation holds HDF5's lock on its file; reading without the lock lets a frame
# of a run in progress be rendered (the writer flushes whole frames).
os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")

import h5py  # noqa: E402  (needs the environment above)
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LightSource, to_rgba  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

CLOTH_COLOUR = "#3b7dd8"
MESH_COLOUR = "#1c2e4a"
EDGE_WIDTH = 0.2
# Beyond this many rows or columns the facets are smaller than a pixel at ~1000 px, and drawing
# them only costs time.
MAX_LINES = 160
DPI = 120
SIZE_PX = (1000, 800)


class InputError(Exception):
    """A missing file, dataset or frame: reported in one line, exit status 2."""


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description="Render one frame of a cosserat .h5 file.")
    parser.add_argument("file", type=Path, help="the .h5 file written by `cosserat run`")
    parser.add_argument("--frame", type=int, default=-1,
                        help="frame index, negative counts from the end (default -1, the last)")
    parser.add_argument("--output", type=Path,
                        help="PNG to write (default: the .h5 path with suffix .png)")
    parser.add_argument("--elev", type=float, default=20.0, help="camera elevation, degrees")
    parser.add_argument("--azim", type=float, default=-35.0, help="camera azimuth, degrees")
    parser.add_argument("--title", help="title (default: scene title, integrator and time)")
    parser.add_argument("--mesh", action="store_true", help="draw thin grid lines")
    return parser.parse_args(argv)


def text_attribute(h5, name):
    value = h5.attrs.get(name, "")
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def scene_title(scene_text):
    try:
        return str(tomllib.loads(scene_text).get("title", ""))
    except tomllib.TOMLDecodeError:
        return ""


def read_frame(path, frame):
    """Return (positions [m, n, 3], time, frame index, frame count, scene title, integrator)."""
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    try:
        h5 = h5py.File(path, "r")
    except OSError as error:
        raise InputError(f"{path}: not a readable HDF5 file ({error})") from error
    with h5:
        if "positions" not in h5:
            raise InputError(f"{path}: no /positions dataset")
        positions = h5["positions"]
        frames = positions.shape[0]
        index = frame + frames if frame < 0 else frame
        if not 0 <= index < frames:
            raise InputError(f"{path}: no frame {frame}; the file holds {frames} "
                             f"(0 to {frames - 1}, or -1 to -{frames})")
        times = h5["time"] if "time" in h5 else None
        time = float(times[index]) if times is not None and index < times.shape[0] else None
        return (np.asarray(positions[index], dtype=float), time, index, frames,
                scene_title(text_attribute(h5, "scene")), text_attribute(h5, "integrator"))


def thinned(points):
    """Keep at most MAX_LINES rows and columns, always including the borders."""
    m, n, _ = points.shape
    rows = np.unique(np.linspace(0, m - 1, min(m, MAX_LINES)).round().astype(int))
    columns = np.unique(np.linspace(0, n - 1, min(n, MAX_LINES)).round().astype(int))
    return points[np.ix_(rows, columns)]


def facet_colours(x, y, z, light):
    """One colour per facet, brighter the more squarely it faces the light from either side
    (cloth has no outside), as an [m, n, 4] array the way plot_surface takes facecolors."""
    corners = np.stack([x, y, z], axis=-1)
    diagonal_a = corners[1:, 1:] - corners[:-1, :-1]
    diagonal_b = corners[:-1, 1:] - corners[1:, :-1]
    normals = np.cross(diagonal_a, diagonal_b)
    lengths = np.linalg.norm(normals, axis=-1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    lambert = np.abs(normals @ light.direction)
    shade = 0.5 + 0.5 * lambert
    colours = np.ones(x.shape + (4,))
    colours[:-1, :-1, :3] = np.asarray(to_rgba(CLOTH_COLOUR)[:3]) * shade[..., None]
    return colours


def padded_limits(low, high, floor):
    """Axis limits around [low, high] at least `floor` wide, so a flat sheet keeps a box."""
    middle, half = (low + high) / 2, max(high - low, floor) / 2
    return middle - half, middle + half


def draw(points, title, elev, azim, mesh, output):
    # World y is up: matplotlib's vertical axis is its third.
    x, y, z = points[..., 0], points[..., 2], points[..., 1]
    figure = plt.figure(figsize=(SIZE_PX[0] / DPI, SIZE_PX[1] / DPI), dpi=DPI)
    axes = figure.add_subplot(projection="3d")
    light = LightSource(azdeg=azim + 45.0, altdeg=50.0)
    colours = facet_colours(x, y, z, light)
    # plot_surface edges each facet in its own colour, which hides the hairline seams between
    # facets; a thin line keeps neighbours from painting over each other.
    surface = axes.plot_surface(x, y, z, facecolors=colours, rstride=1, cstride=1, shade=False,
                                linewidth=EDGE_WIDTH)
    if mesh:
        surface.set_edgecolor(MESH_COLOUR)

    spans = [float(np.ptp(c)) for c in (x, y, z)]
    floor = 0.1 * max(max(spans), 1e-12)
    limits = [padded_limits(float(c.min()), float(c.max()), floor) for c in (x, y, z)]
    max_side = max(hi - lo for lo, hi in limits)
    axes.set_xlim(*limits[0])
    axes.set_ylim(*limits[1])
    axes.set_zlim(*limits[2])
    axes.set_box_aspect([hi - lo for lo, hi in limits])
    # Ticks in proportion to each side, so that a thin side is not crowded with labels.
    for axis, (lo, hi) in zip((axes.xaxis, axes.yaxis, axes.zaxis), limits):
        axis.set_major_locator(MaxNLocator(nbins=max(1, round(6 * (hi - lo) / max_side))))
    axes.set_xlabel("x")
    axes.set_ylabel("z")
    axes.set_zlabel("y (up)")
    axes.view_init(elev=elev, azim=azim)
    axes.set_title(title)
    figure.savefig(output, dpi=DPI)
    plt.close(figure)


def default_title(path, scene, integrator, time, index, frames):
    parts = [scene or path.stem]
    if integrator:
        parts.append(integrator)
    if time is not None:
        parts.append(f"t = {time:.6g} s")
    parts.append(f"frame {index} of {frames}")
    return ", ".join(parts)


def main(argv):
    arguments = parse_arguments(argv)
    try:
        points, time, index, frames, scene, integrator = read_frame(arguments.file,
                                                                    arguments.frame)
    except InputError as error:
        print(f"render.py: {error}", file=sys.stderr)
        return 2
    output = arguments.output or arguments.file.with_suffix(".png")
    title = arguments.title or default_title(arguments.file, scene, integrator, time, index,
                                             frames)
    draw(thinned(points), title, arguments.elev, arguments.azim, arguments.mesh, output)
    print(output)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
