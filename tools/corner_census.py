#!/usr/bin/python3
"""Count hexahedra folded through themselves and nodes inside elements they do not belong to.

For the elements of one part (the `part` cell field; default 0, the can of the can crush)
in one field output of an anvil run:

* the elements with a non-positive Jacobian at one or more of their eight corners. The
  one-point hexahedron checks only its mean volume, so such an element runs on ("no
  inverted element") while its shape has folded through itself: with one element through
  a wall the wall's bending is the element's hourglass mode, and a tight fold does this;
* the nodes of the part that lie inside another of its elements (behind all six faces'
  mean planes), with their depth behind that element's nearest exterior face: the
  overlap of material, whatever the contact search found.

docs/contact.md ("Penetration on the 4-rank model") has what it gives for the can crush.
"""

import argparse
import math
from collections import defaultdict

import numpy as np

from anvil_results import run_main
from anvil_vtu import DEFAULT_TIME_TOLERANCE, VTK_HEXAHEDRON, VtuError, load_output, time_text

HEX_FACES = [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7), (0, 3, 2, 1), (4, 5, 6, 7)]
# The three edge neighbours of each corner, ordered so that an undistorted element has a
# positive determinant at every corner.
CORNER_EDGES = [(1, 3, 4), (2, 0, 5), (3, 1, 6), (0, 2, 7), (7, 5, 0), (4, 6, 1), (5, 7, 2), (6, 4, 3)]


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir", help="anvil output directory (or a .pvd, .pvtu or .vtu file)")
    which = ap.add_mutually_exclusive_group()
    which.add_argument("--step", type=int, help="field output number (default: the last)")
    which.add_argument("--time", type=float, help="the field output nearest this time, s; "
                       "an error when none is within --time-tolerance")
    ap.add_argument("--time-tolerance", type=float, default=DEFAULT_TIME_TOLERANCE,
                    metavar="S", help="largest accepted distance between --time and the "
                    f"output read, s (default {DEFAULT_TIME_TOLERANCE:g})")
    ap.add_argument("--part", type=int, default=0, help="part index (the `part` cell field)")
    args = ap.parse_args(argv)
    if not args.time_tolerance >= 0:
        ap.error(f"--time-tolerance must be >= 0, got {args.time_tolerance:g}")
    return args


def hexahedra(grid, part):
    """Node positions (one row per node id) and the connectivity of the part's hexahedra."""
    ids = grid.point_data.get("node_id")
    if ids is None:
        raise VtuError(f"{grid.sources[0]}: no node_id point array")
    uniq, first, inverse = np.unique(np.asarray(ids), return_index=True, return_inverse=True)
    x = grid.points[first]
    starts = np.concatenate(([0], grid.offsets[:-1]))
    keep = (grid.cell_types == VTK_HEXAHEDRON) & (np.asarray(grid.cell_data["part"]) == part)
    conn = np.stack([inverse[grid.cell_conn[starts[keep] + a]] for a in range(8)], axis=1)
    return x, conn, uniq


def folded_corners(x, conn):
    """Per element, the number of corners with a non-positive Jacobian; the most negative."""
    dets = []
    for a, (i, j, k) in enumerate(CORNER_EDGES):
        o = x[conn[:, a]]
        dets.append(np.einsum("ij,ij->i", x[conn[:, i]] - o,
                              np.cross(x[conn[:, j]] - o, x[conn[:, k]] - o)))
    dets = np.stack(dets, axis=1)
    return (dets <= 0).sum(axis=1), min(0.0, float(dets.min()))


def nodes_inside(x, conn):
    """(depth, node row, element) of every node inside an element it does not belong to."""
    shared = defaultdict(int)
    for h in conn:
        for f in HEX_FACES:
            shared[tuple(sorted(h[a] for a in f))] += 1
    planes = []
    for h in conn:
        pl = []
        for f in HEX_FACES:
            q = x[[h[a] for a in f]]
            n = np.cross(q[2] - q[0], q[3] - q[1])
            n = n / (np.linalg.norm(n) or 1.0)
            pl.append((n, float(n @ q.mean(axis=0)), shared[tuple(sorted(h[a] for a in f))] == 1))
        planes.append(pl)
    lo, hi = x[conn].min(axis=1), x[conn].max(axis=1)
    cell = float((hi - lo).max())
    grid = defaultdict(list)
    for e in range(len(conn)):
        a, b = np.floor(lo[e] / cell).astype(int), np.floor(hi[e] / cell).astype(int)
        for i in range(a[0], b[0] + 1):
            for j in range(a[1], b[1] + 1):
                for k in range(a[2], b[2] + 1):
                    grid[(i, j, k)].append(e)
    owners = defaultdict(set)
    for e, h in enumerate(conn):
        for n in h:
            owners[int(n)].add(e)
    found = []
    for node in owners:
        p = x[node]
        best, where = 0.0, -1
        for e in grid.get(tuple(np.floor(p / cell).astype(int)), ()):
            if e in owners[node] or np.any(p < lo[e]) or np.any(p > hi[e]):
                continue
            depth = math.inf
            for n, off, exterior in planes[e]:
                s = float(n @ p) - off
                if s > 0:
                    break
                if exterior:
                    depth = min(depth, -s)
            else:
                if math.isfinite(depth) and depth > best:
                    best, where = depth, e
        if where >= 0:
            found.append((best, node, where))
    return sorted(found, reverse=True)


def main(argv=None):
    args = parse_args(argv)
    entry, grid = load_output(args.outdir, step=args.step, time=args.time,
                              tolerance=args.time_tolerance)
    x, conn, node_ids = hexahedra(grid, args.part)
    if len(conn) == 0:
        raise VtuError(f"{entry.path}: no hexahedra in part {args.part}")
    bad, worst = folded_corners(x, conn)
    inside = nodes_inside(x, conn)
    print(f"{entry.path}: {time_text(entry.time, ' = ', ' s')}, part {args.part}, {len(conn)} elements")
    print(f"  {int((bad > 0).sum())} with a non-positive corner Jacobian ({int(bad.sum())} corners,"
          f" most negative {worst * 1e9:.3f} mm^3)")
    # Global node ids as the contact search and its messages count them (node_id - 1).
    deepest = ", ".join(f"{d * 1e3:.3f} mm (node {node_ids[n] - 1})" for d, n, _ in inside[:3])
    print(f"  {len(inside)} nodes inside an element they do not belong to"
          + (f"; deepest behind its nearest exterior face: {deepest}" if inside else ""))
    return 0


if __name__ == "__main__":
    run_main(main, "corner_census.py")
