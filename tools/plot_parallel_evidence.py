#!/usr/bin/python3
"""Parallel behaviour of the scaled can crush against the rank count, beyond the cores.

Reads the summaries of one or more scaling_series.sh output roots (for example P = 1..8
with many cycles and P = 16..64 with a few) and draws, against P on a log2 axis:

(a) work imbalance, max over ranks / mean: imbalance.fe and imbalance.contact (from the
    phase timers: wall time, so noisy when ranks share cores) and the contact load
    imbalance (nodes searched + faces held per rank, a count that does not depend on the
    machine; last cycle and worst cycle);
(b) bytes sent per rank per cycle by the contact transfers (max over ranks;
    contact.bytes_sent_per_rank_per_cycle_max), in kB, labelled with the elements
    through the can wall when the run directory holds deck.yaml (a thicker split
    leaves fewer exterior nodes and faces per rank);
(c) wall time per cycle times min(P, cores) / P: on an oversubscribed machine the ranks
    time-share the cores, so this is roughly the time one rank's work takes per cycle,
    which stays flat when the work per rank and the per-rank overheads do not grow with P.

--table prints the numbers as a Markdown table.

    tools/scaling_series.sh --ranks "16 32 64" --cycles 30 --no-fields out/scaling_big
    /usr/bin/python3 tools/plot_parallel_evidence.py out/scaling out/scaling_big \\
        -o docs/figures/parallel_evidence.png --table
"""

import argparse
import os
import re
import sys

import numpy as np

from anvil_results import read_series, run_main, save_figure, use_agg


def parse_args(argv=None):
    """Command line -> argparse.Namespace."""
    p = argparse.ArgumentParser(
        description="Work imbalance, bytes sent per rank and normalised cycle time of the scaled "
        "can crush against the rank count (scaling_series.sh output).",
        epilog="example:\n  plot_parallel_evidence.py out/scaling out/scaling_big -o evidence.png",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("outroot", nargs="+", help="scaling_series.sh output root(s)")
    p.add_argument("-o", "--output", help="PNG (default OUTROOT/parallel_evidence.png)")
    p.add_argument("--nproc", type=int, help="cores (default: nproc in machine.json)")
    p.add_argument("--table", action="store_true", help="print a Markdown table")
    p.add_argument("--title", help="title line")
    p.add_argument("--dpi", type=int, default=120, help="PNG resolution (default 120)")
    args = p.parse_args(argv)
    if args.nproc is not None and args.nproc < 1:
        p.error("--nproc must be at least 1")
    return args


def values(series):
    """Per run: dict of the plotted quantities (NaN where the summary lacks one)."""
    nan = float("nan")
    out = []
    for s in series.runs:
        c = s.get("contact", {})
        imb = s.get("imbalance", {})
        p = int(s["ranks"])
        cyc = max(int(s["cycles"]), 1)
        share = min(p, series.nproc) / p if series.nproc else 1.0
        out.append(dict(
            ranks=p, elements=int(s["elements"]), cycles=int(s["cycles"]),
            imb_fe=float(imb.get("fe", nan)), imb_contact=float(imb.get("contact", nan)),
            load_last=float(c.get("load_imbalance_last", nan)),
            load_max=float(c.get("load_imbalance_max", nan)),
            bytes=float(c.get("bytes_sent_per_rank_per_cycle_max", nan)),
            rebalances=c.get("rebalances", None),
            ms_cycle=float(s["wall_seconds"]) / cyc * 1e3,
            ms_rank=float(s["wall_seconds"]) / cyc * 1e3 * share,
            layers=wall_layers(s["_dir"]),
            over=s["_oversubscribed"],
        ))
    return out


def wall_layers(run_dir):
    """Elements through the can wall from RUN_DIR/deck.yaml (the first mesh's third
    division), or None when the deck is absent or has no such line."""
    try:
        with open(os.path.join(run_dir, "deck.yaml"), encoding="utf-8") as f:
            m = re.search(r"generate:\s*can\b.*?divisions:\s*\[\s*\d+\s*,\s*\d+\s*,\s*(\d+)",
                          f.read())
    except OSError:
        return None
    return int(m.group(1)) if m else None


def log2_axis(ax, ranks):
    """x axis: log2 of the rank count, ticks at the measured counts."""
    ax.set_xscale("log", base=2)
    ax.set_xticks(ranks)
    ax.set_xticklabels([str(p) for p in ranks])
    ax.minorticks_off()
    ax.set_xlim(min(ranks) / 1.5, max(ranks) * 1.5)
    ax.set_xlabel("ranks P")
    ax.grid(True, alpha=0.3)


def series_plot(ax, x, y, over, style, label):
    """Line through all points; filled markers within the cores, hollow beyond."""
    x, y, over = np.asarray(x), np.asarray(y), np.asarray(over)
    ax.plot(x, y, "-", color=style["color"], lw=1.1, alpha=0.8)
    ax.plot(x[~over], y[~over], style["marker"], color=style["color"], ms=6, label=label)
    if over.any():
        ax.plot(x[over], y[over], style["marker"], mfc="white", mec=style["color"], mew=1.4,
                ms=6, label=None if (~over).any() else label)


def plot(series, rows, title):
    """The three panels."""
    plt = use_agg()
    ranks = [r["ranks"] for r in rows]
    over = [r["over"] for r in rows]
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    ax = axes[0]
    for key, label, colour, marker in (
            ("imb_fe", "FE phase time", "tab:blue", "o"),
            ("imb_contact", "contact phase time (search + forces)", "tab:red", "s"),
            ("load_last", "contact load, last cycle (count)", "tab:green", "^"),
            ("load_max", "contact load, worst cycle (count)", "tab:olive", "v")):
        series_plot(ax, ranks, [r[key] for r in rows], over, dict(color=colour, marker=marker),
                    label)
    ax.axhline(1.0, ls="--", color="0.4", lw=1)
    # Only finite values set the range: a run without contact has no contact load.
    imb = [v for r in rows for v in (r["imb_fe"], r["imb_contact"], r["load_max"])
           if np.isfinite(v)]
    ax.set_ylim(0.95, max([1.5] + [v * 1.08 for v in imb]))
    ax.set_ylabel("max / mean over ranks")
    ax.set_title("(a) work imbalance", fontsize=10)
    ax.legend(fontsize=7.5, loc="upper left")

    ax = axes[1]
    sent = [r["bytes"] for r in rows if np.isfinite(r["bytes"])]
    if sent:
        series_plot(ax, ranks, [r["bytes"] / 1e3 for r in rows], over,
                    dict(color="tab:purple", marker="o"), "max over ranks")
        for r in rows:
            if not np.isfinite(r["bytes"]):
                continue
            text = f"{r['bytes'] / 1e3:,.0f}"
            if r["layers"]:
                text += f"\n{r['layers']} layer" + ("s" if r["layers"] > 1 else "")
            ax.annotate(text, (r["ranks"], r["bytes"] / 1e3), textcoords="offset points",
                        xytext=(4, 6), fontsize=7.5)
        ax.set_ylim(0, max(max(sent) / 1e3 * 1.2, 1e-3))
        ax.legend(fontsize=8, loc="lower right")
    else:
        # No summary has contact.bytes_sent_per_rank_per_cycle_max (runs without contact,
        # such as the Taylor bar). Panels (a) and (c) still hold, so the figure is drawn
        # with this panel left empty and saying why, rather than refused (exit 2).
        ax.text(0.5, 0.5, "no contact bytes in these summaries\n(runs without contact)",
                transform=ax.transAxes, ha="center", va="center", fontsize=9, color="0.4")
        ax.set_ylim(0, 1)
        print("note: no summary has contact.bytes_sent_per_rank_per_cycle_max: "
              "panel (b) is left empty", file=sys.stderr)
    ax.set_ylabel("kB sent per rank per cycle")
    ax.set_title("(b) contact transfers: bytes sent to other ranks", fontsize=10)

    ax = axes[2]
    series_plot(ax, ranks, [r["ms_rank"] for r in rows], over,
                dict(color="tab:brown", marker="o"), "wall per cycle x min(P, cores) / P")
    series_plot(ax, ranks, [r["ms_cycle"] for r in rows], over,
                dict(color="0.55", marker="."), "wall per cycle")
    ax.set_yscale("log")
    ax.set_ylabel("ms per cycle")
    ax.set_title("(c) cycle time, and per rank share of the cores", fontsize=10)
    ax.legend(fontsize=8, loc="upper left")

    for ax in axes:
        log2_axis(ax, ranks)
        if series.nproc and max(ranks) > series.nproc:
            ax.axvspan(series.nproc * 2 ** 0.5, max(ranks) * 1.5, color="0.5", alpha=0.1,
                       lw=0)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def table(rows):
    """Markdown table of the plotted numbers."""
    head = ["P", "elements", "wall layers", "cycles", "imb fe (time)", "imb contact (time)",
            "contact load imb last", "contact load imb max", "kB/rank/cycle", "rebalances",
            "ms/cycle", "ms/cycle x min(P,cores)/P", "oversub."]
    lines = ["| " + " | ".join(head) + " |", "|" + "---:|" * len(head)]
    for r in rows:
        lines.append("| " + " | ".join([
            str(r["ranks"]), f"{r['elements']:,}", str(r["layers"] or "?"), str(r["cycles"]), f"{r['imb_fe']:.2f}",
            f"{r['imb_contact']:.2f}", f"{r['load_last']:.3f}", f"{r['load_max']:.3f}",
            f"{r['bytes'] / 1e3:,.1f}", str(r["rebalances"]), f"{r['ms_cycle']:.1f}",
            f"{r['ms_rank']:.2f}", "yes" if r["over"] else "no"]) + " |")
    return "\n".join(lines)


def main(argv=None):
    """Read the series, write the PNG, print its path (and the table)."""
    args = parse_args(argv)
    series = read_series(args.outroot, nproc=args.nproc)
    rows = values(series)
    m = series.machine
    machine = ""
    if series.nproc:
        machine = f"{series.nproc} cores" + (f" ({m['cpu_model']})" if m.get("cpu_model") else "")
        machine += f"; P > {series.nproc} oversubscribed (hollow markers, shaded)"
    cycles = sorted({r["cycles"] for r in rows})
    head = args.title or "Scaled can crush: parallel behaviour against the rank count"
    title = f"{head}\ncycles per run: {', '.join(map(str, cycles))}" + (f"; {machine}" if machine else "")
    fig = plot(series, rows, title)
    out = args.output or os.path.join(args.outroot[0], "parallel_evidence.png")
    save_figure(fig, out, dpi=args.dpi)
    print(out)
    if args.table:
        print(table(rows))
    return 0


if __name__ == "__main__":
    run_main(main, "plot_parallel_evidence.py")
