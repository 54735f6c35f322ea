#!/usr/bin/env python3
"""Quality of a sheet's shape in the frames of a run (issue 11, item 5).

    /usr/bin/python3 tools/sheet_quality.py OUT.h5 [--json] [--every N] [--thickness T]

Per frame, from /positions [frames, m, n, 3] (node [k, l] at [f, k, l, :], docs/output.md):

  det ratio   smallest det a / det A over the cells: cell [k, l] has the edge vectors
              e1 = r[k+1, l] - r[k, l], e2 = r[k, l+1] - r[k, l]; a = |e1|^2 |e2|^2 - (e1.e2)^2,
              A the same of frame 0 (the rest state). 0 = a cell collapsed to a line.
  signed      the same with the sign of n . n_nb, n the cell's unit normal e1 x e2 and n_nb the
              sum of the unit normals of its edge neighbours: negative = a cell inverted against
              the cells around it (the sheet turned through itself there).
  min cos     smallest cosine between the unit normals of two edge-adjacent cells: 1 flat,
              0 a right-angle crease, -1 folded fully over.
  close pairs node pairs more than 3 indices apart (Chebyshev distance in (k, l) > 3) whose
              distance is below h/2, h the smallest rest spacing (from frame 0); and the
              smallest distance / h of such far-apart pairs within h (none within h: blank).
              Found with a uniform grid of bins of size h (numpy), so a 120 x 120 sheet over a
              hundred frames takes seconds. With --thickness T (metres, below h), also those
              closer than T/2 ("pairs<t/2"): self-contact keeps its layers T apart
              (docs/contact.md, "Self-contact").
  crossed     pairs of the sheet's triangles (area()'s two a cell, pairs sharing a node left
              out) that pass through each other, by an exact test: in general position two
              triangles intersect when an edge of one passes through the other, decided by
              the signs of tetrahedron volumes (orient), touching not counted; coplanar
              overlaps are not counted. Also the cells those triangles lie in ("crossing
              cells" in --json). 0 for a sheet that never passes through itself.
  area ratio  S / S0, S the sum over cells of the two triangles (k,l)(k+1,l)(k,l+1) and
              (k+1,l+1)(k,l+1)(k+1,l).
  zig-zag     the grid-scale crinkle: along each grid line the second differences
              D_k = r[k+1] - 2 r[k] + r[k-1] of neighbouring nodes; a smooth fold, resolved by
              the grid, has D_k close to D_k+1, a zig-zag at the grid's own scale (the
              highest frequency it holds, r[k] = (-1)^k a) has D_k = -D_k+1. "zz amp" is the
              largest |D_k - D_k+1| / 8 (metres: a for that zig-zag), "zz frac" the share of
              sum |D_k - D_k+1|^2 in sum |D_k - D_k+1|^2 + |D_k + D_k+1|^2 over both grid
              directions: sin²(π h/λ) for a fold of wavelength λ (0.024 at 20 nodes a
              wavelength), 1 for a pure zig-zag. A sheet flat to rounding (every |D_k| below
              1e-12 of its largest coordinate) has no share ("—"): its second differences are
              rounding noise, whose share says nothing (a flat sheet falling read 0.6-0.8).

Prints a table (one line per frame, then the extremes over the run); --json prints one JSON
object {"file", "grid", "h", "frames": [...], "overall": {...}} instead.
"""

import argparse
import json
import math
import os
import sys

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402
import numpy as np  # noqa: E402

FAR = 3  # pairs closer than this many indices (Chebyshev) are neighbours on the sheet


def cell_vectors(r):
    e1 = r[1:, :-1] - r[:-1, :-1]
    e2 = r[:-1, 1:] - r[:-1, :-1]
    return e1, e2


def det_metric(e1, e2):
    a11 = np.einsum("...i,...i", e1, e1)
    a22 = np.einsum("...i,...i", e2, e2)
    a12 = np.einsum("...i,...i", e1, e2)
    return a11 * a22 - a12 * a12


def area(r):
    p00, p10, p01, p11 = r[:-1, :-1], r[1:, :-1], r[:-1, 1:], r[1:, 1:]
    t1 = np.linalg.norm(np.cross(p10 - p00, p01 - p00), axis=-1)
    t2 = np.linalg.norm(np.cross(p01 - p11, p10 - p11), axis=-1)
    return 0.5 * float(t1.sum() + t2.sum())


def unit_normals(e1, e2):
    n = np.cross(e1, e2)
    norm = np.linalg.norm(n, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0, n / np.where(norm > 0, norm, 1), 0.0)


def bin_pairs(points, size):
    """Index pairs (i, j) of points in the same or neighbouring bins of a uniform grid of bins
    of `size`, as arrays, one neighbouring offset at a time (each pair twice, i = j too): every
    two points closer than `size` are among them."""
    cell = np.floor((points - points.min(axis=0)) / size).astype(np.int64)
    dims = cell.max(axis=0) + 3
    key = ((cell[:, 0] + 1) * dims[1] + (cell[:, 1] + 1)) * dims[2] + (cell[:, 2] + 1)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                target = key + (dx * dims[1] + dy) * dims[2] + dz
                lo = np.searchsorted(skey, target, "left")
                sizes = np.searchsorted(skey, target, "right") - lo
                total = int(sizes.sum())
                if total == 0:
                    continue
                i = np.repeat(np.arange(points.shape[0]), sizes)
                yield i, order[np.arange(total) + np.repeat(lo - np.cumsum(sizes) + sizes, sizes)]


def proximity(r, h, thickness=None):
    """Pairs (i < j) with Chebyshev index distance > FAR closer than h: (count below h/2,
    smallest distance / h or None, count below thickness/2 or None without a thickness, which
    must be below h)."""
    m, n, _ = r.shape
    pts = r.reshape(-1, 3)
    kk, ll = np.divmod(np.arange(m * n), n)
    count, thin, best = 0, 0, math.inf
    for i, j in bin_pairs(pts, h):
        keep = (i < j) & (np.maximum(abs(kk[i] - kk[j]), abs(ll[i] - ll[j])) > FAR)
        if not keep.any():
            continue
        i, j = i[keep], j[keep]
        d = np.linalg.norm(pts[i] - pts[j], axis=-1)
        count += int((d < 0.5 * h).sum())
        if thickness is not None:
            thin += int((d < 0.5 * thickness).sum())
        best = min(best, float(d.min()))
    ratio = best / h if best < h else None
    return count, ratio, (thin if thickness is not None else None)


def orient(a, b, c, d):
    """Six times the signed volume of the tetrahedra (a, b, c, d), over the leading axis."""
    return np.einsum("...i,...i", np.cross(b - a, c - a), d - a)


def segments_cross(p, q, a, b, c):
    """Whether segment pq passes through the inside of triangle abc: its ends on either side
    of the triangle's plane, and the line pq on the same side of each of the triangle's three
    edges. Touching (a zero volume) does not count."""
    s1, s2 = orient(a, b, c, p), orient(a, b, c, q)
    e1, e2, e3 = orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)
    return (s1 * s2 < 0) & (((e1 > 0) & (e2 > 0) & (e3 > 0)) | ((e1 < 0) & (e2 < 0) & (e3 < 0)))


def crossings(r):
    """(pairs of triangles that pass through each other, cells those triangles lie in) of one
    frame. The triangles are area()'s two a cell; pairs sharing a node are left out. Two
    triangles in general position intersect exactly when an edge of one passes through the
    other (segments_cross, on all six edges); coplanar overlaps are not counted. Candidates:
    triangles in neighbouring bins of a uniform grid over their centroids, each bin twice the
    largest distance from a centroid to its corners among the triangles within four times the
    median of that distance; the others, stretched far (a sheet blowing up), are paired with
    every triangle; then the boxes' overlap."""
    m, n, _ = r.shape
    idx = np.arange(m * n).reshape(m, n)
    corners = np.concatenate([
        np.stack([idx[:-1, :-1], idx[1:, :-1], idx[:-1, 1:]], axis=-1).reshape(-1, 3),
        np.stack([idx[1:, 1:], idx[:-1, 1:], idx[1:, :-1]], axis=-1).reshape(-1, 3)])
    cells = np.concatenate([np.arange((m - 1) * (n - 1))] * 2)
    tri = r.reshape(-1, 3)[corners]  # [T, 3 corners, 3]
    centre = tri.mean(axis=1)
    reach = np.linalg.norm(tri - centre[:, None, :], axis=-1).max(axis=1)
    typical = reach <= 4.0 * float(np.median(reach))
    size = max(2.0 * float(reach[typical].max()), 1e-300)
    low, high = tri.min(axis=1), tri.max(axis=1)
    found = []

    def test(i, j):
        """Keeps the pairs (i, j) that share no node, whose boxes overlap and that cross."""
        for c in range(0, i.size, 1 << 20):
            a_i, a_j = i[c:c + (1 << 20)], j[c:c + (1 << 20)]
            keep = ~(corners[a_i][:, :, None] == corners[a_j][:, None, :]).any(axis=(1, 2))
            keep &= ((low[a_i] <= high[a_j]) & (low[a_j] <= high[a_i])).all(axis=1)
            a_i, a_j = a_i[keep], a_j[keep]
            if a_i.size == 0:
                continue
            a, b = tri[a_i], tri[a_j]
            hit = np.zeros(a_i.size, dtype=bool)
            for e in range(3):
                hit |= segments_cross(a[:, e], a[:, (e + 1) % 3], b[:, 0], b[:, 1], b[:, 2])
                hit |= segments_cross(b[:, e], b[:, (e + 1) % 3], a[:, 0], a[:, 1], a[:, 2])
            if hit.any():
                found.append(np.stack([a_i[hit], a_j[hit]], axis=1))

    small = np.flatnonzero(typical)
    for i, j in bin_pairs(centre[small], size):
        keep = i < j
        test(small[i[keep]], small[j[keep]])
    everything = np.arange(len(tri))
    for t in np.flatnonzero(~typical):
        others = everything[typical | (everything > t)]
        test(np.full(others.size, t), others)
    if not found:
        return 0, 0
    pairs = np.concatenate(found)
    return len(pairs), len(np.unique(cells[pairs]))


def zigzag(r):
    """(largest grid-scale amplitude in metres, grid-scale share of the curvature) of one frame,
    both grid directions together; (0, None) on a sheet too small or too flat to say."""
    high = low = 0.0
    amplitude = 0.0
    largest = 0.0
    for axis in (0, 1):
        x = np.moveaxis(r, axis, 0)
        if x.shape[0] < 4:
            continue
        d = x[2:] - 2.0 * x[1:-1] + x[:-2]
        largest = max(largest, float(np.abs(d).max()))
        minus = d[1:] - d[:-1]
        plus = d[1:] + d[:-1]
        high += float((minus ** 2).sum())
        low += float((plus ** 2).sum())
        amplitude = max(amplitude, float(np.linalg.norm(minus, axis=-1).max()) / 8.0)
    if largest <= 1e-12 * float(np.abs(r).max()):
        return amplitude, None
    return amplitude, high / (high + low)


def analyse(path, every=1, thickness=None):
    with h5py.File(path, "r") as f:
        pos = f["/positions"]
        times = f["/time"][:]
        steps = f["/step"][:] if "/step" in f else np.arange(len(times))
        frames = list(range(0, pos.shape[0], every))
        if frames[-1] != pos.shape[0] - 1:
            frames.append(pos.shape[0] - 1)
        rest = pos[0]
        e1, e2 = cell_vectors(rest)
        det_rest = det_metric(e1, e2)
        h = float(min(np.linalg.norm(e1, axis=-1).min(), np.linalg.norm(e2, axis=-1).min()))
        area0 = area(rest)
        out = []
        for fi in frames:
            r = pos[fi]
            e1, e2 = cell_vectors(r)
            ratio = det_metric(e1, e2) / det_rest
            nrm = unit_normals(e1, e2)
            nb = np.zeros_like(nrm)
            nb[1:] += nrm[:-1]
            nb[:-1] += nrm[1:]
            nb[:, 1:] += nrm[:, :-1]
            nb[:, :-1] += nrm[:, 1:]
            sign = np.where(np.einsum("...i,...i", nrm, nb) < 0, -1.0, 1.0)
            cos_k = np.einsum("...i,...i", nrm[1:], nrm[:-1])
            cos_l = np.einsum("...i,...i", nrm[:, 1:], nrm[:, :-1])
            min_cos = min(float(cos_k.min()) if cos_k.size else 1.0,
                          float(cos_l.min()) if cos_l.size else 1.0)
            finite = bool(np.isfinite(r).all())
            zz_amp, zz_frac = zigzag(r) if finite else (None, None)
            pairs, dmin, thin = proximity(r, h, thickness) if finite else (None, None, None)
            crossed, crossed_cells = crossings(r) if finite else (None, None)
            out.append({
                "frame": fi, "step": int(steps[fi]), "time": float(times[fi]),
                "min_det_ratio": float(ratio.min()),
                "min_signed_det_ratio": float((sign * ratio).min()),
                "inverted_cells": int((sign < 0).sum()),
                "min_normal_cos": min_cos,
                "close_pairs": pairs, "min_far_distance_over_h": dmin,
                "pairs_below_half_thickness": thin,
                "crossing_pairs": crossed, "crossing_cells": crossed_cells,
                "area_ratio": area(r) / area0,
                "zigzag_amplitude": zz_amp, "zigzag_fraction": zz_frac,
            })
        status = f.attrs.get("status", "")
        if isinstance(status, bytes):
            status = status.decode()

    def extreme(key, fn):
        vals = [(fr[key], fr["time"]) for fr in out if fr[key] is not None]
        if not vals:
            return None, None
        v, t = fn(vals, key=lambda x: x[0])
        return v, t

    overall = {"status": status, "frames": len(out)}
    for key, fn in (("min_det_ratio", min), ("min_signed_det_ratio", min),
                    ("inverted_cells", max), ("min_normal_cos", min), ("close_pairs", max),
                    ("pairs_below_half_thickness", max),
                    ("crossing_pairs", max), ("crossing_cells", max),
                    ("min_far_distance_over_h", min), ("area_ratio", min),
                    ("zigzag_amplitude", max), ("zigzag_fraction", max)):
        v, t = extreme(key, fn)
        overall[key] = v
        overall[key + "_time"] = t
    overall["max_area_ratio"] = max(fr["area_ratio"] for fr in out)
    overall["final_area_ratio"] = out[-1]["area_ratio"]
    return {"file": path, "grid": list(rest.shape[:2]), "h": h, "thickness": thickness,
            "frames": out, "overall": overall}


def fmt(v, spec):
    return "—" if v is None else format(v, spec)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("h5")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--every", type=int, default=1, help="analyse every N-th frame (and the last)")
    ap.add_argument("--thickness", type=float,
                    help="the cloth's thickness t, m: also count the pairs closer than t/2")
    args = ap.parse_args()
    res = analyse(args.h5, max(1, args.every), args.thickness)
    thin = args.thickness is not None
    if args.json:
        json.dump(res, sys.stdout)
        print()
        return
    print(f"{res['file']}: grid {res['grid'][0]} x {res['grid'][1]}, h = {res['h']:.4g} m, "
          f"status {res['overall']['status'] or '?'}")
    print(f"{'frame':>5} {'time':>8} {'det a/A':>9} {'signed':>9} {'inv':>4} {'min cos':>8} "
          f"{'pairs<h/2':>9} {'dmin/h':>7} {'crossed':>7} {'S/S0':>7} {'zz amp':>8} "
          f"{'zz frac':>7}" + (f" {'pairs<t/2':>9}" if thin else ""))
    for fr in res["frames"]:
        print(f"{fr['frame']:5d} {fr['time']:8.3f} {fr['min_det_ratio']:9.3g} "
              f"{fr['min_signed_det_ratio']:9.3g} {fr['inverted_cells']:4d} "
              f"{fr['min_normal_cos']:8.3f} {fmt(fr['close_pairs'], '9d')} "
              f"{fmt(fr['min_far_distance_over_h'], '7.3f')} {fmt(fr['crossing_pairs'], '7d')} "
              f"{fr['area_ratio']:7.4f} "
              f"{fmt(fr['zigzag_amplitude'], '8.2e')} {fmt(fr['zigzag_fraction'], '7.3f')}"
              + (f" {fmt(fr['pairs_below_half_thickness'], '9d')}" if thin else ""))
    o = res["overall"]
    print(f"overall: det a/A {o['min_det_ratio']:.3g} (t {o['min_det_ratio_time']:.3f}), signed "
          f"{o['min_signed_det_ratio']:.3g}, most inverted cells {o['inverted_cells']}, min cos "
          f"{o['min_normal_cos']:.3f} (t {o['min_normal_cos_time']:.3f}), most pairs<h/2 "
          f"{fmt(o['close_pairs'], 'd')}, dmin/h {fmt(o['min_far_distance_over_h'], '.3f')}, "
          f"most crossing triangle pairs {fmt(o['crossing_pairs'], 'd')} (in "
          f"{fmt(o['crossing_cells'], 'd')} cells), "
          f"S/S0 {o['area_ratio']:.4f}..{o['max_area_ratio']:.4f} (final "
          f"{o['final_area_ratio']:.4f}), zig-zag amplitude up to "
          f"{fmt(o['zigzag_amplitude'], '.2e')} m, share up to {fmt(o['zigzag_fraction'], '.3f')}"
          + (f", most pairs<t/2 {fmt(o['pairs_below_half_thickness'], 'd')}" if thin else ""))


if __name__ == "__main__":
    main()
