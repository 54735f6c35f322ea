"""The held nodes and loads of a scene (its [[fix]] and [[load]] blocks, docs/scene-format.md)
that act at a frame, for render.py to draw.

The scene's text comes from the output file's `scene` attribute or from a scene file. The scene
loader has validated it when the run started, so this reads it without checking again; a node
outside the grid (a region written for another `grid.nodes` than the one a `--set` gave the
run) is left out.
"""

import tomllib

import numpy as np


def region_nodes(block, shape):
    """The (k, l) nodes [count, 2] a fix or load block names, by `nodes` or `region`."""
    m, n = shape
    if "nodes" in block:
        nodes = np.array(block["nodes"], dtype=int).reshape(-1, 2)
    else:
        region = block.get("region", {})
        k, l = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
        if "rect" in region:
            k0, l0, k1, l1 = region["rect"]
            inside = (k >= k0) & (k <= k1) & (l >= l0) & (l <= l1)
        elif "disk" in region:
            centre_k, centre_l = region["disk"]["center"]
            radius = region["disk"]["radius"]
            inside = (k - centre_k) ** 2 + (l - centre_l) ** 2 <= radius ** 2
        elif "row" in region:
            inside = l == region["row"]
        elif "column" in region:
            inside = k == region["column"]
        else:
            inside = np.zeros(shape, dtype=bool)
        nodes = np.argwhere(inside)
    on_grid = (nodes[:, 0] >= 0) & (nodes[:, 0] < m) & (nodes[:, 1] >= 0) & (nodes[:, 1] < n)
    return nodes[on_grid]


def acts(block, step, time):
    """Whether a block acts at a frame of this step and time: its windows in steps and in
    seconds are inclusive, and both must hold (docs/scene-format.md, "Fixes and loads")."""
    return (block.get("start", 0) <= step <= block.get("end", step)
            and block.get("start_time", 0.0) <= time <= block.get("end_time", time))


class Constraints:
    """A scene's fixes and loads on a grid of `shape` (m, n)."""

    def __init__(self, scene_text, shape):
        scene = tomllib.loads(scene_text)
        self.fixes = [(block, region_nodes(block, shape)) for block in scene.get("fix", [])]
        self.loads = [(block, region_nodes(block, shape),
                       np.asarray(block.get("force", [0.0, 0.0, 0.0]), dtype=float))
                      for block in scene.get("load", [])]

    def __bool__(self):
        return bool(self.fixes or self.loads)

    def held(self, step, time):
        """The nodes [count, 2] some fix holds at this frame, each once."""
        nodes = [nodes for block, nodes in self.fixes if acts(block, step, time)]
        if not nodes:
            return np.zeros((0, 2), dtype=int)
        return np.unique(np.concatenate(nodes), axis=0)

    def lines(self, step, time):
        """The fixes of a list of nodes on one grid line (one k or one l), as the node pairs at
        the line's two ends: S1's clothesline, S4's flag pole. Only the nodes of such a fix are
        held, so the line is the support that holds them."""
        ends = []
        for block, nodes in self.fixes:
            if "nodes" not in block or len(nodes) < 2 or not acts(block, step, time):
                continue
            for axis in (0, 1):
                if np.all(nodes[:, axis] == nodes[0, axis]):
                    along = nodes[:, 1 - axis]
                    ends.append((nodes[along.argmin()], nodes[along.argmax()]))
                    break
        return ends

    def forces(self, step, time):
        """The loaded nodes [count, 2] at this frame and the total force on each [count, 3]."""
        total = {}
        for block, nodes, force in self.loads:
            if acts(block, step, time):
                for node in map(tuple, nodes):
                    total[node] = total.get(node, 0.0) + force
        if not total:
            return np.zeros((0, 2), dtype=int), np.zeros((0, 3))
        return np.array(list(total)), np.array(list(total.values()))

    def largest_force(self):
        """The largest force on one node of any one load block (N), or 0: the scale of the
        arrows, the same for every frame, so that they shrink when a load eases."""
        return max((float(np.linalg.norm(force)) for _, _, force in self.loads), default=0.0)
