#!/usr/bin/python3
"""The paper's Figure 2 from a scaled can crush series (tools/scaling_series.sh).

Reads OUTROOT/P<n>/summary.json for every rank count and OUTROOT/machine.json, and draws

* the scaling figure (-o): grind time, wall seconds per cycle per element in microseconds
  (summary.json's grind_us), against the rank count P on a log2 axis, with the ideal
  grind(1)/P; and the scaled efficiency E(P) = grind(1) / (P grind(P)), ideal 1;
* the phase figure (--phases-output): per rank count, the wall time per cycle split into
  fe, halo, contact_search, contact_force, transfer, rebalance and other (the rest of the
  wall time: predict, update, output and untimed work), as stacked bars in milliseconds
  per cycle and as shares of the wall time.  The phase timers are maxima over ranks.

Runs with more ranks than the machine's cores (nproc in machine.json, or --nproc) are
drawn hollow/hatched and labelled oversubscribed: their ranks time-share the cores, so
their timings are not scaling data.  When the run directories hold scaling_series.sh's
time.txt, the grind panel also shows the CPU time (user + system of all ranks, setup
included) per element per cycle: constant for ideal weak scaling, on any number of cores.
--table prints the numbers as a Markdown table ("CPU µs" is that CPU grind).

    tools/scaling_series.sh --max-ranks 8 --cycles 1000 out/scaling
    /usr/bin/python3 tools/plot_figure2.py out/scaling -o docs/figures/figure2_scaling.png \\
        --phases-output docs/figures/figure2_phases.png --table
"""

import argparse
import os

import numpy as np

from anvil_results import (
    SERIES_PHASES,
    phase_seconds,
    read_series,
    run_main,
    save_figure,
    scaled_efficiency,
    use_agg,
)

PHASE_STYLE = {  # phase -> (label, colour)
    "fe": ("FE (element forces)", "#4C72B0"),
    "halo": ("halo exchange", "#8FB0D9"),
    "contact_search": ("contact search", "#DD8452"),
    "contact_force": ("contact forces", "#C44E52"),
    "transfer": ("FE <-> contact transfer", "#937860"),
    "rebalance": ("contact RCB rebalance", "#8172B3"),
    "other": ("other (predict, update, output, ...)", "#B5B5B5"),
}
OVER_COLOUR = "#999999"


def parse_args(argv=None):
    """Command line -> argparse.Namespace."""
    p = argparse.ArgumentParser(
        description="Figure 2 of Attaway et al. 1997 (grind time and scaled efficiency of the "
        "scaled can crush) and a per-phase breakdown, from scaling_series.sh output.",
        epilog="example:\n  plot_figure2.py out/scaling -o fig2.png --phases-output phases.png",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("outroot", nargs="+",
                   help="scaling_series.sh output root(s) holding P<n>/summary.json")
    p.add_argument("-o", "--output",
                   help="scaling PNG (default OUTROOT/figure2_scaling.png)")
    p.add_argument("--phases-output",
                   help="phase breakdown PNG (default: next to -o, *_phases.png)")
    p.add_argument("--nproc", type=int,
                   help="cores of the machine (default: nproc in OUTROOT/machine.json)")
    p.add_argument("--table", action="store_true", help="print a Markdown table of the numbers")
    p.add_argument("--title", help="title line (default: from the runs)")
    p.add_argument("--dpi", type=int, default=120, help="PNG resolution (default 120)")
    args = p.parse_args(argv)
    if args.nproc is not None and args.nproc < 1:
        p.error("--nproc must be at least 1")
    return args


def phases_path(scaling_png):
    """Default phase-figure path derived from the scaling-figure path."""
    d, base = os.path.split(scaling_png)
    stem, ext = os.path.splitext(base)
    if "scaling" in stem:
        return os.path.join(d, stem.replace("scaling", "phases") + (ext or ".png"))
    return os.path.join(d, stem + "_phases" + (ext or ".png"))


def describe(series):
    """Subtitle: problem size per rank, cycles and machine."""
    runs = series.runs
    per_rank = sorted({round(s["elements"] / s["ranks"]) for s in runs})
    cycles = sorted({int(s["cycles"]) for s in runs})
    m = series.machine
    cyc = f"{cycles[0]:,} cycles" if len(cycles) == 1 else \
        f"{cycles[0]:,}-{cycles[-1]:,} cycles"
    size = f"~{per_rank[0]:,}" if len(per_rank) == 1 else f"{per_rank[0]:,}-{per_rank[-1]:,}"
    machine = ""
    if series.nproc:
        machine = f"; {cores(series.nproc)}"
        if m.get("cpu_model"):
            machine += f" ({m['cpu_model']})"
    decomposition = ""
    if m.get("decomposition", "paper") != "paper":
        decomposition = f", {m['decomposition']} decomposition"
    return f"{size} elements per rank, {cyc}{decomposition}{machine}"


def cores(n):
    """'1 core', '2 cores'."""
    return f"{n} core" + ("" if n == 1 else "s")


def mark_oversubscribed(ax, series, ranks):
    """Shade the P > nproc part of a log2 rank axis and label it."""
    if not series.nproc or max(ranks) <= series.nproc:
        return
    lo = series.nproc * 2 ** 0.5 if series.nproc in ranks else series.nproc
    ax.axvspan(lo, max(ranks) * 1.6, color="0.5", alpha=0.12, lw=0)
    ax.set_xlabel(f"ranks P   (shaded: P > {cores(series.nproc)}, oversubscribed, "
                  "not scaling data)", fontsize=9)


def log2_axis(ax, ranks):
    """x axis: log2 of the rank count with the measured counts as ticks."""
    ax.set_xscale("log", base=2)
    ax.set_xticks(ranks)
    ax.set_xticklabels([str(p) for p in ranks])
    ax.minorticks_off()
    ax.set_xlim(min(ranks) / 1.6, max(ranks) * 1.6)
    ax.set_xlabel("ranks P")
    ax.grid(True, which="major", alpha=0.3)


def plot_scaling(series, args, title):
    """Two panels: grind time and scaled efficiency against P."""
    plt = use_agg()
    runs = series.runs
    ranks = [int(s["ranks"]) for s in runs]
    grind = np.array([float(s["grind_us"]) for s in runs])
    eff = np.array(scaled_efficiency(runs))
    over = np.array([s["_oversubscribed"] for s in runs])
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.6))

    p0 = ranks[0]
    ideal = grind[0] * p0 / np.array(ranks, dtype=float)
    ax1.plot(ranks, ideal, "--", color="0.4", lw=1, label=f"ideal: grind({p0}) {p0}/P")
    for ax, y, fmt in ((ax1, grind, "{:.3g}"), (ax2, eff, "{:.2f}")):
        ax.plot(ranks, y, "-", color="tab:blue", lw=1.2, zorder=2)
        ax.plot(np.array(ranks)[~over], y[~over], "o", color="tab:blue", ms=7, zorder=3,
                label="measured")
        if over.any():
            ax.plot(np.array(ranks)[over], y[over], "o", mfc="white", mec="tab:blue", mew=1.5,
                    ms=7, zorder=3, label="measured, oversubscribed")
        for p, v in zip(ranks, y):
            ax.annotate(fmt.format(v), (p, v), textcoords="offset points", xytext=(6, 6),
                        fontsize=8)
        log2_axis(ax, ranks)
        mark_oversubscribed(ax, series, ranks)
    cpu = np.array([cpu_grind(s) for s in runs])
    if np.isfinite(cpu).any():
        ax1.plot(ranks, cpu, "^--", color="tab:gray", ms=5, lw=1, zorder=2,
                 label="CPU time of all ranks per element per cycle\n(user + sys, incl. setup)")
    ax1.set_yscale("log")
    from matplotlib.ticker import LogLocator, ScalarFormatter

    ax1.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax1.yaxis.set_major_formatter(ScalarFormatter())
    ax1.yaxis.set_minor_formatter(plt.NullFormatter())
    ax1.set_ylabel("grind time [µs / element / cycle]")
    ax1.set_title("grind time (wall s per cycle per element)", fontsize=10)
    ax1.legend(fontsize=8, loc="lower left")
    ax2.axhline(1.0, ls="--", color="0.4", lw=1, label="ideal")
    ax2.set_ylim(0, max(1.15, float(np.nanmax(eff)) * 1.1))
    base = f"grind({p0})" if p0 == 1 else f"{p0} grind({p0})"
    ax2.set_ylabel(f"scaled efficiency  {base} / (P grind(P))")
    ax2.set_title("scaled efficiency", fontsize=10)
    ax2.legend(fontsize=8, loc="center right")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def plot_phases(series, args, title):
    """Two panels: stacked phase times per cycle [ms], and their shares of the wall time."""
    plt = use_agg()
    runs = series.runs
    labels = [f"{s['ranks']}" + ("*" if s["_oversubscribed"] else "") for s in runs]
    x = np.arange(len(runs))
    names = SERIES_PHASES + ["other"]
    ms = {n: np.array([phase_seconds(s)[n] / max(int(s["cycles"]), 1) * 1e3 for s in runs])
          for n in names}
    total = sum(ms.values())
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.8))
    phase_handles = []
    for ax, scale in ((ax1, np.ones_like(total)), (ax2, 100.0 / np.maximum(total, 1e-300))):
        bottom = np.zeros(len(runs))
        for n in names:
            label, colour = PHASE_STYLE[n]
            h = ms[n] * scale
            bars = ax.bar(x, h, 0.65, bottom=bottom, color=colour, edgecolor="white", lw=0.5,
                          label=label)
            if ax is ax1:
                phase_handles.append(bars)
            for b, s in zip(bars, runs):
                if s["_oversubscribed"]:
                    b.set_hatch("///")
                    b.set_edgecolor((1, 1, 1, 0.8))
            bottom += h
        ax.set_xticks(x)
        ax.set_xticklabels(labels)
        ax.set_xlabel("ranks P" + (f"   (* oversubscribed: P > {cores(series.nproc)})"
                                   if any(s["_oversubscribed"] for s in runs) else ""))
        ax.grid(True, axis="y", alpha=0.3)
        ax.set_axisbelow(True)
    wall = np.array([float(s["wall_seconds"]) / max(int(s["cycles"]), 1) * 1e3 for s in runs])
    wall_handle = ax1.hlines(wall, x - 0.42, x + 0.42, color="black", lw=1.5,
               label="wall time per cycle\n(the phase maxima may sum to more)")
    for xi, t in zip(x, wall):
        ax1.text(xi, t, f"{t:.3g}", ha="center", va="bottom", fontsize=8)
    ax1.set_ylabel("time per cycle [ms]")
    ax1.set_title("time per cycle by phase (each phase: max over ranks)", fontsize=10)
    ax1.set_ylim(0, float(max(total.max(), wall.max())) * 1.12)
    ax2.set_ylabel("share [%]")
    ax2.set_ylim(0, 100)
    ax2.set_title("shares of the summed phase times", fontsize=10)
    # phases top to bottom as stacked, then the wall-time marker
    fig.legend(phase_handles[::-1] + [wall_handle],
               [PHASE_STYLE[n][0] for n in names[::-1]] + [wall_handle.get_label()],
               loc="center right", fontsize=8, frameon=False)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout(rect=(0, 0, 0.77, 1))
    return fig


def cpu_grind(s):
    """User + system seconds of all ranks per cycle per element [µs] (NaN if unknown)."""
    cpu = s.get("_cpu_seconds")
    if cpu is None:
        return float("nan")
    return cpu / max(int(s["cycles"]), 1) / int(s["elements"]) * 1e6


def table(series):
    """Markdown table of the series: sizes, grind, efficiency, phases, imbalance, bytes."""
    runs = series.runs
    eff = scaled_efficiency(runs)
    head = ["P", "elements", "cycles", "wall s", "grind µs", "E(P)", "CPU µs"] + \
        [f"{n} s" for n in SERIES_PHASES + ["other"]] + \
        ["imb fe", "imb contact", "contact load imb last/max", "bytes/rank/cycle", "rebal.",
         "oversub."]
    lines = ["| " + " | ".join(head) + " |", "|" + "---:|" * len(head)]
    for s, e in zip(runs, eff):
        ph = phase_seconds(s)
        imb = s.get("imbalance", {})
        c = s.get("contact", {})
        row = [str(s["ranks"]), f"{s['elements']:,}", f"{s['cycles']:,}",
               f"{s['wall_seconds']:.2f}", f"{s['grind_us']:.3f}", f"{e:.2f}",
               f"{cpu_grind(s):.3f}"]
        row += [f"{ph[n]:.3f}" for n in SERIES_PHASES + ["other"]]
        row += [f"{imb.get('fe', float('nan')):.2f}", f"{imb.get('contact', float('nan')):.2f}"]
        row += [f"{c['load_imbalance_last']:.2f} / {c['load_imbalance_max']:.2f}"
                if "load_imbalance_last" in c else "–",
                f"{c['bytes_sent_per_rank_per_cycle_max']:,.0f}"
                if "bytes_sent_per_rank_per_cycle_max" in c else "–",
                str(c.get("rebalances", "–")),
                "yes" if s["_oversubscribed"] else "no"]
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def main(argv=None):
    """Read the series, write both PNGs, print their paths (and the table)."""
    args = parse_args(argv)
    series = read_series(args.outroot, nproc=args.nproc)
    out = args.output or os.path.join(args.outroot[0], "figure2_scaling.png")
    out_phases = args.phases_output or phases_path(out)
    head = args.title or "Scaled can crush (Attaway et al. 1997, Figure 2)"
    title = f"{head}\n{describe(series)}"
    fig = plot_scaling(series, args, title)
    save_figure(fig, out, dpi=args.dpi)
    print(out)
    fig = plot_phases(series, args, title.replace("Figure 2", "Figure 2, phases"))
    save_figure(fig, out_phases, dpi=args.dpi)
    print(out_phases)
    if args.table:
        print(table(series))
    return 0


if __name__ == "__main__":
    run_main(main, "plot_figure2.py")
