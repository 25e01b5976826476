#!/usr/bin/python3
"""The paper's Figure 3 from a multi-rank can crush run: the FE and contact decompositions.

Six panels drawn from the field outputs of OUTDIR (results.pvd) nearest to t = 0, 1.6 ms
and 3.2 ms (--times):

    (a) FE decomposition (fe_rank) at t = 0        (the paper's Chaco partition)
    (b) contact decomposition (contact_rank) at t = 0   (the paper's RCB of the surfaces)
    (c) contact decomposition at 1.6 ms, deformed  (d) the same on the undeformed shape
    (e) contact decomposition at 3.2 ms, deformed  (f) the same on the undeformed shape

A rank has the same colour in every panel.  contact_rank is per element: the RCB rank of
the element's first exterior face; -1 (grey) marks an element without one.

anvil's run writes its t = 0 output before the first contact RCB, so there contact_rank
is still the FE rank.  Panel (b) therefore takes --t0 DIR, the output of
`anvil decompose` for the same deck and rank count, when given (and warns otherwise).

    mpirun -np 4 anvil bench can-crush -o out/can_crush_np4
    mpirun -np 4 anvil bench can-crush --print-deck > out/can_crush_np4.yaml
    mpirun -np 4 anvil decompose out/can_crush_np4.yaml -o out/can_crush_np4_t0
    /usr/bin/python3 tools/plot_figure3.py out/can_crush_np4 --t0 out/can_crush_np4_t0 \\
        -o docs/figures/figure3_decompositions.png
"""

import argparse
import os
import sys

import numpy as np

from anvil_results import ResultsError, length_unit, read_summary, run_main, save_figure, use_agg
from anvil_vtu import DEFAULT_TIME_TOLERANCE, load_output
from plot_decomposition import (
    add_faces,
    exterior_surface,
    front_faces,
    light_vector,
    padded_limits,
    shade,
    style_3d_axes,
)

NO_RANK = (0.75, 0.75, 0.75, 1.0)  # colour of contact_rank -1


def parse_args(argv=None):
    """Command line -> argparse.Namespace."""
    p = argparse.ArgumentParser(
        description="Figure 3 of Attaway et al. 1997: FE and contact decompositions of the can "
        "crush at t = 0, 1.6 and 3.2 ms on the deformed and undeformed shape.",
        epilog="example:\n  plot_figure3.py out/can_crush_np4 --t0 out/can_crush_np4_t0 "
        "-o figure3.png",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("outdir", help="anvil run directory (results.pvd) with outputs at the --times")
    p.add_argument("--t0", metavar="DIR",
                   help="`anvil decompose` output (same deck, same ranks) for panel (b)")
    p.add_argument("--times", type=float, nargs=3, metavar=("T0", "T1", "T2"),
                   default=(0.0, 1.6e-3, 3.2e-3),
                   help="the three output times [s] (default 0 1.6e-3 3.2e-3)")
    p.add_argument("--time-tolerance", type=float, default=DEFAULT_TIME_TOLERANCE,
                   help="largest accepted distance between a wanted time and the output's "
                   f"[s] (default {DEFAULT_TIME_TOLERANCE:g})")
    p.add_argument("--elev", type=float, default=20.0, help="view elevation [deg] (default 20)")
    p.add_argument("--azim", type=float, default=-60.0, help="view azimuth [deg] (default -60)")
    p.add_argument("--cut", metavar="AXIS=VALUE",
                   help="cutaway: keep only cells whose centroid has AXIS <= VALUE [m]")
    p.add_argument("--no-edges", action="store_true", help="do not draw element edges")
    p.add_argument("--axes", action="store_true", help="draw the x, y, z axes in each panel")
    p.add_argument("--title", help="title (default: from summary.json)")
    p.add_argument("--dpi", type=int, default=110, help="PNG resolution (default 110)")
    p.add_argument("-o", "--output", help="PNG to write (default OUTDIR/figure3.png)")
    args = p.parse_args(argv)
    if not args.time_tolerance >= 0:
        p.error(f"--time-tolerance must be >= 0, got {args.time_tolerance:g}")
    if args.cut is not None:
        axis, _, value = args.cut.partition("=")
        try:
            if axis.strip().lower() not in ("x", "y", "z"):
                raise ValueError(axis)
            args.cut = ("xyz".index(axis.strip().lower()), float(value))
        except ValueError:
            p.error(f"--cut expects AXIS=VALUE with AXIS x, y or z, got {args.cut!r}")
    return args


def load_at(outdir, t, tol):
    """(entry, grid) of the output of `outdir` nearest to time t; VtuError when the nearest
    is further than tol (the run may have stopped early; anvil_vtu.select_entry)."""
    return load_output(outdir, time=t, tolerance=tol)


def rank_palette(n_ranks):
    """RGBA per rank 0..n-1: tab10 up to 10 ranks, tab20 up to 20, else turbo samples."""
    import matplotlib

    if n_ranks <= 10:
        cmap = matplotlib.colormaps["tab10"]
        return [cmap(i) for i in range(n_ranks)]
    if n_ranks <= 20:
        cmap = matplotlib.colormaps["tab20"]
        return [cmap(i) for i in range(n_ranks)]
    cmap = matplotlib.colormaps["turbo"]
    # interleave so that neighbouring ranks (often neighbouring boxes) differ in colour
    order = np.argsort([(i * 7919) % n_ranks for i in range(n_ranks)])
    return [cmap(0.05 + 0.9 * k / (n_ranks - 1)) for k in order]


def rank_colors(values, palette):
    """RGBA per face from integer rank values (-1 or out of range: grey)."""
    out = np.empty((len(values), 4))
    for i, v in enumerate(np.asarray(values, dtype=np.int64)):
        out[i] = palette[v] if 0 <= v < len(palette) else NO_RANK
    return out


def panels(args):
    """The six panels: (label, caption, (entry, grid), field, undeformed)."""
    t0, t1, t2 = args.times
    tol = args.time_tolerance
    run0 = load_at(args.outdir, t0, tol)
    if args.t0:
        dec0 = load_output(args.t0)
        source_b = "anvil decompose"
    else:
        dec0 = run0
        source_b = "run output"
        g = run0[1]
        if "contact_rank" in g.cell_data and np.array_equal(g.cell_data["contact_rank"],
                                                            g.cell_data["fe_rank"]):
            print("warning: the run's t = 0 contact_rank equals fe_rank (written before the "
                  "first contact RCB); pass --t0 with `anvil decompose` output for panel (b)",
                  file=sys.stderr)
    run1 = load_at(args.outdir, t1, tol)
    run2 = load_at(args.outdir, t2, tol)
    ms = lambda e: f"t = {e.time * 1e3:.3g} ms"  # noqa: E731
    return [
        ("a", f"FE decomposition, {ms(run0[0])}", run0, "fe_rank", False),
        ("b", f"contact decomposition, t = 0 ({source_b})", dec0, "contact_rank", False),
        ("c", f"contact decomposition, {ms(run1[0])}, deformed", run1, "contact_rank", False),
        ("d", f"contact decomposition, {ms(run1[0])}, undeformed", run1, "contact_rank", True),
        ("e", f"contact decomposition, {ms(run2[0])}, deformed", run2, "contact_rank", False),
        ("f", f"contact decomposition, {ms(run2[0])}, undeformed", run2, "contact_rank", True),
    ]


def per_rank_counts(grid, field, n_ranks):
    """Elements per rank of an integer cell field (length n_ranks; -1 not counted)."""
    v = np.asarray(grid.cell_data[field], dtype=np.int64)
    return np.bincount(v[(v >= 0) & (v < n_ranks)], minlength=n_ranks)


def main(argv=None):
    """Read the outputs, draw the six panels, write the PNG and print its path."""
    args = parse_args(argv)
    plt = use_agg()
    from matplotlib.patches import Patch

    spec = panels(args)
    for _, _, (entry, grid), field, _ in spec:
        if field not in grid.cell_data:
            raise ResultsError(f"{entry.path}: no cell field {field!r} (a run without contact?)")
    n_ranks = int(max(np.max(g.cell_data[f]) for _, _, (_, g), f, _ in spec)) + 1
    summary = read_summary(args.outdir) if os.path.isdir(args.outdir) else None
    if summary and summary.get("ranks"):
        n_ranks = max(n_ranks, int(summary["ranks"]))
    palette = rank_palette(n_ranks)

    surfaces = [exterior_surface(g, f, und, args.cut, e.path)
                for _, _, (e, g), f, und in spec]
    all_pts = np.concatenate([s.quads.reshape(-1, 3) for s in surfaces])
    lf, lu = length_unit((all_pts.max(axis=0) - all_pts.min(axis=0)).max())
    lo, hi = padded_limits(all_pts * lf)
    light = light_vector(args.elev, args.azim)

    fig = plt.figure(figsize=(15, 11.2))
    any_missing = False
    for i, ((label, caption, (entry, grid), field, _), surf) in enumerate(zip(spec, surfaces)):
        ax = fig.add_subplot(2, 3, 1 + [0, 3, 1, 4, 2, 5][i], projection="3d",
                             computed_zorder=False)
        front = front_faces(surf, args.elev, args.azim)
        rgba = shade(rank_colors(surf.values, palette)[front], surf.normals[front], light, 0.6)
        any_missing = any_missing or bool(np.any(surf.values < 0))
        # Opaque edges a shade darker than their face: they draw the mesh and also cover
        # the anti-aliasing seams between faces (which would let the background through).
        edge_rgba = rgba.copy()
        if not args.no_edges:
            edge_rgba[:, :3] *= 0.7
        add_faces(ax, surf.quads[front] * lf, rgba, linewidth=0.5, edgecolors=edge_rgba)
        style_3d_axes(ax, lo, hi, lu, args.elev, args.azim, zoom=1.0 if args.axes else 1.12,
                      label_size=8, tick_size=7)
        if not args.axes:
            ax.set_axis_off()
        counts = per_rank_counts(grid, field, n_ranks)
        spread = (f"elements per rank {counts.min():,}-{counts.max():,}, max/mean "
                  f"{counts.max() / max(counts.mean(), 1e-300):.2f}")
        ax.set_title(f"({label}) {caption}\n{spread}", fontsize=9, pad=0)

    handles = [Patch(facecolor=c, edgecolor="0.3", label=f"rank {r}")
               for r, c in enumerate(palette)]
    if any_missing:
        handles.append(Patch(facecolor=NO_RANK, edgecolor="0.3", label="no exterior face"))
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 10), fontsize=9,
               frameon=False, bbox_to_anchor=(0.5, 0.0))
    head = args.title or "Scaled can crush (Attaway et al. 1997, Figure 3)"
    if summary:
        head += f": {summary.get('ranks', n_ranks)} ranks, {summary.get('elements', 0):,} elements"
    fig.suptitle(head + "\nFE decomposition (a) and contact RCB decomposition (b-f); "
                 "same colour = same rank", fontsize=12)
    fig.subplots_adjust(left=0.0, right=1.0, top=0.9, bottom=0.05, wspace=0.0, hspace=0.1)
    out = args.output or os.path.join(
        args.outdir if os.path.isdir(args.outdir) else ".", "figure3.png")
    save_figure(fig, out, dpi=args.dpi)
    print(out)
    return 0


if __name__ == "__main__":
    run_main(main, "plot_figure3.py")
