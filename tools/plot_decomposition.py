#!/usr/bin/python3
"""Draw the exterior surface of an anvil hexahedral mesh in 3-D, coloured by a field.

The default colours the FE decomposition (cell field fe_rank) on the deformed shape of
the last field output.  Exterior faces are those used by exactly one hexahedron, found
by their sorted global node ids (point field node_id) so that faces shared by cells on
two ranks count as interior.  Faces pointing away from the viewer are culled (the view
is orthographic), the rest are shaded by a fixed headlight and drawn with matplotlib's
Poly3DCollection.

Fields: any cell field (fe_rank, contact_rank, part, plastic_strain, von_mises, ...),
a component of a cell field (stress.xx, stress.yz), or a point field averaged over the
face's nodes (displacement: magnitude, displacement.z: component).  Integer fields with
at most 20 distinct values are drawn with a qualitative colormap and a legend; other
fields with a colorbar.
"""

import argparse
import os
import sys
from dataclasses import dataclass

import numpy as np

from anvil_results import (
    ResultsError,
    length_unit,
    read_summary,
    run_main,
    save_figure,
    time_unit,
    title_of,
    use_agg,
)
from anvil_vtu import DEFAULT_TIME_TOLERANCE, load_output

# The six faces of a VTK hexahedron in local node order, outward for a positive cell.
HEX_FACES = np.array(
    [[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7], [0, 3, 2, 1], [4, 5, 6, 7]]
)

COMPONENTS = {  # component suffix -> index, for 3-vectors and 6-component symmetric tensors
    3: {"x": 0, "y": 1, "z": 2},
    6: {"xx": 0, "yy": 1, "zz": 2, "xy": 3, "yz": 4, "xz": 5},
}

# Display of known fields: label, unit, factor from SI.
FIELD_INFO = {
    "fe_rank": ("FE rank", "", 1.0),
    "contact_rank": ("contact rank", "", 1.0),
    "sph_rank": ("SPH rank", "", 1.0),
    "part": ("part", "", 1.0),
    "element_id": ("element id", "", 1.0),
    "plastic_strain": ("equivalent plastic strain", "–", 1.0),
    "von_mises": ("von Mises stress", "MPa", 1e-6),
    "pressure": ("pressure", "MPa", 1e-6),
    "stress": ("stress", "MPa", 1e-6),
    "temperature": ("temperature", "K", 1.0),
    "displacement": ("displacement", "mm", 1e3),
    "velocity": ("velocity", "m/s", 1.0),
}

MAX_CATEGORIES = 20


def parse_args(argv=None):
    """Command line -> argparse.Namespace."""
    p = argparse.ArgumentParser(
        description="3-D picture of an anvil mesh's exterior faces coloured by a field "
        "(default: the FE decomposition, fe_rank).",
        epilog="examples:\n"
        "  plot_decomposition.py out/taylor_bar -o fe_ranks.png\n"
        "  plot_decomposition.py out/taylor_bar --step 0 --undeformed -o t0.png\n"
        "  plot_decomposition.py out/taylor_bar --field plastic_strain -o eps.png",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("outdir", help="anvil output directory (results.pvd), or a .pvd/.pvtu/.vtu")
    when = p.add_mutually_exclusive_group()
    when.add_argument("--step", type=int, help="field output index in results.pvd "
                      "(0 = first, -1 = last; default last)")
    when.add_argument("--time", type=float, help="field output nearest to this time [s]; "
                      "an error when none is within --time-tolerance")
    p.add_argument("--time-tolerance", type=float, default=DEFAULT_TIME_TOLERANCE,
                   metavar="S", help="largest accepted distance between --time and the "
                   f"output drawn [s] (default {DEFAULT_TIME_TOLERANCE:g}, as plot_figure3.py)")
    p.add_argument("--field", default="fe_rank",
                   help="colouring field: NAME or NAME.COMPONENT (default fe_rank)")
    p.add_argument("--undeformed", action="store_true",
                   help="draw the undeformed shape (points minus displacement)")
    p.add_argument("--cut", metavar="AXIS=VALUE",
                   help="cutaway: keep only cells whose centroid has AXIS <= VALUE [m] "
                   "(e.g. y=0 shows the interior on the plane y = 0)")
    p.add_argument("--show-eroded", action="store_true",
                   help="draw eroded elements too (cell field eroded = 1; hidden by default, "
                   "so the faces erosion exposed show)")
    p.add_argument("--elev", type=float, default=20.0, help="view elevation [deg] (default 20)")
    p.add_argument("--azim", type=float, default=-60.0, help="view azimuth [deg] (default -60)")
    p.add_argument("--clim", type=float, nargs=2, metavar=("MIN", "MAX"),
                   help="colour range of a continuous field, in displayed units")
    p.add_argument("--cmap", help="matplotlib colormap (default tab10/tab20 or viridis)")
    p.add_argument("--no-edges", action="store_true", help="do not draw element edges")
    p.add_argument("--size", type=float, nargs=2, metavar=("W", "H"), default=(6.4, 6.4),
                   help="figure size in inches (default 6.4 6.4)")
    p.add_argument("--dpi", type=int, default=110, help="PNG resolution (default 110)")
    p.add_argument("--title", help="plot title (default: deck title from summary.json)")
    p.add_argument("-o", "--output", help="PNG to write (default OUTDIR/FIELD.png)")
    args = p.parse_args(argv)
    if args.clim and not args.clim[0] < args.clim[1]:
        p.error("--clim needs MIN < MAX")
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


# --------------------------------------------------------------------------- geometry


def node_keys(grid):
    """Global node id per point (node_id), or point indices when there is no node_id."""
    if "node_id" in grid.point_data:
        return np.asarray(grid.point_data["node_id"], dtype=np.int64)
    if len(set(grid.piece_of_cell.tolist())) > 1:
        print("warning: no node_id point field; faces between pieces will be drawn",
              file=sys.stderr)
    return np.arange(grid.n_points, dtype=np.int64)


def exterior_faces(conn, keys):
    """Faces used by exactly one hexahedron.

    conn: (n_hex, 8) point indices; keys: (n_points,) global node id per point.
    Returns (faces, owner): faces (m, 4) point indices in outward order, owner (m,) the
    row of `conn` each face belongs to.
    """
    faces = conn[:, HEX_FACES].reshape(-1, 4)
    ids = np.sort(keys[faces], axis=1)
    order = np.lexsort(ids.T[::-1])
    s = ids[order]
    new = np.ones(len(s), dtype=bool)
    new[1:] = np.any(s[1:] != s[:-1], axis=1)
    starts = np.flatnonzero(new)
    counts = np.diff(np.append(starts, len(s)))
    single = order[starts[counts == 1]]
    single.sort()
    return faces[single], single // 6


def face_normals(quads):
    """Unit normals of (m, 4, 3) quadrilaterals from the cross product of the diagonals."""
    n = np.cross(quads[:, 2] - quads[:, 0], quads[:, 3] - quads[:, 1])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.maximum(length, 1e-300)


def view_vector(elev, azim):
    """Unit vector from the scene towards the viewer for matplotlib's elev/azim [deg]."""
    e, a = np.radians(elev), np.radians(azim)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


# --------------------------------------------------------------------------- fields


def split_field(spec):
    """'stress.xx' -> ('stress', 'xx'); 'fe_rank' -> ('fe_rank', None)."""
    name, _, comp = spec.partition(".")
    return name, comp or None


def select_component(values, name, comp, where):
    """Reduce an (n,) or (n, k) array to (n,) by component name (magnitude by default)."""
    if values.ndim == 1:
        if comp:
            raise ResultsError(f"{where}: field {name!r} is a scalar, it has no component {comp!r}")
        return values
    k = values.shape[1]
    if comp is None:
        if k == 3:
            return np.linalg.norm(values, axis=1)
        raise ResultsError(
            f"{where}: field {name!r} has {k} components; choose one of "
            f"{', '.join(name + '.' + c for c in COMPONENTS.get(k, {}))}"
        )
    index = COMPONENTS.get(k, {}).get(comp)
    if index is None and comp.isdigit() and int(comp) < k:
        index = int(comp)
    if index is None:
        raise ResultsError(f"{where}: field {name!r} has no component {comp!r}")
    return values[:, index]


def face_values(grid, spec, hex_cells, faces, owner, where):
    """Value of field `spec` on each exterior face: the owning cell's value for a cell
    field, the mean over the face's 4 points for a point field.  Returns (values, is_int).
    `where` names the input in error messages."""
    name, comp = split_field(spec)
    if name in grid.cell_data:
        raw = grid.cell_data[name]
        vals = select_component(raw, name, comp, where)[hex_cells[owner]]
    elif name in grid.point_data:
        raw = grid.point_data[name]
        vals = select_component(raw, name, comp, where)[faces].mean(axis=1)
    else:
        have = sorted(set(grid.cell_data) | set(grid.point_data))
        raise ResultsError(f"{where}: no field {name!r}; available: {', '.join(have)}")
    is_int = np.issubdtype(raw.dtype, np.integer) and name != "node_id"
    return vals, is_int


def field_label(spec):
    """(axis label with unit, factor from SI) for field `spec`."""
    name, comp = split_field(spec)
    label, unit, factor = FIELD_INFO.get(name, (name, "", 1.0))
    if comp:
        label = f"{label} {comp}"
    elif name in ("displacement", "velocity"):
        label = f"{label} magnitude"
    return (f"{label} [{unit}]" if unit else label), factor


# --------------------------------------------------------------------------- drawing


def face_colors(vals, is_int, args):
    """RGBA per face and a legend description: ('categories', {value: rgba}) or
    ('colorbar', (ScalarMappable, extend)) with extend telling which end --clim clips."""
    import matplotlib
    from matplotlib import cm, colors

    cats = np.unique(vals) if is_int else None
    if cats is not None and len(cats) <= MAX_CATEGORIES:
        cmap = matplotlib.colormaps[args.cmap or ("tab10" if len(cats) <= 10 else "tab20")]
        palette = {int(v): cmap(i % cmap.N) for i, v in enumerate(cats)}
        rgba = np.array([palette[int(v)] for v in vals]) if len(vals) else np.zeros((0, 4))
        return rgba, ("categories", palette)
    _, factor = field_label(args.field)
    shown = vals * factor
    lo, hi = args.clim if args.clim else (np.nanmin(shown), np.nanmax(shown))
    if lo == hi:
        lo, hi = lo - 0.5, hi + 0.5
    norm = colors.Normalize(lo, hi)
    mappable = cm.ScalarMappable(norm=norm, cmap=args.cmap or "viridis")
    mappable.set_array([])
    below, above = np.nanmin(shown) < lo, np.nanmax(shown) > hi
    extend = {(True, True): "both", (True, False): "min", (False, True): "max"}.get(
        (below, above), "neither")
    return mappable.to_rgba(shown), ("colorbar", (mappable, extend))


def light_vector(elev, azim):
    """Unit vector towards a light above and to the left of the viewer."""
    return view_vector(min(elev + 35.0, 89.0), azim - 40.0)


def shade(rgba, normals, light, strength):
    """Darken colours by the angle between face normal and the light direction;
    strength in [0, 1] is the darkening of a face turned away from the light."""
    lit = 1.0 - strength + strength * np.clip(normals @ light, 0.0, 1.0)
    out = rgba.copy()
    out[:, :3] *= lit[:, None]
    return out


def category_counts(grid, spec, hex_cells):
    """{value: number of hexahedra} of an integer cell field (empty for point fields)."""
    name, _ = split_field(spec)
    if name not in grid.cell_data or grid.cell_data[name].ndim != 1:
        return {}
    v, c = np.unique(grid.cell_data[name][hex_cells], return_counts=True)
    return dict(zip(v.tolist(), c.tolist()))


def padded_limits(pts, min_ratio=0.45):
    """Axis limits (lo, hi) around points: every span at least min_ratio of the largest,
    widened about its centre, so that the scale stays equal on all axes while a slender
    body still leaves room for tick labels."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = hi - lo
    biggest = max(span.max(), 1e-12 * max(1.0, np.abs(hi).max()))
    want = np.maximum(span, min_ratio * biggest)
    mid = 0.5 * (lo + hi)
    return mid - 0.5 * want, mid + 0.5 * want


def style_3d_axes(ax, lo, hi, lu, elev, azim, zoom=1.1, label_size=9, tick_size=8):
    """Limits lo..hi (3,) in length unit `lu`, equal scale on all axes, orthographic view
    from elev/azim [deg], transparent panes, light grid and labelled axes."""
    from matplotlib.ticker import MaxNLocator

    ax.set_proj_type("ortho")
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect((hi - lo) / (hi - lo).max(), zoom=zoom)
    ax.view_init(elev=elev, azim=azim)
    for axis, name in ((ax.xaxis, "x"), (ax.yaxis, "y"), (ax.zaxis, "z")):
        axis.pane.set_alpha(0.0)
        axis._axinfo["grid"].update(color=(0.5, 0.5, 0.5, 0.25), linewidth=0.5)
        axis.set_label_text(f"{name} [{lu}]")
        axis.label.set_size(label_size)
        axis.set_major_locator(MaxNLocator(5))
    ax.tick_params(labelsize=tick_size, pad=1)


def add_faces(ax, quads, rgba, edges=True, linewidth=0.15, edgecolors=None):
    """Add (m, 4, 3) quadrilaterals with RGBA colours to a 3-D axes.  Edges are thin and
    dark by default; `edgecolors` (one or one per face) overrides their colour."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if edgecolors is None:
        edgecolors = (0.1, 0.1, 0.1, 0.35) if edges else "none"
    coll = Poly3DCollection(quads, facecolors=rgba, edgecolors=edgecolors, linewidths=linewidth)
    ax.add_collection3d(coll)
    return coll


def draw(quads, rgba, legend, counts, args, title, lu):
    """Build the figure from quads (m,4,3) already in length unit `lu`, their RGBA colours,
    the legend description of face_colors and per-category element counts."""
    plt = use_agg()
    from matplotlib.patches import Patch

    fig = plt.figure(figsize=tuple(args.size))
    ax = fig.add_subplot(projection="3d", computed_zorder=False)
    add_faces(ax, quads, rgba, edges=not args.no_edges)
    lo, hi = padded_limits(quads.reshape(-1, 3) if len(quads) else np.zeros((1, 3)))
    style_3d_axes(ax, lo, hi, lu, args.elev, args.azim)
    fig.subplots_adjust(top=0.9 if args.elev >= 0 else 0.82)  # tick labels on top from below
    fig.suptitle(title, fontsize=11, y=0.96)

    kind, info = legend
    if kind == "categories":
        name = field_label(args.field)[0]
        handles = [
            Patch(facecolor=c, edgecolor="0.3",
                  label=f"{v}" + (f" ({counts[v]:,} el.)" if v in counts else ""))
            for v, c in info.items()
        ]
        ax.legend(handles=handles, title=name, loc="upper left", bbox_to_anchor=(0.0, 1.0),
                  fontsize=8, title_fontsize=9, framealpha=0.9)
    else:
        mappable, extend = info
        cb = fig.colorbar(mappable, ax=ax, shrink=0.6, pad=0.06, extend=extend)
        cb.set_label(field_label(args.field)[0], fontsize=9)
        cb.ax.tick_params(labelsize=8)
    return fig


def build_title(args, summary, entry):
    """Two-line title: deck title, then field, time and shape."""
    head = args.title or title_of(summary, "anvil mesh")
    name = field_label(args.field)[0].split(" [")[0]
    if split_field(args.field)[0] == "fe_rank":
        name = "FE decomposition"
        ranks = (summary or {}).get("ranks")
        if ranks:
            name += f" on {ranks} ranks"
    when = ""
    if np.isfinite(entry.time):
        tf, tu = time_unit(entry.time) if entry.time > 0 else (1e6, "µs")
        when = f", t = {entry.time * tf:.3g} {tu}"
    shape = "undeformed" if args.undeformed else "deformed"
    if args.elev < 0:
        shape += ", seen from below"
    if args.cut is not None:
        shape += f", cut at {'xyz'[args.cut[0]]} = {args.cut[1]:g} m"
    return f"{head}\n{name}{when} ({shape})"


@dataclass
class Surface:
    """The exterior faces of a field output, ready to draw.

    quads (m, 4, 3) corner coordinates [m] in outward order; normals (m, 3) unit outward;
    values (m,) the field on each face (SI units); is_int: an integer field; counts
    {value: number of hexahedra} for an integer cell field ({} otherwise); points: all
    point coordinates used [m] (deformed or undeformed as asked)."""

    quads: np.ndarray
    normals: np.ndarray
    values: np.ndarray
    is_int: bool
    counts: dict
    points: np.ndarray


def exterior_surface(grid, field, undeformed=False, cut=None, where="input",
                     show_eroded=False):
    """Exterior faces of `grid`'s hexahedra coloured by `field` (see face_values).

    undeformed: subtract the displacement point field; cut: (axis index, value) keeps only
    cells whose centroid has coordinate <= value; eroded cells (cell field eroded) are left
    out unless show_eroded.  `where` names the input in errors."""
    conn, hex_cells = grid.hex_connectivity()
    if len(conn) == 0:
        raise ResultsError(f"{where}: no hexahedral cells to draw")
    if not show_eroded and "eroded" in grid.cell_data:
        live = np.asarray(grid.cell_data["eroded"]).reshape(-1)[hex_cells] == 0
        if not live.any():
            raise ResultsError(f"{where}: every element has eroded (--show-eroded draws them)")
        conn, hex_cells = conn[live], hex_cells[live]
    points = grid.points
    if undeformed:
        if "displacement" not in grid.point_data:
            raise ResultsError(f"{where}: no displacement field for --undeformed")
        points = points - grid.point_data["displacement"]
    if cut is not None:
        keep = points[conn].mean(axis=1)[:, cut[0]] <= cut[1]
        if not keep.any():
            raise ResultsError(f"{where}: --cut removes every cell")
        conn, hex_cells = conn[keep], hex_cells[keep]
    faces, owner = exterior_faces(conn, node_keys(grid))
    vals, is_int = face_values(grid, field, hex_cells, faces, owner, where)
    quads = points[faces]
    counts = category_counts(grid, field, hex_cells) if is_int else {}
    return Surface(quads, face_normals(quads), vals, is_int, counts, points)


def front_faces(surface, elev, azim):
    """Boolean mask of the faces turned towards a viewer at elev/azim (orthographic)."""
    return surface.normals @ view_vector(elev, azim) > -1e-9


def main(argv=None):
    """Entry point: read one field output, draw, write the PNG and print its path."""
    args = parse_args(argv)
    entry, grid = load_output(args.outdir, step=args.step, time=args.time,
                              tolerance=args.time_tolerance)
    surf = exterior_surface(grid, args.field, args.undeformed, args.cut, entry.path,
                            args.show_eroded)
    front = front_faces(surf, args.elev, args.azim)  # orthographic view: back faces hidden
    rgba, legend = face_colors(surf.values, surf.is_int, args)

    extent = (surf.points.max(axis=0) - surf.points.min(axis=0)).max()
    lf, lu = length_unit(extent)
    summary = read_summary(args.outdir) if os.path.isdir(args.outdir) else None
    title = build_title(args, summary, entry)
    counts = surf.counts if legend[0] == "categories" else {}
    fig = draw(surf.quads[front] * lf,
               shade(rgba[front], surf.normals[front], light_vector(args.elev, args.azim),
                     0.6 if legend[0] == "categories" else 0.3), legend, counts,
               args, title, lu)
    out = args.output or os.path.join(
        args.outdir if os.path.isdir(args.outdir) else ".", f"{args.field}.png")
    save_figure(fig, out, dpi=args.dpi, tight=True)
    print(out)
    return 0


if __name__ == "__main__":
    run_main(main, "plot_decomposition.py")
