#!/usr/bin/python3
"""Where the ranks of a run wait: reads the records tools/mpi_trace.cpp wrote.

    mpirun -np 2 -x LD_PRELOAD=$PWD/build/tools/libanvil_mpi_trace.so \\
        -x ANVIL_MPI_TRACE=/tmp/tr build/apps/anvil bench can-crush -o out/cc2
    tools/mpi_trace.py build/apps/anvil /tmp/tr

Prints, per rank: each call site (its function, from addr2line) with its calls and the
time spent in them; the sizes of the messages sent; and the cycles, told apart by the
per-cycle step reduction (--start) and grouped by how many calls they make (a lazy
contact cycle makes fewer than a full one): their number and time, and for the commonest
sequences of calls the mean time of each call and of the work before it.
"""
import argparse
import collections
import glob
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from anvil_results import ResultsError, run_main  # noqa: E402

KINDS = {1: "allreduce", 2: "allgather", 3: "waitall", 4: "sendrecv", 5: "recv",
         6: "alltoall", 7: "isend"}
RECORD = np.dtype([("t0", "f8"), ("t1", "f8"), ("site", "u8"), ("kind", "i4"),
                   ("bytes", "i4")])


def site_names(binary, sites):
    """Function names of return addresses (offsets in the binary), shortened."""
    sites = sorted(sites)
    try:
        out = subprocess.run(["addr2line", "-f", "-C", "-e", binary] + [hex(s) for s in sites],
                             capture_output=True, text=True, check=True).stdout.split("\n")
    except (OSError, subprocess.CalledProcessError) as e:
        raise ResultsError(f"{binary}: cannot read its symbols ({e})") from None
    names = {}
    for i, s in enumerate(sites):
        name = out[2 * i].split("(")[0].replace("anvil::", "")
        names[s] = name if name != "??" else hex(s)
    return names


def report(binary, path, groups, start):
    try:
        d = np.fromfile(path, dtype=RECORD)
    except (OSError, ValueError) as e:
        raise ResultsError(f"{path}: cannot read ({e})") from None
    if len(d) == 0 or not np.isin(d["kind"], list(KINDS)).all():
        raise ResultsError(f"{path}: not a record of tools/mpi_trace.cpp")
    sends = d[d["kind"] == 7]
    d = d[d["kind"] != 7]
    names = site_names(binary, set(d["site"].tolist()))
    label = np.array([f"{names[s]} ({KINDS[k]})" for s, k in zip(d["site"], d["kind"])])
    dur = (d["t1"] - d["t0"]) * 1e6
    print(f"{path}: {len(d)} calls, {dur.sum() / 1e6:.3f} s in them")
    for name in sorted(set(label), key=lambda n: -dur[label == n].sum()):
        x = dur[label == name]
        print(f"  {name:60s} {len(x):7d} calls {x.sum() / 1e6:7.3f} s  mean {x.mean():7.2f} us"
              f"  p50 {np.median(x):6.2f}  p90 {np.percentile(x, 90):7.2f}")
    if len(sends):
        b = sends["bytes"]
        print(f"  messages sent: {len(b)}, bytes p10/p50/p90/max "
              f"{np.percentile(b, 10):.0f} / {np.median(b):.0f} / {np.percentile(b, 90):.0f}"
              f" / {b.max()}")
    # Cycles: from one per-cycle step reduction to the next.
    red = d["kind"] == 1
    counts = collections.Counter(d["site"][red].tolist())
    if not counts:
        raise ResultsError(f"{path}: no MPI_Allreduce to split the run into cycles")
    marker = max(counts, key=lambda s: (not start or names[s] == start, counts[s]))
    starts = np.where(red & (d["site"] == marker))[0]
    calls = np.diff(starts)
    length = np.diff(d["t0"][starts]) * 1e6
    print(f"  cycles: {len(length)}, marked by {names[marker]}")
    for n, count in sorted(collections.Counter(calls.tolist()).items()):
        x = length[calls == n]
        print(f"    {n:3d} calls: {count:6d} cycles, mean {x.mean():8.1f} us, median "
              f"{np.median(x):8.1f}, {x.sum() / 1e6:6.3f} s")
    # The commonest sequences of calls, each broken down.
    seqs = [tuple(d["site"][starts[i]:starts[i + 1]].tolist()) for i in range(len(starts) - 1)]
    for seq, count in collections.Counter(seqs).most_common(groups):
        rows = [i for i in range(1, len(seqs)) if seqs[i] == seq]
        if not rows:
            continue
        n = len(seq)
        work = np.array([[d["t0"][starts[i] + k] - d["t1"][starts[i] + k - 1]
                          for k in range(n)] for i in rows]) * 1e6
        wait = np.array([[dur[starts[i] + k] for k in range(n)] for i in rows])
        print(f"    {count} cycles of {n} calls: mean us of the work before each call, then of "
              f"the call")
        for k in range(n):
            print(f"      {names[seq[k]]:28s} work {work[:, k].mean():8.1f}   call "
                  f"{wait[:, k].mean():7.2f}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("binary", help="the traced executable (for the call sites' names)")
    p.add_argument("prefix", help="ANVIL_MPI_TRACE of the run (files PREFIX.RANK.bin)")
    p.add_argument("--groups", type=int, default=2,
                   help="cycle groups to break down (the commonest first)")
    p.add_argument("--start", help="the function whose MPI_Allreduce starts a cycle (for anvil "
                   "Comm::min, the step reduction; default: the commonest reduction's)")
    a = p.parse_args()
    paths = glob.glob(a.prefix + ".*.bin")
    if not paths:
        raise ResultsError(f"{a.prefix}.*.bin: no such files")
    for path in sorted(paths, key=lambda s: int(s.split(".")[-2]) if s.split(".")[-2].isdigit()
                       else -1):
        report(a.binary, path, a.groups, a.start)


if __name__ == "__main__":
    run_main(main, "mpi_trace.py")
