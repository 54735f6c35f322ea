#!/usr/bin/python3
"""Render one frame of a cosserat output file (docs/output.md) to a PNG.

    render.py FILE.h5 [--frame N] [--output PNG] [--elev E --azim A] [--title T] [--mesh]

The cloth is drawn as a surface in one colour, shaded by how squarely each facet faces a light
so that folds show. Scenes put "up" along world y, so world (x, y, z) is drawn as matplotlib
(x, z, y) and the cloth hangs downward in the picture. Exit status 2 when the file or the frame
is missing.

Rigid solids (/solids/<i>/world_vertices of the frame, docs/output.md) are drawn grey and
half transparent beside the cloth, cut to the cloth's neighbourhood (a plane's surface is a large
square); their facets and the cloth's are sorted by depth together, so the cloth shows in front
of a solid or through it. A file without solids is drawn as before.
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
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

CLOTH_COLOUR = "#3b7dd8"
MESH_COLOUR = "#1c2e4a"
EDGE_WIDTH = 0.2
# Beyond this many rows or columns the facets are smaller than a pixel at ~1000 px, and drawing
# them only costs time.
MAX_LINES = 160
DPI = 120
SIZE_PX = (1000, 800)
SOLID_COLOUR = "#8c8c8c"
SOLID_ALPHA = 0.45
# Solids are drawn within this many of the cloth's largest span around the cloth's box.
NEIGHBOURHOOD = 0.5
# Matplotlib sorts facets by their mean depth only: a solid's facet larger than this fraction of
# the picture's largest side is cut into smaller ones, so a floor does not hide the whole cloth.
LARGEST_FACET = 1.0 / 12.0


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


def read_solids(h5, index):
    """Each solid's (name, vertices [nv, 3] placed at frame `index`, triangles [nt, 3]), in the
    order of their groups /solids/0, /solids/1, ...; none for a file without /solids."""
    if "solids" not in h5:
        return []
    solids = []
    for key in sorted(h5["solids"], key=int):
        group = h5["solids"][key]
        world = group["world_vertices"]
        if index >= world.shape[0]:
            raise InputError(f"{h5.filename}: /solids/{key}/world_vertices has no frame {index}")
        solids.append((text_attribute(group, "name"), np.asarray(world[index], dtype=float),
                       np.asarray(group["triangles"], dtype=int)))
    return solids


def read_frame(path, frame):
    """Return (positions [m, n, 3], time, frame index, frame count, scene title, integrator,
    solids as read_solids gives them)."""
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
                scene_title(text_attribute(h5, "scene")), text_attribute(h5, "integrator"),
                read_solids(h5, index))


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


def clipped(polygon, low, high):
    """The part of a convex polygon [k, 3] inside the box [low, high] (Sutherland-Hodgman, one
    face of the box at a time); fewer than 3 points when nothing is inside."""
    for axis in range(3):
        for bound, sign in ((low[axis], 1.0), (high[axis], -1.0)):
            if len(polygon) < 3:
                return polygon
            inside = sign * (polygon[:, axis] - bound)
            kept = []
            for i in range(len(polygon)):
                j = (i + 1) % len(polygon)
                if inside[i] >= 0:
                    kept.append(polygon[i])
                if (inside[i] >= 0) != (inside[j] >= 0):
                    t = inside[i] / (inside[i] - inside[j])
                    kept.append(polygon[i] + t * (polygon[j] - polygon[i]))
            polygon = np.array(kept).reshape(-1, 3)
    return polygon


def split(polygon, largest):
    """Triangles covering a convex polygon, none with a side longer than `largest`."""
    pending = [polygon[[0, i, i + 1]] for i in range(1, len(polygon) - 1)]
    pieces = []
    while pending:
        triangle = pending.pop()
        sides = np.linalg.norm(triangle - np.roll(triangle, 1, axis=0), axis=1)
        if sides.max() <= largest or len(pieces) + len(pending) > 20000:
            pieces.append(triangle)
            continue
        a, b, c = triangle
        ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
        pending += [np.array(t) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))]
    return pieces


def solid_facets(solids, low, high, light, largest):
    """The solids' triangles (in drawing coordinates) cut to the box [low, high], each with its
    colour: grey, brighter the more squarely it faces the light."""
    facets, colours = [], []
    base = np.asarray(to_rgba(SOLID_COLOUR)[:3])
    for _, vertices, triangles in solids:
        corners = vertices[:, [0, 2, 1]][triangles]
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        lengths = np.linalg.norm(normals, axis=-1, keepdims=True)
        normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
        shades = 0.45 + 0.55 * np.abs(normals @ light.direction)
        inside = np.all((corners >= low) & (corners <= high), axis=(1, 2))
        for triangle, shade, whole in zip(corners, shades, inside):
            polygon = triangle if whole else clipped(triangle, low, high)
            if len(polygon) < 3:
                continue
            for piece in split(polygon, largest):
                facets.append(piece)
                colours.append((*(base * shade), SOLID_ALPHA))
    return facets, colours


def scene_limits(cloth, solids):
    """Axis limits around the cloth and the solids' parts near it, and the box those parts are
    cut to."""
    low, high = cloth.reshape(-1, 3).min(axis=0), cloth.reshape(-1, 3).max(axis=0)
    margin = NEIGHBOURHOOD * max(float((high - low).max()), 1e-12)
    near_low, near_high = low - margin, high + margin
    for _, vertices, _ in solids:
        points = np.clip(vertices[:, [0, 2, 1]], near_low, near_high)
        low, high = np.minimum(low, points.min(axis=0)), np.maximum(high, points.max(axis=0))
    return low, high


def draw(points, title, elev, azim, mesh, output, solids=()):
    # World y is up: matplotlib's vertical axis is its third.
    x, y, z = points[..., 0], points[..., 2], points[..., 1]
    figure = plt.figure(figsize=(SIZE_PX[0] / DPI, SIZE_PX[1] / DPI), dpi=DPI)
    axes = figure.add_subplot(projection="3d")
    light = LightSource(azdeg=azim + 45.0, altdeg=50.0)
    colours = facet_colours(x, y, z, light)
    if not solids:
        # plot_surface edges each facet in its own colour, which hides the hairline seams
        # between facets; a thin line keeps neighbours from painting over each other.
        surface = axes.plot_surface(x, y, z, facecolors=colours, rstride=1, cstride=1,
                                    shade=False, linewidth=EDGE_WIDTH)
        if mesh:
            surface.set_edgecolor(MESH_COLOUR)
        spans = [float(np.ptp(c)) for c in (x, y, z)]
        floor = 0.1 * max(max(spans), 1e-12)
        limits = [padded_limits(float(c.min()), float(c.max()), floor) for c in (x, y, z)]
    else:
        cloth = np.stack([x, y, z], axis=-1)
        low, high = scene_limits(cloth, solids)
        floor = 0.1 * max(float((high - low).max()), 1e-12)
        limits = [padded_limits(float(lo), float(hi), floor) for lo, hi in zip(low, high)]
        box_low = np.array([lo for lo, _ in limits])
        box_high = np.array([hi for _, hi in limits])
        # One collection, so that matplotlib sorts the cloth's facets and the solids' by depth
        # together (it sorts whole collections against each other by one depth each).
        quads = np.stack([cloth[:-1, :-1], cloth[1:, :-1], cloth[1:, 1:], cloth[:-1, 1:]],
                         axis=2).reshape(-1, 4, 3)
        cloth_colours = colours[:-1, :-1].reshape(-1, 4)
        facets, solid_colours = solid_facets(
            solids, box_low, box_high, light, LARGEST_FACET * float((box_high - box_low).max()))
        edges = [MESH_COLOUR if mesh else tuple(c) for c in cloth_colours]
        collection = Poly3DCollection(
            list(quads) + facets, facecolors=[tuple(c) for c in cloth_colours] + solid_colours,
            edgecolors=edges + ["none"] * len(facets),
            linewidths=[EDGE_WIDTH] * len(quads) + [0.0] * len(facets))
        axes.add_collection3d(collection)

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
        points, time, index, frames, scene, integrator, solids = read_frame(arguments.file,
                                                                            arguments.frame)
    except InputError as error:
        print(f"render.py: {error}", file=sys.stderr)
        return 2
    output = arguments.output or arguments.file.with_suffix(".png")
    title = arguments.title or default_title(arguments.file, scene, integrator, time, index,
                                             frames)
    draw(thinned(points), title, arguments.elev, arguments.azim, arguments.mesh, output, solids)
    print(output)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
