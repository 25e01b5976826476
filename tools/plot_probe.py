#!/usr/bin/python3
"""Plot time histories of probe columns (PROBE.FIELD) of OUTDIR/history.csv.

Columns may be given exactly (tip.uz) or as shell patterns (tip.u?, '*.vz').  Columns
of the same kind share a panel: displacements (ux, uy, uz) in mm, velocities (vx, vy,
vz) in m/s, forces (wall0.force, and the reactions bc0.fx ... bc0.fz) in kN; any other
column gets its own panel.
"""

import argparse
import fnmatch
import os

from anvil_results import (
    ResultsError,
    read_history,
    read_summary,
    run_main,
    save_figure,
    time_axis,
    title_of,
    use_agg,
)

KINDS = [  # (field names, panel label, factor from SI)
    (("ux", "uy", "uz"), "displacement [mm]", 1e3),
    (("vx", "vy", "vz"), "velocity [m/s]", 1.0),
    (("force", "fx", "fy", "fz"), "force [kN]", 1e-3),
]


def parse_args(argv=None):
    """Command line -> argparse.Namespace (outdir, columns, output, title)."""
    p = argparse.ArgumentParser(
        description="Time history of probe columns of an anvil run's history.csv.",
        epilog="example: plot_probe.py out/taylor_bar tip.uz rim.ux -o probes.png",
    )
    p.add_argument("outdir", help="anvil output directory holding history.csv (or the .csv)")
    p.add_argument("columns", nargs="+", metavar="PROBE.FIELD",
                   help="history column(s), e.g. tip.uz; shell patterns like 'tip.v*' allowed")
    p.add_argument("-o", "--output", help="PNG to write (default OUTDIR/probes.png)")
    p.add_argument("--title", help="plot title (default: the deck title in summary.json)")
    p.add_argument("--x", metavar="COLUMN",
                   help="plot against this column instead of time (a force against a "
                        "displacement: bc1.fz --x block.uz)")
    p.add_argument("--negate", action="store_true",
                   help="plot the columns' negatives (a driver's reaction as a crush force)")
    p.add_argument("--negate-x", action="store_true", help="negate the --x column")
    return p.parse_args(argv)


def resolve_columns(h, patterns):
    """Expand names/patterns against the History's probe columns, keeping file order and
    dropping duplicates; raise ResultsError naming what did not match."""
    available = h.probe_columns()
    chosen = []
    for pat in patterns:
        hits = [c for c in available if fnmatch.fnmatchcase(c, pat)]
        if not hits:
            raise ResultsError(
                f"{h.path}: no column matches {pat!r}; probe columns: "
                f"{', '.join(available) if available else '(none)'}"
            )
        chosen += [c for c in hits if c not in chosen]
    return chosen


def group_columns(columns):
    """[(panel label, factor, [columns])] grouping columns by kind, in first-seen order."""
    groups = {}
    for col in columns:
        field = col.rsplit(".", 1)[-1]
        for names, label, factor in KINDS:
            if field in names:
                key = (label, factor)
                break
        else:
            key = (col, 1.0)
        groups.setdefault(key, []).append(col)
    return [(label, factor, cols) for (label, factor), cols in groups.items()]


def plot(h, columns, title, x=None, negate=False, negate_x=False):
    """One panel per kind of column, sharing the time axis or the column `x`; returns the
    Figure."""
    plt = use_agg()
    groups = group_columns(columns)
    if x is None:
        t, tu, xlim = time_axis(h)
        xlabel = f"time [{tu}]"
    else:
        (xunit, xfactor, _), = group_columns([x])
        t = h[x] * xfactor * (-1.0 if negate_x else 1.0)
        xlabel = f"{'-' if negate_x else ''}{x}" + (f" ({xunit})" if xunit != x else "")
        xlim = None
    sign = -1.0 if negate else 1.0
    marker = dict(marker="o") if len(h) == 1 else {}  # a single point draws no line
    fig, axes = plt.subplots(len(groups), 1, sharex=True, squeeze=False,
                             figsize=(7.5, 2.0 + 2.3 * len(groups)))
    for ax, (label, factor, cols) in zip(axes[:, 0], groups):
        for col in cols:
            ax.plot(t, h[col] * factor * sign, label=("-" if negate else "") + col, **marker)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=9)
    axes[-1, 0].set_xlabel(xlabel)
    if xlim is not None:
        axes[-1, 0].set_xlim(*xlim)  # one history row: a window around the point (time_axis)
    axes[0, 0].set_title(title, fontsize=11)
    fig.align_ylabels(axes[:, 0])
    fig.tight_layout()
    return fig


def main(argv=None):
    """Entry point: read history.csv, plot the chosen columns, print the PNG path."""
    args = parse_args(argv)
    h = read_history(args.outdir)
    columns = resolve_columns(h, args.columns)
    x = resolve_columns(h, [args.x])[0] if args.x else None
    base = args.outdir if os.path.isdir(args.outdir) else (os.path.dirname(args.outdir) or ".")
    summary = read_summary(base)
    title = args.title or title_of(summary, "anvil probe history")
    fig = plot(h, columns, title, x, args.negate, args.negate_x)
    out = args.output or os.path.join(base, "probes.png")
    save_figure(fig, out)
    print(out)
    return 0


if __name__ == "__main__":
    run_main(main, "plot_probe.py")
