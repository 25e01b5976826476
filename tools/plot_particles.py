#!/usr/bin/python3
"""Draw SPH particles and the FE mesh of an anvil run in a section, one panel per output.

Particles (particles.pvd, vertex cells) whose position lies within a slab around the
section plane (--cut y=0 by default, half-thickness --slab, default one smoothing length
of the first output) are drawn as dots coloured by a particle field (sph_rank by
default: the SPH decomposition; or pressure, density, plastic_strain, velocity, a
component such as stress.zz or velocity.z). Hexahedra whose centroid lies in the slab
are drawn as grey outlines of their face that faces the section's -normal side, so the
structure appears in the same cut. Several outputs (--steps 0,2,4) give a sequence;
a negative index counts from the end (-1, the default, is the last output).

Without results.pvd (an `anvil decompose` output of a deck of particles only, which
writes no FE pieces) the particles are drawn alone.
"""

import argparse
import os
import sys

import numpy as np

from anvil_results import ResultsError, read_summary, run_main, save_figure, title_of, use_agg
from anvil_vtu import exodus_hint, read_grid, read_pvd, select_entry

FIELD_INFO = {
    "sph_rank": ("SPH rank", "", 1.0),
    "particle_set": ("particle set", "", 1.0),
    "pressure": ("pressure", "MPa", 1e-6),
    "density": ("density", "kg/m³", 1.0),
    "plastic_strain": ("equivalent plastic strain", "–", 1.0),
    "von_mises": ("von Mises stress", "MPa", 1e-6),
    "stress": ("stress", "MPa", 1e-6),
    "velocity": ("velocity", "m/s", 1.0),
    "displacement": ("displacement", "mm", 1e3),
    "energy": ("specific internal energy", "J/kg", 1.0),
}
COMPONENTS = {3: {"x": 0, "y": 1, "z": 2}, 6: {"xx": 0, "yy": 1, "zz": 2, "xy": 3, "yz": 4, "xz": 5}}
AXES = {"x": 0, "y": 1, "z": 2}
# Per section normal: the face of a VTK hexahedron lying on its -normal side.
SECTION_FACE = {0: [0, 3, 7, 4], 1: [0, 1, 5, 4], 2: [0, 1, 2, 3]}


def step_list(text):
    """argparse type of --steps: '0,2,-1' -> [0, 2, -1]; anything else is a usage error
    (exit 2) rather than a traceback from int()."""
    try:
        steps = [int(s) for s in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected comma-separated output indices such as 0,2,-1") from None
    return steps


def cut_plane(text):
    """argparse type of --cut: 'y=0' -> (1, 0.0)."""
    axis_name, _, value = text.partition("=")
    try:
        return AXES[axis_name], float(value)
    except (KeyError, ValueError):
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected AXIS=VALUE with AXIS x, y or z (e.g. y=0)") from None


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("outdir", help="anvil output directory (with particles.pvd)")
    p.add_argument("--steps", type=step_list, default=[-1],
                   help="comma-separated output indices of particles.pvd, negative from the "
                   "end (default: -1, the last)")
    p.add_argument("--field", default="sph_rank", help="particle field (default sph_rank)")
    p.add_argument("--cut", type=cut_plane, default="y=0",
                   help="section plane AXIS=VALUE (default y=0)")
    p.add_argument("--slab", type=float, default=None, help="half-thickness of the slab, m")
    p.add_argument("--clim", type=float, nargs=2, default=None, help="colour range (display units)")
    p.add_argument("-o", "--output", default="particles.png", help="PNG to write")
    args = p.parse_args(argv)
    # A slab of no thickness selects no particle: an empty figure that looks like a bug.
    if args.slab is not None and not args.slab > 0:
        p.error(f"--slab {args.slab:g}: the half-thickness must be > 0 (m)")
    if args.clim is not None and not args.clim[0] < args.clim[1]:
        p.error("--clim needs MIN < MAX")
    return args


def field_values(grid, name, where):
    base, _, comp = name.partition(".")
    if base not in grid.point_data:
        raise ResultsError(f"{where}: no particle field {base!r} (have {sorted(grid.point_data)})")
    v = np.asarray(grid.point_data[base], dtype=float)
    if v.ndim == 2:
        if comp:
            idx = COMPONENTS.get(v.shape[1], {}).get(comp)
            if idx is None:
                raise ResultsError(f"{where}: {base} has no component {comp!r}")
            v = v[:, idx]
        else:
            v = np.linalg.norm(v, axis=1)
    label, unit, factor = FIELD_INFO.get(base, (base, "", 1.0))
    return v * factor, f"{label}{'.' + comp if comp else ''}" + (f" ({unit})" if unit else "")


def main(argv=None):
    args = parse_args(argv)
    axis, cut = args.cut
    cut_text = f"{'xyz'[axis]}={cut:g}"
    plane = [a for a in range(3) if a != axis]
    if not os.path.isdir(args.outdir):
        raise ResultsError(f"{args.outdir}: no such directory")
    pvd = os.path.join(args.outdir, "particles.pvd")
    if not os.path.exists(pvd):
        raise ResultsError(f"{args.outdir}: no particles.pvd (a run without particles?)")
    entries = read_pvd(pvd)
    for s in args.steps:
        if not -len(entries) <= s < len(entries):
            raise ResultsError(f"{pvd}: --steps {s} is out of range: the series has "
                               f"{len(entries)} output(s), 0 to {len(entries) - 1}")
    # The mesh: `anvil decompose` of a deck of particles only writes no FE pieces and no
    # results.pvd, so there the particles are drawn alone (docs/sph.md, "Outputs").
    fe_pvd = os.path.join(args.outdir, "results.pvd")
    fe_entries = read_pvd(fe_pvd) if os.path.exists(fe_pvd) else None
    if fe_entries is None:
        hint = exodus_hint(args.outdir)
        print(f"note: {args.outdir}: no results.pvd, drawing the particles without the mesh"
              + (f" ({hint})" if hint else ""), file=sys.stderr)
    plt = use_agg()
    fig, axs = plt.subplots(1, len(args.steps), figsize=(4.2 * len(args.steps) + 1.2, 4.6),
                            squeeze=False)
    summary = read_summary(args.outdir) or {}
    parts = []
    for s in args.steps:
        e = select_entry(entries, step=s)
        # The FE output of the same time (the two series share their step numbers).
        fe = read_grid(select_entry(fe_entries, time=e.time).path) if fe_entries else None
        parts.append((e, read_grid(e.path), fe))
    slab = args.slab
    if slab is None:
        g0 = parts[0][1]
        if "smoothing_length" not in g0.point_data or not g0.n_points:
            raise ResultsError(f"{g0.sources[0]}: no smoothing_length to size the slab; give --slab")
        slab = float(np.max(g0.point_data["smoothing_length"]))
    all_vals = []
    for _, g, _ in parts:
        v, label = field_values(g, args.field, g.sources[0])
        all_vals.append(v)
    categorical = args.field in ("sph_rank", "particle_set")
    lo = min(float(np.min(v)) for v in all_vals) if args.clim is None else args.clim[0]
    hi = max(float(np.max(v)) for v in all_vals) if args.clim is None else args.clim[1]
    cmap = plt.get_cmap("tab10" if categorical else "viridis")
    lim_lo = np.min([np.min(g.points[:, plane], axis=0) for _, g, _ in parts], axis=0)
    lim_hi = np.max([np.max(g.points[:, plane], axis=0) for _, g, _ in parts], axis=0)
    for (entry, g, fe), v, ax in zip(parts, all_vals, axs[0]):
        # The mesh in the section.
        if fe is not None and fe.cell_types.size:
            conn, _ = fe.hex_connectivity()  # (wedges, pyramids, tetrahedra as hexahedra)
            cent = fe.points[conn].mean(axis=1)
            keep = np.abs(cent[:, axis] - cut) <= 0.5 * np.ptp(fe.points[conn][:, :, axis], axis=1).max(initial=0) + 1e-12
            from matplotlib.collections import PolyCollection

            polys = fe.points[conn[keep]][:, SECTION_FACE[axis]][:, :, plane] * 1e3
            ax.add_collection(PolyCollection(polys, facecolors="0.85", edgecolors="0.45", linewidths=0.3))
            if len(polys):
                lim_lo = np.minimum(lim_lo, polys.reshape(-1, 2).min(axis=0) / 1e3)
                lim_hi = np.maximum(lim_hi, polys.reshape(-1, 2).max(axis=0) / 1e3)
        sel = np.abs(g.points[:, axis] - cut) <= slab
        p = g.points[sel][:, plane] * 1e3
        if categorical:
            sc = ax.scatter(p[:, 0], p[:, 1], c=v[sel] % 10, cmap=cmap, vmin=0, vmax=9, s=4, lw=0)
        else:
            sc = ax.scatter(p[:, 0], p[:, 1], c=v[sel], cmap=cmap, vmin=lo, vmax=hi, s=4, lw=0)
        ax.set_aspect("equal")
        ax.set_title(f"t = {entry.time * 1e6:.1f} µs")
        ax.set_xlabel(f"{'xyz'[plane[0]]} (mm)")
        ax.set_ylabel(f"{'xyz'[plane[1]]} (mm)")
    pad = 0.03 * (lim_hi - lim_lo)
    for ax in axs[0]:
        ax.set_xlim((lim_lo[0] - pad[0]) * 1e3, (lim_hi[0] + pad[0]) * 1e3)
        ax.set_ylim((lim_lo[1] - pad[1]) * 1e3, (lim_hi[1] + pad[1]) * 1e3)
    if categorical:
        ranks = sorted({int(x) for v in all_vals for x in np.unique(v)})
        handles = [plt.Line2D([], [], ls="", marker="o", color=cmap(r % 10), label=f"{r}") for r in ranks]
        fig.legend(handles=handles, title=label, loc="center right")
    else:
        fig.colorbar(sc, ax=list(axs[0]), label=label, shrink=0.8)
    fig.suptitle(f"{title_of(summary, args.outdir)}: section {cut_text}, particles within ±{slab * 1e3:.2g} mm")
    save_figure(fig, args.output, tight=True)
    print(args.output)
    return 0


if __name__ == "__main__":
    run_main(main, "plot_particles.py")
