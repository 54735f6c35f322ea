#!/usr/bin/python3
"""Pictures and animations of a cosserat output file (docs/output.md, docs/rendering.md).

    render.py FILE.h5 [--frame N | --time T] [--field F] [--scene SCENE.toml]
                      [--output PNG] [--animate OUT.mp4|OUT.gif] [--max-frames N] [--fps F]
                      [--elev E] [--azim A] [--title T] [--mesh]

Writes one frame as a PNG (default: the most deformed frame, to FILE.png) and, with --animate,
the run as an MP4 (through ffmpeg) or a GIF (through Pillow). The cloth is coloured by a field
(height, strain, curvature, speed, energy_density, or none; those the run wrote in /fields are
read, the others computed from the positions) and lit from above the camera; the held nodes and
loads of the scene, the solids and the floor of the file are drawn beside it. The axes and
the colour scale are the same in every frame of an animation, and the canvas is cut to what is
drawn. Scenes put "up" along world y, so world (x, y, z) is drawn as matplotlib (x, z, y).
Exit status 2 when the file, a frame or the scene is missing or unreadable.
"""

import argparse
import math
import os
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

# A running simulation holds HDF5's lock on its file; reading without the lock lets a frame
# of a run in progress be rendered (the writer flushes whole frames).
os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")

import h5py  # noqa: E402  (needs the environment above)
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import animation  # noqa: E402
from matplotlib.cm import ScalarMappable  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.colors import Normalize, to_rgba  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
from mpl_toolkits.mplot3d import proj3d  # noqa: E402

import cloth_fields  # noqa: E402
from scene_constraints import Constraints  # noqa: E402
from solid_surfaces import clipped, is_plane, plane_normal, split  # noqa: E402

CLOTH_COLOUR = "#3b7dd8"
MESH_COLOUR = "#1c2e4a"
EDGE_WIDTH = 0.2
# Beyond this many rows or columns the facets are smaller than a pixel at ~1000 px, and drawing
# them only costs time.
MAX_LINES = 160
# The survey of every frame (the axes' limits, the most deformed frame) needs the shape, not
# the detail: this many rows and columns find a fold's place to a fiftieth of the sheet.
SURVEY_LINES = 48
DPI = 100
# The figure is drawn this large, then cut to the ink: about 750 px across the box.
DRAWING_SIZE_PX = (1000, 820)
MIN_WIDTH_PX = 640
MARGIN_PX = 12
HEADER_PX = 58
COLOURBAR_BAND_PX = 120
# Diffuse light on top of this much ambient: folds show, and the field's colour stays readable
# on facets edge-on to the light.
AMBIENT = 0.45
SOLID_COLOUR = "#8c8c8c"
SOLID_ALPHA = 0.45
FLOOR_COLOUR = "#c8bfa9"
FLOOR_ALPHA = 0.55
HELD_COLOUR = "#111111"
LINE_COLOUR = "#5a4632"
LOAD_COLOUR = "#d62728"
# The largest load's arrow is this fraction of the box's largest side.
ARROW_FRACTION = 0.15
# Bounded solids count towards the axes within this many of the cloth's largest span around the
# cloth's box; a plane counts only where it passes within that distance along its normal and
# within PLANE_MARGIN of the cloth's box across it, so that a floor is a rim, not a field.
NEIGHBOURHOOD = 0.5
PLANE_MARGIN = 0.08
# Facets are sorted by their mean depth only: a solid's facet larger than this fraction of the
# picture's largest side is cut into smaller ones, and sorted as if it lay that much farther
# from the camera. A cloth resting on a solid, closer than that to its surface, is then drawn
# over it; a cloth farther behind a solid than that still goes behind it.
LARGEST_FACET = 1.0 / 30.0
# A node-held region has many nodes: past this count each is a dot, not a marker.
FEW_HELD = 40
# A GIF frame has 256 colours and compresses poorly (5 MB for S4's 101 frames at full size):
# it is written at this fraction of the picture's size.
GIF_SCALE = 0.6
# An animation plays at FPS frames a second, or slower when that would make it shorter than
# SHORTEST_ANIMATION seconds: a fold that grows over thirty frames takes more than a second.
FPS = 20.0
SHORTEST_ANIMATION = 5.0


@dataclass(frozen=True)
class Field:
    label: str
    colour_map: str
    # Centred fields have a sign that matters (stretch against compression): their colour
    # scale is symmetric about 0, white there.
    centred: bool
    # Fields with isolated spikes (a loaded node, a kink at a held corner) take their colour
    # range from the 99th percentile, so the spike saturates instead of washing out the rest.
    robust: bool


FIELDS = {
    "height": Field("height, world y (m)", "viridis", centred=False, robust=False),
    "strain": Field("area strain S/S₀ − 1 (%)", "RdBu_r", centred=True, robust=True),
    "curvature": Field("mean curvature |H| (1/m)", "YlOrRd", centred=False, robust=True),
    "speed": Field("speed (m/s)", "plasma", centred=False, robust=True),
    "energy_density": Field("stored energy density (J/m²)", "inferno", centred=False,
                            robust=True),
    "none": None,
}


@dataclass(frozen=True)
class Stored:
    """Where a field is read from when the file holds it: /fields/<dataset> (docs/output.md,
    "Fields"), its node values ([frames, m, n], or [frames, m, n, components]) turned into the
    field's by `node_values`."""
    dataset: str
    components: int | None
    node_values: object


STORED = {
    "strain": Stored("area_ratio", None, lambda ratio: 100.0 * (ratio - 1.0)),
    "curvature": Stored("curvature", None, np.abs),
    "speed": Stored("velocity", 3, lambda velocity: np.linalg.norm(velocity, axis=-1)),
    "energy_density": Stored("energy_density", None, lambda density: density),
}


class InputError(Exception):
    """A missing file, dataset, frame or scene: reported in one line, exit status 2."""


def parse_arguments(argv):
    parser = argparse.ArgumentParser(
        description="Picture (PNG) and animation (MP4 or GIF) of a cosserat .h5 file.")
    parser.add_argument("file", type=Path, help="the .h5 file written by `cosserat run`")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--frame", type=int,
                       help="frame index, negative counts from the end "
                            "(default: the most deformed frame)")
    which.add_argument("--time", type=float, help="the frame nearest this simulated time (s)")
    parser.add_argument("--field", choices=list(FIELDS), default="height",
                        help="what colours the cloth (default height)")
    parser.add_argument("--scene", type=Path,
                        help="scene file whose [[fix]] and [[load]] blocks are drawn "
                             "(default: the scene text stored in the .h5 file)")
    parser.add_argument("--output", type=Path,
                        help="PNG to write (default: the .h5 path with suffix .png)")
    parser.add_argument("--animate", type=Path,
                        help="also write an animation: .mp4 (needs ffmpeg; a .gif beside it "
                             "without) or .gif")
    parser.add_argument("--max-frames", type=int, default=150,
                        help="the animation takes every k-th frame, k the smallest that keeps "
                             "it to this many with the last frame added (default 150)")
    parser.add_argument("--fps", type=float,
                        help="animation frames per second (default 20, fewer for an animation "
                             "of under 100 frames, so that it lasts 5 s)")
    parser.add_argument("--elev", type=float,
                        help="camera elevation, degrees (default: from the sheet's shape)")
    parser.add_argument("--azim", type=float,
                        help="camera azimuth, degrees (default: from the sheet's shape)")
    parser.add_argument("--title", help="title (default: scene title, integrator and time)")
    parser.add_argument("--mesh", action="store_true", help="draw thin grid lines")
    arguments = parser.parse_args(argv)
    if arguments.max_frames < 2:
        parser.error("--max-frames must be at least 2 (the first and the last frame)")
    if arguments.fps is not None and arguments.fps <= 0:
        parser.error("--fps must be positive")
    return arguments


def text_attribute(h5, name):
    value = h5.attrs.get(name, "")
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def to_drawing(world):
    """World (x, y, z), y up, as matplotlib's (x, z, y), whose third axis is vertical."""
    return world[..., [0, 2, 1]]


def thinning(count, lines):
    """At most `lines` indices out of `count`, evenly spread, both ends included."""
    return np.unique(np.linspace(0, count - 1, min(count, lines)).round().astype(int))


class Run:
    """What an output file holds for a picture: the cloth's frames, their times and steps, the
    solids, the scene text, and stored fields (/fields/<name>, docs/rendering.md)."""

    def __init__(self, h5, path):
        if "positions" not in h5:
            raise InputError(f"{path}: no /positions dataset")
        self.path = path
        self.positions = h5["positions"]
        self.frames, self.m, self.n = self.positions.shape[:3]
        if self.frames == 0:
            raise InputError(f"{path}: /positions holds no frame")
        self.times = (np.asarray(h5["time"], dtype=float) if "time" in h5
                      else np.arange(self.frames, dtype=float))
        self.steps = (np.asarray(h5["step"], dtype=int) if "step" in h5
                      else np.arange(self.frames))
        self.has_times = "time" in h5
        self.scene_text = text_attribute(h5, "scene")
        self.integrator = text_attribute(h5, "integrator")
        self.fields = h5["fields"] if "fields" in h5 else {}
        self.solids = [h5["solids"][key] for key in sorted(h5.get("solids", {}), key=int)]

    def cloth(self, frame, rows=None, columns=None):
        """Frame `frame` in drawing coordinates [rows, columns, 3], all nodes by default."""
        points = to_drawing(np.asarray(self.positions[frame], dtype=float))
        return points if rows is None else points[np.ix_(rows, columns)]

    def solid_surfaces(self, frame):
        """Each solid's (vertices [nv, 3] in drawing coordinates at `frame`, triangles)."""
        surfaces = []
        for group in self.solids:
            world = group["world_vertices"]
            if frame >= world.shape[0]:
                raise InputError(f"{self.path}: {group.name}/world_vertices has no frame {frame}")
            surfaces.append((to_drawing(np.asarray(world[frame], dtype=float)),
                             np.asarray(group["triangles"], dtype=int)))
        return surfaces

    def stored_field(self, name, components=None):
        """/fields/<name>, one value per node and frame ([frames, m, n], or [frames, m, n,
        components]), or None when the file has none."""
        if name not in self.fields:
            return None
        dataset = self.fields[name]
        shape = (self.frames, self.m, self.n) + ((components,) if components else ())
        if dataset.shape != shape:
            raise InputError(f"{self.path}: /fields/{name} has shape {dataset.shape}, not "
                             f"{shape} (frames, m, n{', components' if components else ''})")
        return dataset

    def title(self):
        try:
            return str(tomllib.loads(self.scene_text).get("title", ""))
        except tomllib.TOMLDecodeError:
            return ""


def frame_index(run, frame, time):
    """The frame `--frame` or `--time` names, or None for the default (the most deformed)."""
    if frame is not None:
        index = frame + run.frames if frame < 0 else frame
        if not 0 <= index < run.frames:
            raise InputError(f"{run.path}: no frame {frame}; the file holds {run.frames} "
                             f"(0 to {run.frames - 1}, or -1 to -{run.frames})")
        return index
    if time is not None:
        if not run.has_times:
            raise InputError(f"{run.path}: no /time dataset to find time {time} in")
        first, last = float(run.times[0]), float(run.times[-1])
        slack = 1e-9 * max(abs(first), abs(last), 1.0)
        if not first - slack <= time <= last + slack:
            raise InputError(f"{run.path}: no frame at t = {time:g} s; the frames run from "
                             f"{first:g} to {last:g} s")
        return int(np.abs(run.times - time).argmin())
    return None


@dataclass
class Survey:
    """What every frame gives together: the cloth's box over the run, and each frame's
    deformation (cloth_fields.deformation)."""
    low: np.ndarray
    high: np.ndarray
    deformations: np.ndarray


def survey(run):
    rows, columns = thinning(run.m, SURVEY_LINES), thinning(run.n, SURVEY_LINES)
    rest = run.cloth(0, rows, columns)
    low, high = np.full(3, np.inf), np.full(3, -np.inf)
    deformations = np.zeros(run.frames)
    for frame in range(run.frames):
        points = run.cloth(frame)
        flat = points.reshape(-1, 3)
        low, high = np.minimum(low, flat.min(axis=0)), np.maximum(high, flat.max(axis=0))
        deformations[frame] = cloth_fields.deformation(points[np.ix_(rows, columns)], rest)
    return Survey(low, high, deformations)


def axes_box(run, cloth_low, cloth_high):
    """The box the axes show: the cloth over the whole run, the bounded solids near it, and the
    part of each plane under (or beside) it, each solid over every frame; at least a tenth of
    its largest side along each axis, so that a flat sheet keeps a box."""
    span = max(float((cloth_high - cloth_low).max()), 1e-12)
    near_low, near_high = cloth_low - NEIGHBOURHOOD * span, cloth_high + NEIGHBOURHOOD * span
    low, high = cloth_low.copy(), cloth_high.copy()
    for index, group in enumerate(run.solids):
        triangles = np.asarray(group["triangles"], dtype=int)
        for frame in range(group["world_vertices"].shape[0]):
            vertices = to_drawing(np.asarray(group["world_vertices"][frame], dtype=float))
            if is_plane(vertices, triangles):
                across = np.full(3, PLANE_MARGIN * span)
                across[np.abs(plane_normal(vertices, triangles)).argmax()] = NEIGHBOURHOOD * span
                points = clipped(vertices, cloth_low - across, cloth_high + across)
                if len(points) < 3:
                    continue
            else:
                points = np.clip(vertices, near_low, near_high)
            low, high = np.minimum(low, points.min(axis=0)), np.maximum(high, points.max(axis=0))
    middle, half = (low + high) / 2, np.maximum(high - low, 0.1 * float((high - low).max())) / 2
    return middle - half, middle + half


def sheet_normal(points):
    """The unit normal of the plane that best fits a frame's nodes (least squares)."""
    flat = points.reshape(-1, 3)
    return np.linalg.svd(flat - flat.mean(axis=0), full_matrices=False)[2][2]


def camera(points, elev, azim):
    """Elevation and azimuth that look at the sheet's face: a sheet that lies flat is seen from
    35 degrees up; one that stands is seen 35 degrees off its normal from 20 degrees up, from
    whichever side is nearer matplotlib's default azimuth (-60). Given angles are kept."""
    normal = sheet_normal(points)
    standing = math.hypot(normal[0], normal[1]) > 0.5
    if elev is None:
        elev = 20.0 if standing else 35.0
    if azim is None:
        if standing:
            facing = math.degrees(math.atan2(normal[1], normal[0]))
            candidates = [facing + side + turn for side in (0.0, 180.0) for turn in (-35.0, 35.0)]
            azim = min(candidates, key=lambda a: abs((a + 60.0 + 180.0) % 360.0 - 180.0))
            azim = (azim + 180.0) % 360.0 - 180.0
        else:
            azim = -60.0
    return elev, azim


def light_direction(elev, azim):
    """From above and to the left of the camera, so that the lit side faces the viewer."""
    up, around = math.radians(min(elev + 35.0, 85.0)), math.radians(azim - 40.0)
    return np.array([math.cos(up) * math.cos(around), math.cos(up) * math.sin(around),
                     math.sin(up)])


def lambert(normals, light):
    """Brightness of facets with these normals, lit from either side (cloth has no outside)."""
    lengths = np.linalg.norm(normals, axis=-1, keepdims=True)
    unit = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    return AMBIENT + (1.0 - AMBIENT) * np.abs(unit @ light)


class Sheet:
    """The cloth's frames as drawn (thinned to MAX_LINES rows and columns, read once each) and
    the field's cell values on them."""

    def __init__(self, run, field_name):
        self.run, self.field_name = run, field_name
        self.rows, self.columns = thinning(run.m, MAX_LINES), thinning(run.n, MAX_LINES)
        self.rest = run.cloth(0, self.rows, self.columns)
        self.frames = {}

    def points(self, frame):
        if frame not in self.frames:
            self.frames[frame] = self.run.cloth(frame, self.rows, self.columns)
        return self.frames[frame]

    def torn(self, frame):
        """Per drawn cell [rows - 1, columns - 1], whether a spring across it is broken
        (/fields/broken_springs of a mass-spring run, docs/output.md "Fields"): such a cell is
        left out, so a tear shows as a hole. None when the run tore nothing."""
        stored = self.run.stored_field("broken_springs")
        if stored is None:
            return None
        bits = np.asarray(stored[frame]).astype(np.int64)
        if not bits.any():
            return None
        # A node's bits 0-3: its springs to (k+1, l), (k, l+1), (k+1, l+1), and from (k, l) to
        # (k+1, l-1), which crosses cell (k, l-1). Cell (k, l) holds the first three of its corner
        # (k, l), 0 of (k, l+1), 1 of (k+1, l) and 3 of (k, l+1).
        def bit(slot):
            return (bits >> slot) & 1 == 1
        cell = (bit(0)[:-1, :-1] | bit(1)[:-1, :-1] | bit(2)[:-1, :-1] | bit(0)[:-1, 1:]
                | bit(1)[1:, :-1] | bit(3)[:-1, 1:])
        # A drawn cell spans the grid cells between its thinned rows and columns.
        torn = np.zeros((len(self.rows) - 1, len(self.columns) - 1), dtype=bool)
        for i in range(len(self.rows) - 1):
            for j in range(len(self.columns) - 1):
                torn[i, j] = cell[self.rows[i]:self.rows[i + 1],
                                  self.columns[j]:self.columns[j + 1]].any()
        return torn

    def values(self, frame):
        """The field's cell values [m - 1, n - 1] at `frame`, the means of their corners': from
        the field the run wrote (STORED) when the file holds it, else computed from the
        positions (cloth_fields); None for no field. The energy density exists only as written."""
        name, run = self.field_name, self.run
        if FIELDS[name] is None:
            return None
        source = STORED.get(name)
        stored = run.stored_field(source.dataset, source.components) if source else None
        if stored is not None:
            nodes = np.asarray(stored[frame], dtype=float)[np.ix_(self.rows, self.columns)]
            return cloth_fields.cell_means(source.node_values(nodes))
        if name == "energy_density":
            raise InputError(f"{run.path}: no /fields/energy_density; `cosserat run` writes it "
                             "when output.fields names it (docs/output.md)")
        points = self.points(frame)
        if name == "height":
            return cloth_fields.cell_means(points[..., 2])
        if name == "strain":
            return 100.0 * cloth_fields.area_strain(points, self.rest)
        if name == "curvature":
            return cloth_fields.cell_means(cloth_fields.mean_curvature(points, self.rest))
        before, after = max(frame - 1, 0), min(frame + 1, run.frames - 1)
        interval = float(run.times[after] - run.times[before])
        return cloth_fields.cell_means(
            cloth_fields.speed(self.points(before), self.points(after), interval))


def colour_scale(field, values):
    """Colour limits common to every drawn frame's `values`."""
    every = np.concatenate([v.ravel() for v in values])
    if field.centred:
        reach = float(np.percentile(np.abs(every), 99) if field.robust else np.abs(every).max())
        reach = reach if reach > 0 else 1.0
        return Normalize(-reach, reach)
    low = float(every.min())
    high = float(np.percentile(every, 99) if field.robust else every.max())
    # Values equal but for round-off (a sheet lying flat: heights 4e-16 m apart) would spread
    # over the whole colour bar as a gradient that is not there; they take its middle colour.
    if high - low <= 1e-12 * max(abs(low), abs(high), 1.0):
        return Normalize(low - 0.5, low + 0.5)
    return Normalize(low, high)


def animation_frames(frames, most):
    """Every k-th frame from the first, and the last: evenly spaced in time (a stored run's
    frames are), at most `most` of them."""
    stride = max(1, math.ceil((frames - 1) / (most - 1)))
    chosen = list(range(0, frames, stride))
    return chosen if chosen[-1] == frames - 1 else chosen + [frames - 1]


class DepthSortedFacets(PolyCollection):
    """Facets in 3-D [count, 4, 3] drawn far to near along the camera's direction `eye`, each
    sorted as if it lay `bias` farther away. Poly3DCollection does the same sort without the
    bias and, in Debian 12's matplotlib, in Python facet by facet: 0.3 s a frame for a 60 x 60
    sheet, most of an animation's time. The camera and limits are fixed, so the order is
    fixed when the facets are; only the projection waits for the draw."""

    def __init__(self, facets, eye, bias, facecolors, edgecolors, linewidths, **kwargs):
        depth = -(facets.mean(axis=1) @ eye) + bias
        order = np.argsort(depth, kind="stable")[::-1]
        self.facets = facets[order]
        super().__init__(np.zeros((0, 4, 2)), facecolors=facecolors[order],
                         edgecolors=edgecolors[order], linewidths=linewidths[order], **kwargs)

    def do_3d_projection(self):
        flat = self.facets.reshape(-1, 3)
        xs, ys, zs = proj3d.proj_transform(flat[:, 0], flat[:, 1], flat[:, 2], self.axes.M)
        self.set_verts(np.stack([xs, ys], axis=-1).reshape(-1, 4, 2))
        return float(np.min(zs)) if len(zs) else 0.0


class Picture:
    """One figure, laid out once (axes, camera, colour bar, canvas cut to the ink), whose cloth,
    solids and marks are redrawn for each frame shown."""

    def __init__(self, box, view, field, norm, constraints, run, mesh):
        self.low, self.high = box
        self.field, self.norm, self.constraints, self.run, self.mesh = (field, norm, constraints,
                                                                          run, mesh)
        self.light = light_direction(*view)
        elev, azim = np.radians(view)
        self.eye = np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim),
                             np.sin(elev)])
        self.largest_facet = LARGEST_FACET * float((self.high - self.low).max())
        self.solid_cache = {}
        self.artists = []
        self.figure = plt.figure(figsize=(DRAWING_SIZE_PX[0] / DPI, DRAWING_SIZE_PX[1] / DPI),
                                 dpi=DPI)
        # The cloth and the solids are sorted by depth together (DepthSortedFacets); the marks
        # go on top of them, so that a held node or a load behind the cloth still shows.
        self.axes = self.figure.add_axes([0, 0, 1, 1], projection="3d", computed_zorder=False)
        # Above the axes' grid lines, as matplotlib puts collections it sorts itself.
        self.zorder = max(axis.get_zorder() for axis in
                          (self.axes.xaxis, self.axes.yaxis, self.axes.zaxis)) + 1
        sides = self.high - self.low
        for set_limits, lo, hi in zip((self.axes.set_xlim, self.axes.set_ylim,
                                       self.axes.set_zlim), self.low, self.high):
            set_limits(lo, hi)
        self.axes.set_box_aspect(sides)
        # Ticks in proportion to each side, so that a thin side is not crowded with labels.
        for axis, side in zip((self.axes.xaxis, self.axes.yaxis, self.axes.zaxis), sides):
            axis.set_major_locator(MaxNLocator(nbins=max(1, round(6 * side / sides.max()))))
        self.axes.set_xlabel("x (m)")
        self.axes.set_ylabel("z (m)")
        self.axes.set_zlabel("y, up (m)")
        self.axes.view_init(elev=view[0], azim=view[1])
        # The depth sort is along one direction, exact for parallel rays.
        self.axes.set_proj_type("ortho")
        # Placed by fit(), which measures the drawing without it.
        self.title = self.figure.text(0, 1, "", fontsize=12, va="top", visible=False)

    def solid_facets(self, index, vertices, triangles):
        """A solid's triangles cut to the box and split for the depth sort, as degenerate
        quads [count, 4, 3], their colours, and whether they lie behind everything else: a
        plane seen from its outer side, where the cloth stays, is drawn first and whole (a
        cloth resting on a floor would otherwise sort partly under it). Kept while the solid
        does not move (most solids are fixed, and the cut costs the most)."""
        key = (index, vertices.tobytes())
        if key not in self.solid_cache:
            floor = is_plane(vertices, triangles)
            backdrop = floor and float(plane_normal(vertices, triangles) @ self.eye) > 0
            base = np.asarray(to_rgba(FLOOR_COLOUR if floor else SOLID_COLOUR)[:3])
            alpha = FLOOR_ALPHA if floor else SOLID_ALPHA
            corners = vertices[triangles]
            shades = lambert(np.cross(corners[:, 1] - corners[:, 0],
                                      corners[:, 2] - corners[:, 0]), self.light)
            inside = np.all((corners >= self.low) & (corners <= self.high), axis=(1, 2))
            facets, colours = [np.zeros((0, 3, 3))], [np.zeros((0, 4))]
            for triangle, shade, whole in zip(corners, shades, inside):
                polygon = triangle if whole else clipped(triangle, self.low, self.high)
                if len(polygon) < 3:
                    continue
                pieces = split(polygon, np.inf if backdrop else self.largest_facet)
                facets.append(pieces)
                colours.append(np.tile((*(base * shade), alpha), (len(pieces), 1)))
            triangles_3d = np.concatenate(facets)
            quads = np.concatenate([triangles_3d, triangles_3d[:, 2:]], axis=1)
            self.solid_cache = {k: v for k, v in self.solid_cache.items() if k[0] != index}
            self.solid_cache[key] = (quads, np.concatenate(colours), backdrop)
        return self.solid_cache[key]

    def cloth_colours(self, points, values):
        """One colour per facet [m - 1, n - 1, 4]: the field's through its colour map, or the
        cloth's own colour, times the facet's light."""
        diagonal_a = points[1:, 1:] - points[:-1, :-1]
        diagonal_b = points[:-1, 1:] - points[1:, :-1]
        shade = lambert(np.cross(diagonal_a, diagonal_b), self.light)
        if self.field is None:
            colours = np.broadcast_to(to_rgba(CLOTH_COLOUR), shade.shape + (4,)).copy()
        else:
            colours = plt.get_cmap(self.field.colour_map)(self.norm(values))
        colours[..., :3] *= shade[..., None]
        return colours

    def show(self, frame, points, values, full, solids, title, torn=None):
        """Draw `frame`: its thinned nodes `points`, the field's cell `values`, the whole frame
        `full` (the marks sit on nodes the thinning may leave out) and the solids' surfaces;
        the cells `torn` marks are left out."""
        for artist in self.artists:
            artist.remove()
        quads = np.stack([points[:-1, :-1], points[1:, :-1], points[1:, 1:], points[:-1, 1:]],
                         axis=2).reshape(-1, 4, 3)
        colours = self.cloth_colours(points, values).reshape(-1, 4)
        if torn is not None:
            kept = ~torn.reshape(-1)
            quads, colours = quads[kept], colours[kept]
        # Each cloth facet is edged in its own colour: antialiasing alone leaves hairline
        # seams between neighbouring facets, through which the back of the cloth shows.
        edges = np.tile(to_rgba(MESH_COLOUR), (len(quads), 1)) if self.mesh else colours
        layers = {True: [], False: [(quads, colours, edges, np.full(len(quads), EDGE_WIDTH),
                                     np.zeros(len(quads)))]}
        for index, (vertices, triangles) in enumerate(solids):
            facets, facet_colours, behind = self.solid_facets(index, vertices, triangles)
            # A solid's facet sorts as if it lay one facet's size farther away: the facets
            # are that large, and a cloth resting on the solid is closer to it than that.
            layers[behind].append((facets, facet_colours, np.zeros_like(facet_colours),
                                   np.zeros(len(facets)), np.full(len(facets),
                                                                  self.largest_facet)))
        self.artists = []
        for behind, zorder in ((True, self.zorder), (False, self.zorder + 1)):
            if not layers[behind]:
                continue
            facets, face, edge, width, bias = (np.concatenate(part)
                                               for part in zip(*layers[behind]))
            collection = DepthSortedFacets(facets, self.eye, bias, face, edge, width,
                                           zorder=zorder)
            self.axes.add_collection(collection, autolim=False)
            self.artists.append(collection)
        self.artists += self.marks(frame, full)
        self.title.set_text(title)

    def marks(self, frame, full):
        """The scene's supports and loads acting at `frame`: each fix of nodes on one grid line
        as that line, every held node as a dot, every load as an arrow ending at its node."""
        if not self.constraints:
            return []
        step, time = int(self.run.steps[frame]), float(self.run.times[frame])
        artists = []
        for start, end in self.constraints.lines(step, time):
            ends = full[[start[0], end[0]], [start[1], end[1]]]
            artists += self.axes.plot(*ends.T, color=LINE_COLOUR, linewidth=3.0,
                                      zorder=self.zorder + 2,
                                      solid_capstyle="round")
        held = self.constraints.held(step, time)
        if len(held):
            points = full[held[:, 0], held[:, 1]]
            few = len(held) <= FEW_HELD
            artists.append(self.axes.scatter(*points.T, s=28 if few else 4, c=HELD_COLOUR,
                                             edgecolors="white" if few else "none",
                                             linewidths=0.6, depthshade=False,
                                             zorder=self.zorder + 3))
        nodes, forces = self.constraints.forces(step, time)
        largest = self.constraints.largest_force()
        if len(nodes) and largest > 0:
            scale = ARROW_FRACTION * float((self.high - self.low).max()) / largest
            tips = full[nodes[:, 0], nodes[:, 1]]
            arrows = to_drawing(forces) * scale
            artists.append(self.axes.quiver(*tips.T, *arrows.T, pivot="tip", color=LOAD_COLOUR,
                                            linewidth=1.6, arrow_length_ratio=0.3,
                                            zorder=self.zorder + 4))
        return artists

    def fit(self, legend):
        """Cut the canvas to the drawn box, its ticks and labels (matplotlib leaves a wide
        margin around a 3-D box), with a header for the title and legend and a band on the
        right for the colour bar. Called once, after the first frame: the limits and camera
        are fixed, so every frame of an animation has the same size."""
        self.figure.canvas.draw()
        image = np.asarray(self.figure.canvas.buffer_rgba())
        ink = np.any(image[..., :3] < 250, axis=-1)
        rows, columns = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
        height_px = image.shape[0]
        left, right = int(columns[0]), int(columns[-1]) + 1
        bottom, top = height_px - (int(rows[-1]) + 1), height_px - int(rows[0])
        band = COLOURBAR_BAND_PX if self.field is not None else 0
        content_width = right - left + 2 * MARGIN_PX
        width = max(content_width + band, MIN_WIDTH_PX)
        height = top - bottom + 2 * MARGIN_PX + HEADER_PX
        # The box is centred in what the colour bar leaves, so a narrow sheet sits in the middle.
        offset_x = (width - band - content_width) // 2 + MARGIN_PX - left
        offset_y = MARGIN_PX - bottom
        drawn_width, drawn_height = DRAWING_SIZE_PX
        self.figure.set_size_inches(width / DPI, height / DPI)
        self.axes.set_position([offset_x / width, offset_y / height, drawn_width / width,
                                drawn_height / height])
        self.title.set_position((MARGIN_PX / width, 1.0 - 8 / height))
        self.title.set_visible(True)
        if self.field is not None:
            bar_height = 0.6 * (top - bottom)
            bar = self.figure.add_axes([(width - band + 18) / width,
                                        (MARGIN_PX + (top - bottom - bar_height) / 2) / height,
                                        16 / width, bar_height / height])
            extend = "both" if self.field.centred and self.field.robust else (
                "max" if self.field.robust else "neither")
            colour_bar = self.figure.colorbar(ScalarMappable(self.norm, self.field.colour_map),
                                              cax=bar, extend=extend)
            colour_bar.set_label(self.field.label)
        if legend:
            self.figure.legend(*zip(*legend), loc="upper left", ncol=len(legend),
                               frameon=False, fontsize=9, handlelength=1.6,
                               bbox_to_anchor=(MARGIN_PX / width - 0.01, 1.0 - 30 / height))


def legend_entries(run, constraints, frames):
    """What the legend names: only what some drawn frame shows."""
    entries = []
    if constraints:
        shows_lines = any(constraints.lines(int(run.steps[f]), float(run.times[f])) for f in frames)
        shows_held = any(len(constraints.held(int(run.steps[f]), float(run.times[f])))
                         for f in frames)
        shows_loads = any(len(constraints.forces(int(run.steps[f]), float(run.times[f]))[0])
                          for f in frames)
        if shows_lines:
            entries.append((Line2D([], [], color=LINE_COLOUR, linewidth=3), "support line"))
        if shows_held:
            entries.append((Line2D([], [], color=HELD_COLOUR, marker="o", linestyle="",
                                   markersize=5), "held nodes"))
        if shows_loads:
            entries.append((Line2D([], [], color=LOAD_COLOUR, marker=">", markersize=5,
                                   linewidth=1.6), "loads"))
    surfaces = run.solid_surfaces(0)
    if any(not is_plane(*surface) for surface in surfaces):
        entries.append((Patch(color=SOLID_COLOUR, alpha=0.7), "solids"))
    if any(is_plane(*surface) for surface in surfaces):
        entries.append((Patch(color=FLOOR_COLOUR, alpha=0.9), "floor (planes)"))
    return entries


def read_constraints(run, scene_path):
    """The fixes and loads of `--scene`, else of the scene text the file stores."""
    if scene_path is not None:
        try:
            text = scene_path.read_text()
        except OSError as error:
            raise InputError(f"{scene_path}: cannot read the scene ({error.strerror})") from error
        source = scene_path
    else:
        text, source = run.scene_text, f"{run.path} (attribute scene)"
    try:
        return Constraints(text, (run.m, run.n))
    except tomllib.TOMLDecodeError as error:
        raise InputError(f"{source}: not a TOML scene ({error})") from error


def default_title(run, index, chosen):
    parts = [run.title() or run.path.stem]
    if run.integrator:
        parts.append(run.integrator)
    if run.has_times:
        parts.append(f"t = {run.times[index]:.4g} s")
    parts.append(f"frame {index} of {run.frames - 1}" + (", the most deformed" if chosen else ""))
    return "  ·  ".join(parts)


def animation_writer(path, fps):
    """The writer for `path`'s suffix, the path written (an .mp4 asked for without ffmpeg
    becomes a .gif beside it) and the resolution in dots per inch."""
    suffix = path.suffix.lower()
    if suffix == ".mp4":
        if animation.writers.is_available("ffmpeg"):
            return animation.FFMpegWriter(fps=fps, codec="h264"), path, DPI
        print(f"render.py: ffmpeg not found (apt-get install ffmpeg); writing a GIF instead of "
              f"{path}", file=sys.stderr)
        path = path.with_suffix(".gif")
    elif suffix != ".gif":
        raise InputError(f"{path}: an animation is written as .mp4 or .gif")
    return animation.PillowWriter(fps=fps), path, DPI * GIF_SCALE


def render(arguments, run):
    """Write the picture and, with --animate, the animation; return the paths written."""
    index = frame_index(run, arguments.frame, arguments.time)
    movie_frames, movie_writer = [], None
    if arguments.animate:
        movie_frames = animation_frames(run.frames, arguments.max_frames)
        fps = arguments.fps or min(FPS, len(movie_frames) / SHORTEST_ANIMATION)
        movie_writer = animation_writer(arguments.animate, fps)
    constraints = read_constraints(run, arguments.scene)
    swept = survey(run)
    chosen = index is None
    if chosen:
        index = int(swept.deformations.argmax())
    field = FIELDS[arguments.field]
    sheet = Sheet(run, arguments.field)
    values = {frame: sheet.values(frame) for frame in {index, *movie_frames}}
    box = axes_box(run, swept.low, swept.high)
    view = camera(sheet.points(index), arguments.elev, arguments.azim)
    legend = legend_entries(run, constraints, [index, *movie_frames])

    def show(picture, frame, most_deformed):
        picture.show(frame, sheet.points(frame), values[frame], run.cloth(frame),
                     run.solid_surfaces(frame),
                     arguments.title or default_title(run, frame, most_deformed),
                     sheet.torn(frame))

    def picture_of(frames):
        """A picture laid out for these frames (their colour scale), showing the first."""
        norm = colour_scale(field, [values[f] for f in frames]) if field is not None else None
        picture = Picture(box, view, field, norm, constraints, run, arguments.mesh)
        show(picture, frames[0], chosen and frames[0] == index)
        picture.fit(legend)
        return picture

    output = arguments.output or run.path.with_suffix(".png")
    still = picture_of([index])
    still.figure.savefig(output, dpi=DPI)
    plt.close(still.figure)
    written = [output]
    if movie_writer:
        writer, path, dpi = movie_writer
        movie = picture_of(movie_frames)
        with writer.saving(movie.figure, path, dpi):
            for frame in movie_frames:
                show(movie, frame, False)
                writer.grab_frame()
        plt.close(movie.figure)
        written.append(path)
    return written


def main(argv):
    arguments = parse_arguments(argv)
    try:
        if not arguments.file.is_file():
            raise InputError(f"{arguments.file}: no such file")
        try:
            h5 = h5py.File(arguments.file, "r")
        except OSError as error:
            raise InputError(f"{arguments.file}: not a readable HDF5 file ({error})") from error
        with h5:
            written = render(arguments, Run(h5, arguments.file))
    except InputError as error:
        print(f"render.py: {error}", file=sys.stderr)
        return 2
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
