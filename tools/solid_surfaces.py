"""Rigid solids' surfaces (docs/output.md, /solids) as facets for render.py: which solid is a
plane, its outward side, and triangles cut to the picture's box and split for the depth sort.

Vertices are in render.py's drawing coordinates, world (x, z, y).
"""

import math

import numpy as np


def is_plane(vertices, triangles):
    """A plane is written as one flat square (docs/output.md), and drawn as a floor."""
    return len(vertices) == 4 and len(triangles) == 2


def plane_normal(vertices, triangles):
    """A plane's outward unit normal in drawing coordinates, from its first triangle, which is
    counter-clockwise seen from outside in the world; drawing coordinates mirror the world's
    (y and z swapped), which reverses that winding."""
    a, b, c = vertices[triangles[0]]
    normal = -np.cross(b - a, c - a)
    return normal / max(float(np.linalg.norm(normal)), 1e-300)


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
    """Triangles [count, 3, 3] covering a convex polygon, none with a side longer than
    `largest`: each triangle of the polygon's fan cut into the k^2 triangles of its k-fold
    barycentric lattice."""
    pieces = []
    for a, b, c in (polygon[[0, i, i + 1]] for i in range(1, len(polygon) - 1)):
        longest = max(np.linalg.norm(b - a), np.linalg.norm(c - b), np.linalg.norm(a - c))
        k = max(1, math.ceil(longest / largest))
        i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
        upright = i + j < k
        inverted = i + j < k - 1

        def lattice(di, dj, where):
            return (a + np.multiply.outer((i[where] + di) / k, b - a)
                    + np.multiply.outer((j[where] + dj) / k, c - a))

        pieces.append(np.stack([lattice(0, 0, upright), lattice(1, 0, upright),
                                lattice(0, 1, upright)], axis=1))
        pieces.append(np.stack([lattice(1, 0, inverted), lattice(1, 1, inverted),
                                lattice(0, 1, inverted)], axis=1))
    return np.concatenate(pieces) if pieces else np.zeros((0, 3, 3))
