#!/usr/bin/python3
"""Plot the energy history of an anvil run from OUTDIR/history.csv.

Top panel: kinetic, internal, hourglass, contact energy, external work and the total
(kinetic + internal + hourglass + contact).  Bottom panel: the energy balance error
|total - E0 - external_work| / max(|total|, |external_work|, |E0|), anvil's definition
of summary.json's energy.balance_error.  E0 is summary.json's energy.initial (the kinetic
energy of the initial velocities, before constraints) when the run wrote it; otherwise
the first history row's total less its external work (a fixed or prescribed node's
initial velocity is removed at t = 0 and booked as external work, so the first row's
total alone would offset the whole curve).  history.csv's t=0 row averages v(-1/2) and
v(+1/2), so its total differs slightly from E0; the final value from summary.json is
printed next to the curve.
"""

import argparse
import os

import numpy as np

from anvil_results import (
    ResultsError,
    read_history,
    read_summary,
    run_description,
    run_main,
    save_figure,
    time_axis,
    title_of,
    use_agg,
)

ENERGY_CURVES = [  # column, label, style
    ("kinetic", "kinetic", dict(color="tab:blue")),
    ("internal", "internal", dict(color="tab:orange")),
    ("hourglass", "hourglass", dict(color="tab:green")),
    ("contact", "contact", dict(color="tab:red")),
    ("external_work", "external work", dict(color="tab:purple", linestyle="--")),
    ("total", "total", dict(color="black", linewidth=2.0)),
]


def parse_args(argv=None):
    """Command line -> argparse.Namespace (outdir, output)."""
    p = argparse.ArgumentParser(
        description="Energy history plot (and balance error) of an anvil run.",
        epilog="example: plot_history.py out/taylor_bar -o out/taylor_bar/energy.png",
    )
    p.add_argument("outdir", help="anvil output directory holding history.csv (or the .csv)")
    p.add_argument("-o", "--output", help="PNG to write (default OUTDIR/energy.png)")
    p.add_argument("--title", help="plot title (default: the deck title in summary.json)")
    return p.parse_args(argv)


def initial_energy(h, summary):
    """E0 of the balance: summary.json's energy.initial, else the first row's E - W."""
    e0 = (summary or {}).get("energy", {}).get("initial")
    if isinstance(e0, (int, float)) and np.isfinite(e0):
        return float(e0)
    return float(h["total"][0] - h["external_work"][0])


def balance_error(h, e0):
    """Relative energy balance error per history row, as anvil defines it."""
    total, work = h["total"], h["external_work"]
    scale = np.maximum.reduce([np.abs(total), np.abs(work), np.full_like(total, abs(e0))])
    scale = np.maximum(scale, 1e-300)
    return np.abs(total - e0 - work) / scale


def energy_unit(e_max):
    """(factor, label) for energies of size `e_max` joules."""
    e_max = abs(e_max)
    if e_max >= 1e6:
        return 1e-6, "MJ"
    if e_max >= 1e3:
        return 1e-3, "kJ"
    if 0 < e_max < 1e-3:
        return 1e3, "mJ"
    return 1.0, "J"


def plot(h, summary, title):
    """Draw the two panels for History `h`; return the matplotlib Figure."""
    plt = use_agg()
    missing = [c for c, _, _ in ENERGY_CURVES if c not in h.data]
    if missing:
        raise ResultsError(f"{h.path}: missing energy columns {missing}")
    t, tu, xlim = time_axis(h)
    marker = dict(marker="o") if len(h) == 1 else {}  # a single point draws no line
    e_max = max(np.abs(h[c]).max() for c, _, _ in ENERGY_CURVES)
    ef, eu = energy_unit(e_max)

    fig, (ax, axb) = plt.subplots(
        2, 1, sharex=True, figsize=(7.5, 6.0), gridspec_kw=dict(height_ratios=[3, 1.3])
    )
    for col, label, style in ENERGY_CURVES:
        ax.plot(t, h[col] * ef, label=label, **style, **marker)
    ax.set_ylabel(f"energy [{eu}]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=9, ncol=2, framealpha=0.9)
    sub = run_description(summary)
    ax.set_title(title + (f"\n{sub}" if sub else ""), fontsize=11)

    err = balance_error(h, initial_energy(h, summary)) * 100
    axb.plot(t, err, color="tab:red", **marker)
    axb.set_ylabel("balance error [%]")
    axb.set_xlabel(f"time [{tu}]")
    axb.grid(True, alpha=0.3)
    axb.set_ylim(bottom=0, top=max(err.max() * 1.6, 1e-3))
    axb.set_xlim(*xlim)  # one history row: a window around the point (time_axis)
    note = f"final {err[-1]:.3g} %, max {err.max():.3g} % (history rows)"
    reported = (summary or {}).get("energy", {}).get("balance_error")
    if isinstance(reported, (int, float)):
        note += f"\nsummary.json: {reported * 100:.3g} % (last cycle)"
    axb.text(0.99, 0.94, note, transform=axb.transAxes, ha="right", va="top", fontsize=8.5)
    fig.align_ylabels([ax, axb])
    fig.tight_layout()
    return fig


def main(argv=None):
    """Entry point: read OUTDIR, write the PNG, print its path."""
    args = parse_args(argv)
    h = read_history(args.outdir)
    base = args.outdir if os.path.isdir(args.outdir) else os.path.dirname(args.outdir)
    summary = read_summary(base or ".")
    title = args.title or title_of(summary, "anvil energy history")
    out = args.output or os.path.join(base or ".", "energy.png")
    fig = plot(h, summary, title)
    save_figure(fig, out)
    print(out)
    return 0


if __name__ == "__main__":
    run_main(main, "plot_history.py")
