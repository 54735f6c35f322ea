"""Quantities of a cloth frame that render.py colours by, computed from node positions alone.

Every function takes frames as arrays [m, n, 3] of node positions (node [k, l] at [k, l, :],
docs/output.md), possibly thinned to fewer rows and columns, and `rest` is frame 0 of the same
rows and columns: every scene starts as the flat grid at rest (docs/scene-format.md), so frame 0
gives the rest spacing and the rest area of each cell without reading the scene.
"""

import numpy as np


def cell_means(node_values):
    """The mean of each cell's four corners: [m, n] node values to [m - 1, n - 1] cell values."""
    return 0.25 * (node_values[:-1, :-1] + node_values[1:, :-1] + node_values[:-1, 1:]
                   + node_values[1:, 1:])


def cell_areas(points):
    """Each cell's area, half the cross product of its diagonals (exact for a flat cell, and
    independent of which diagonal would split a bent one into triangles)."""
    diagonal_a = points[1:, 1:] - points[:-1, :-1]
    diagonal_b = points[:-1, 1:] - points[1:, :-1]
    return 0.5 * np.linalg.norm(np.cross(diagonal_a, diagonal_b), axis=-1)


def area_strain(points, rest):
    """S/S0 - 1 of each cell [m - 1, n - 1]: positive stretched, negative compressed."""
    rest_areas = cell_areas(rest)
    return np.divide(cell_areas(points), rest_areas, out=np.ones_like(rest_areas),
                     where=rest_areas > 0) - 1.0


def node_normals(points):
    """Unit normals [m, n, 3] from the central-difference tangents along k and l."""
    normals = np.cross(np.gradient(points, axis=0), np.gradient(points, axis=1))
    lengths = np.linalg.norm(normals, axis=-1, keepdims=True)
    return np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)


def second_difference(points, spacing, axis):
    """d2r/ds2 along `axis` at the interior nodes of that axis, on the uneven rest spacing a
    thinned grid has (spacing[i] between lines i and i + 1)."""
    moved = np.moveaxis(points, axis, 0)
    shape = (-1,) + (1,) * (moved.ndim - 1)
    ahead = spacing[1:].reshape(shape)
    behind = spacing[:-1].reshape(shape)
    slope_ahead = (moved[2:] - moved[1:-1]) / ahead
    slope_behind = (moved[1:-1] - moved[:-2]) / behind
    return np.moveaxis(2.0 * (slope_ahead - slope_behind) / (ahead + behind), 0, axis)


def mean_curvature(points, rest):
    """|H| at each node [m, n] (1/m): for a sheet that keeps its lengths the Laplacian in rest
    coordinates is 2 H n, so H = (d2r/dk2 + d2r/dl2) . n / 2. The border rows and columns take
    their inner neighbours' values, which have a full stencil."""
    spacing_k = np.linalg.norm(rest[1:] - rest[:-1], axis=-1).mean(axis=1)
    spacing_l = np.linalg.norm(rest[:, 1:] - rest[:, :-1], axis=-1).mean(axis=0)
    laplacian = (second_difference(points, spacing_k, 0)[:, 1:-1]
                 + second_difference(points, spacing_l, 1)[1:-1, :])
    normals = node_normals(points)[1:-1, 1:-1]
    inner = 0.5 * np.abs(np.sum(laplacian * normals, axis=-1))
    return np.pad(inner, 1, mode="edge")


def speed(before, after, interval):
    """|dr/dt| at each node [m, n] by the difference of two frames `interval` seconds apart: the
    mean speed over the interval, so motion faster than the frames is underestimated."""
    if interval <= 0:
        return np.zeros(before.shape[:-1])
    return np.linalg.norm(after - before, axis=-1) / interval


def deformation(points, rest):
    """How far a frame is from a rigid motion of the rest sheet: the RMS distance (m) of its nodes
    from the rest nodes best fitted onto them by a rotation and a translation (Kabsch). A sheet
    that only falls or turns scores 0; a fold, a sag or a stretch does not."""
    moved = points.reshape(-1, 3) - points.reshape(-1, 3).mean(axis=0)
    still = rest.reshape(-1, 3) - rest.reshape(-1, 3).mean(axis=0)
    u, _, vt = np.linalg.svd(still.T @ moved)
    # A reflection fits a flat sheet as well as a rotation; only a rotation is a rigid motion.
    handedness = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt)) or 1.0])
    rotation = u @ handedness @ vt
    return float(np.sqrt(np.mean(np.sum((still @ rotation - moved) ** 2, axis=-1))))
