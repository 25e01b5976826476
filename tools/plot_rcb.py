#!/usr/bin/python3
"""Draws the paper's Figure 1 for a 2-D point cloud partitioned by anvil's Rcb.

Left: the points, their bounding box and the first cut (dotted). Right: the final
partition, each rank's box (clipped to the bounding box) and its points coloured by rank,
with every cut drawn, thicker for earlier levels.

The input JSON is written by bench/rcb_dump (run it on 8 ranks for the paper's picture):

    mpirun -np 8 build/bench/rcb_dump out/rcb.json
    /usr/bin/python3 tools/plot_rcb.py out/rcb.json -o docs/figures/rcb_figure1.png

Uses Debian's python3-matplotlib: run with /usr/bin/python3.
"""
import argparse

from anvil_results import ResultsError, read_json, run_main, save_figure, use_agg

# Top-level keys of bench/rcb_dump's JSON that the figure uses, with their JSON type.
RCB_KEYS = {"points_xy_owner": list, "ranks": int, "domain": dict, "cut_segments": list,
            "boxes": list, "counts": list, "points": int, "total_iterations": int}
TYPE_NAMES = {list: "a list", int: "an integer", dict: "an object"}


def read_rcb(path):
    """The rcb_dump JSON at `path` as a dict; ResultsError naming the file when it is
    missing, not JSON, or lacks a key the figure needs."""
    d = read_json(path)
    if not isinstance(d, dict):
        raise ResultsError(f"{path}: expected a JSON object (the output of bench/rcb_dump)")
    for key, kind in RCB_KEYS.items():
        if key not in d:
            raise ResultsError(f"{path}: no {key!r} (is this the output of bench/rcb_dump?)")
        if not isinstance(d[key], kind) or isinstance(d[key], bool):
            raise ResultsError(f"{path}: {key!r} is not {TYPE_NAMES[kind]}")
    return d


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json", help="output of bench/rcb_dump")
    ap.add_argument("-o", "--output", default="rcb_figure1.png", help="PNG to write")
    args = ap.parse_args()
    d = read_rcb(args.json)
    try:
        fig = draw(d)
    except (KeyError, IndexError, TypeError, ValueError) as e:
        # A key present but of the wrong shape inside (a box without "lo", a short point).
        raise ResultsError(f"{args.json}: malformed rcb_dump output ({type(e).__name__}: {e})") from None
    save_figure(fig, args.output)
    print(f"wrote {args.output}")
    return 0


def draw(d):
    """Both panels of Figure 1 from the rcb_dump dict `d`; returns the Figure."""
    plt = use_agg()  # imported here: errors in the input are reported without the wait
    import matplotlib.patches as patches

    pts = d["points_xy_owner"]
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    owner = [p[2] for p in pts]
    ranks = d["ranks"]
    lo, hi = d["domain"]["lo"], d["domain"]["hi"]
    cmap = plt.get_cmap("tab10" if ranks <= 10 else "tab20")
    color = [cmap(r % cmap.N) for r in range(ranks)]

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 5.0))
    pad = 0.03 * max(hi[0] - lo[0], hi[1] - lo[1])
    for ax in (left, right):
        ax.set_aspect("equal")
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.add_patch(patches.Rectangle((lo[0], lo[1]), hi[0] - lo[0], hi[1] - lo[1],
                                       fill=False, lw=1.2, ec="black"))

    # Left: the first cut.
    left.scatter(xs, ys, s=6, c="black", lw=0)
    first = [c for c in d["cut_segments"] if c["level"] == 0]
    for c in first:
        left.plot([c["from"][0], c["to"][0]], [c["from"][1], c["to"][1]], ls=":", lw=2.5,
                  c="tab:red")
    left.set_title("First cut of RCB")

    # Right: the final partition.
    for r, b in enumerate(d["boxes"]):
        (x0, y0, _), (x1, y1, _) = b["lo"], b["hi"]
        right.add_patch(patches.Rectangle((x0, y0), x1 - x0, y1 - y0, fc=color[r], alpha=0.25,
                                          ec="none"))
        right.text(0.5 * (x0 + x1), 0.5 * (y0 + y1), str(r), ha="center", va="center",
                   fontsize=11, weight="bold", color="0.2")
    right.scatter(xs, ys, s=6, c=[color[o] for o in owner], lw=0)
    depth = max([c["level"] for c in d["cut_segments"]] + [0])
    for c in d["cut_segments"]:
        right.plot([c["from"][0], c["to"][0]], [c["from"][1], c["to"][1]], c="black",
                   lw=2.4 - 1.6 * c["level"] / max(depth, 1))
    counts = ", ".join(str(n) for n in d["counts"])
    right.set_title(f"Final partition for {ranks} processors")
    fig.text(0.5, 0.02, f"{d['points']} points; points per rank: {counts}; "
             f"{d['total_iterations']} median-search rounds", ha="center", fontsize=9)
    fig.tight_layout(rect=(0, 0.05, 1, 0.97))
    return fig


if __name__ == "__main__":
    run_main(main, "plot_rcb.py")
