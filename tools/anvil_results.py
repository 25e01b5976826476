#!/usr/bin/python3
"""Shared helpers of anvil's plotting tools: history.csv and summary.json readers,
unit choices for axes, and command-line error handling.

Public interface:
    ResultsError                         malformed or missing input (message names the file)
    read_history(outdir) -> History      the columns of OUTDIR/history.csv as float arrays
    read_summary(outdir) -> dict | None  OUTDIR/summary.json, or None when absent (its
                                         shape checked by check_summary)
    time_unit(t_max) -> (factor, label)  scale seconds for an axis ("µs", "ms" or "s")
    time_axis(history) -> (t, label, xlim) history times scaled, with x limits
    length_unit(extent) -> (factor, label)
    run_main(main, prog)                 call main(); input errors -> exit status 2, a
                                         closed pipe (`| head`) -> quiet exit 141
    save_figure(fig, path)               write a PNG, creating the directory
    read_series(roots) -> Series         the runs of tools/scaling_series.sh, by rank count
"""

import glob
import json
import os
import re
import sys
from dataclasses import dataclass, field

import numpy as np


class ResultsError(Exception):
    """Missing, unreadable or malformed anvil output; the message names the file."""


@dataclass
class History:
    """history.csv: `columns` in file order and `data[name]` a float64 array per column."""

    path: str
    columns: list
    data: dict

    def __getitem__(self, name):
        return self.data[name]

    def __len__(self):
        return len(self.data[self.columns[0]]) if self.columns else 0

    def probe_columns(self):
        """The PROBE.FIELD columns (those with a dot in the name), in file order."""
        return [c for c in self.columns if "." in c]


def _history_path(outdir):
    """OUTDIR/history.csv, or `outdir` itself if it is a file."""
    return outdir if os.path.isfile(outdir) else os.path.join(outdir, "history.csv")


def read_history(outdir):
    """Read OUTDIR/history.csv (or the .csv file given) into a History.

    A final line without its newline (a run still writing) is dropped with a warning;
    any other malformed line raises ResultsError naming the file and line.
    """
    path = _history_path(outdir)
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise ResultsError(f"{path}: cannot read ({e.strerror or e})") from None
    lines = text.split("\n")
    partial = lines.pop() if lines else ""  # text after the last newline
    if partial.strip():
        print(f"warning: {path}: ignoring the unterminated last line", file=sys.stderr)
    if not lines or not lines[0].strip():
        raise ResultsError(f"{path}: empty file, expected a header line")
    columns = [c.strip() for c in lines[0].split(",")]
    for required in ("time", "cycle"):
        if required not in columns:
            raise ResultsError(f"{path}: header has no {required!r} column")
    rows = []
    for lineno, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) != len(columns):
            raise ResultsError(
                f"{path}:{lineno}: {len(fields)} fields, the header has {len(columns)}"
            )
        try:
            rows.append([float(x) for x in fields])
        except ValueError:
            raise ResultsError(f"{path}:{lineno}: a field is not a number") from None
    table = np.array(rows, dtype=np.float64).reshape(len(rows), len(columns))
    if not rows:
        raise ResultsError(f"{path}: no data rows")
    return History(path, columns, {c: table[:, i] for i, c in enumerate(columns)})


def read_json(path):
    """The JSON document at `path`; ResultsError naming the file when it cannot be read or
    is not JSON."""
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        raise ResultsError(f"{path}: cannot read ({getattr(e, 'strerror', None) or e})") from None


def read_summary(outdir):
    """Return OUTDIR/summary.json as a dict, None if absent; ResultsError if malformed."""
    path = os.path.join(outdir, "summary.json") if os.path.isdir(outdir) else None
    if path is None or not os.path.exists(path):
        return None
    summary = read_json(path)
    check_summary(summary, path)
    return summary


# The summary.json fields the tools read, with the type anvil writes. Checked once here so
# that a file of the wrong shape (hand-edited, from another program) gives one clear error
# instead of a traceback wherever a tool first uses the field. Unknown keys are allowed.
_INT, _NUM, _STR = "an integer", "a number", "a string"
SUMMARY_FIELDS = {
    "title": _STR, "deck": _STR, "status": _STR, "message": _STR, "anvil_version": _STR,
    "ranks": _INT, "nodes": _INT, "elements": _INT, "particles": _INT, "cycles": _INT,
    "eroded_elements": _INT, "exit_status": _INT, "restart_cycle": _INT,
    "time": _NUM, "wall_seconds": _NUM, "grind_us": _NUM, "grind_us_compute": _NUM,
    "dt_initial": _NUM, "dt_final": _NUM,
}
# Blocks whose values are all numbers (energy.initial, timers.fe, contact.rebalances, ...).
SUMMARY_NUMBER_BLOCKS = ("energy", "timers", "imbalance", "contact", "sph", "part_mass")


def _is_type(value, kind):
    """True when a JSON value has the kind of SUMMARY_FIELDS (bool is not a number)."""
    if kind == _STR:
        return isinstance(value, str)
    if isinstance(value, bool):
        return False
    return isinstance(value, int) if kind == _INT else isinstance(value, (int, float))


def _json_type(value):
    """The JSON name of a value's type, for messages."""
    names = {bool: "a boolean", str: "a string", list: "a list", dict: "an object",
             int: "an integer", float: "a number", type(None): "null"}
    return names.get(type(value), type(value).__name__)


def check_summary(summary, path):
    """Raise ResultsError naming `path` unless `summary` has summary.json's shape."""
    if not isinstance(summary, dict):
        raise ResultsError(f"{path}: expected a JSON object, found {_json_type(summary)}")
    for key, kind in SUMMARY_FIELDS.items():
        if key in summary and not _is_type(summary[key], kind):
            raise ResultsError(f"{path}: {key!r} is {_json_type(summary[key])}, expected {kind}")
    for block in SUMMARY_NUMBER_BLOCKS:
        if block not in summary:
            continue
        if not isinstance(summary[block], dict):
            raise ResultsError(
                f"{path}: {block!r} is {_json_type(summary[block])}, expected an object")
        for key, value in summary[block].items():
            if not _is_type(value, _NUM):
                raise ResultsError(
                    f"{path}: '{block}.{key}' is {_json_type(value)}, expected a number")


def time_unit(t_max):
    """(factor, label) to show times up to `t_max` seconds: multiply seconds by factor."""
    t_max = abs(t_max)
    if 0 < t_max < 1e-3:
        return 1e6, "µs"
    if 0 < t_max < 1:
        return 1e3, "ms"
    return 1.0, "s"


def time_axis(h):
    """(t, unit, (lo, hi)): History `h`'s times in a unit chosen by time_unit, the unit's
    label and x limits spanning them.  A history of one row (a run stopped at its first
    output) spans no time; equal limits make matplotlib warn ("identical low and high
    xlims"), so there the unit comes from the step dt and the limits are one step either
    side of the point (one unit without a dt column)."""
    t_ref = h["time"].max()
    dt = float(h["dt"][0]) if "dt" in h.data and h["dt"][0] > 0 else 0.0
    if len(h) == 1:
        t_ref = max(t_ref, dt)
    factor, label = time_unit(t_ref)
    t = h["time"] * factor
    if t[-1] > t[0]:
        return t, label, (t[0], t[-1])
    half = dt * factor if dt else 1.0
    return t, label, (t[0] - half, t[0] + half)


def length_unit(extent):
    """(factor, label) to show lengths of size `extent` metres."""
    extent = abs(extent)
    if 0 < extent < 1e-3:
        return 1e6, "µm"
    if 0 < extent < 1:
        return 1e3, "mm"
    return 1.0, "m"


def title_of(summary, fallback):
    """A plot title: the deck title from summary.json, else `fallback`."""
    if summary and summary.get("title"):
        return str(summary["title"])
    return fallback


def run_description(summary):
    """One line describing the run (ranks, elements, cycles) from summary.json, or ''."""
    if not summary:
        return ""
    parts = []
    for key, label in (("ranks", "ranks"), ("elements", "elements"), ("particles", "particles")):
        if summary.get(key):
            parts.append(f"{summary[key]:,} {label}")
    if summary.get("cycles"):
        parts.append(f"{summary['cycles']:,} cycles")
    if summary.get("status") and summary["status"] != "completed":
        parts.append(f"status: {summary['status']}")
    return ", ".join(parts)


def use_agg():
    """Select matplotlib's file-only Agg backend and return pyplot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path, dpi=110, tight=False):
    """Write `fig` to `path` (directory created if needed); raise ResultsError on failure.
    tight=True crops the empty margin (useful around 3-D axes)."""
    directory = os.path.dirname(os.path.abspath(path))
    try:
        os.makedirs(directory, exist_ok=True)
        extra = dict(bbox_inches="tight", pad_inches=0.3) if tight else {}
        fig.savefig(path, dpi=dpi, **extra)
    except (OSError, ValueError) as e:
        raise ResultsError(f"{path}: cannot write ({e})") from None


# The exit status of a tool whose reader went away (`TOOL | head`): 128 + SIGPIPE, what a
# shell reports for a command that SIGPIPE ended.
BROKEN_PIPE_STATUS = 141


def run_main(main, prog):
    """Call main() and exit with its status.  Errors from unreadable input (ResultsError,
    VtuError) print as 'PROG: error: message' and exit 2.  A reader that closes the pipe
    early (`TOOL | head`) ends the tool quietly with BROKEN_PIPE_STATUS, never a traceback:
    the output is flushed here, where a BrokenPipeError can be caught, and the standard
    streams are pointed at /dev/null so that the interpreter's own flush at exit fails
    silently too.  Every tool's entry point (selftest.py included) goes through here."""
    from anvil_vtu import VtuError

    try:
        try:
            status = main()
        except (ResultsError, VtuError) as e:
            print(f"{prog}: error: {e}", file=sys.stderr)
            status = 2
        except SystemExit as e:  # argparse's --help and usage errors
            status = e.code
        sys.stdout.flush()
        sys.stderr.flush()
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        for stream in (sys.stdout, sys.stderr):
            try:
                os.dup2(devnull, stream.fileno())
            except (OSError, ValueError):
                pass
        status = BROKEN_PIPE_STATUS
    sys.exit(status or 0)


# --------------------------------------------------------------------------- scaling series

# Phases of summary.json's timers shown separately in the breakdowns, in stacking order;
# the rest of the wall time (predict, update, output, sph and untimed work) is "other".
SERIES_PHASES = ["fe", "halo", "contact_search", "contact_force", "transfer", "rebalance"]


@dataclass
class Series:
    """The runs of one or more scaling_series.sh output roots.

    runs: summary.json dicts sorted by rank count, each with "_dir" (its directory) and
    "_oversubscribed" (ranks > nproc) and "_cpu_seconds" (user + system seconds of all
    ranks from time.txt, or None) added; machine: OUTROOT/machine.json of the first root
    that has one ({} if none); nproc: cores of that machine (None when unknown)."""

    runs: list
    machine: dict = field(default_factory=dict)
    nproc: int = None


def read_machine(root):
    """ROOT/machine.json as written by scaling_series.sh, or {} when absent."""
    path = os.path.join(root, "machine.json")
    if not os.path.exists(path):
        return {}
    machine = read_json(path)
    if not isinstance(machine, dict):
        raise ResultsError(f"{path}: expected a JSON object, found {_json_type(machine)}")
    if "nproc" in machine and not (_is_type(machine["nproc"], _INT) and machine["nproc"] > 0):
        raise ResultsError(f"{path}: 'nproc' is {machine['nproc']!r}, expected a positive integer")
    return machine


def read_cpu_seconds(run_dir):
    """User + system CPU seconds of the whole mpirun (all ranks, setup included) from
    RUN_DIR/time.txt as scaling_series.sh writes it ('elapsed user sys' on the last line),
    or None when absent or unreadable."""
    try:
        with open(os.path.join(run_dir, "time.txt"), encoding="utf-8") as f:
            last = f.read().strip().splitlines()[-1].split()
        return float(last[1]) + float(last[2])
    except (OSError, IndexError, ValueError):
        return None


def read_series(roots, nproc=None):
    """Collect ROOT/P<n>/summary.json of every root, a series OUTROOT as
    tools/scaling_series.sh writes it.

    Runs with the same rank count: the first root wins and a warning names the other.
    `nproc` overrides the core count of machine.json.  Runs whose summary says failed are
    skipped with a warning.  Raises ResultsError when no run is found, and when a root is
    one run directory (summary.json at its top, no P<n>/summary.json): read as a series of
    one run it gave E = 1.00 and NaN CPU times that looked like results."""
    runs, machine, seen = [], {}, {}
    for root in roots:
        if not os.path.isdir(root):
            raise ResultsError(f"{root}: no such directory")
        if not machine:
            machine = read_machine(root)
        dirs = [d for d in glob.glob(os.path.join(root, "P*")) if re.fullmatch(
            r"P\d+", os.path.basename(d)) and os.path.isdir(d)]
        if not any(os.path.exists(os.path.join(d, "summary.json")) for d in dirs):
            _refuse_single_run(root)
        for d in sorted(dirs, key=lambda d: int(re.sub(r"\D", "", os.path.basename(d)) or 0)):
            s = read_summary(d)
            if s is None:
                print(f"warning: {d}: no summary.json (run failed or still running?)",
                      file=sys.stderr)
                continue
            path = os.path.join(d, "summary.json")
            for key in ("ranks", "elements", "cycles", "wall_seconds", "grind_us", "timers"):
                if key not in s:
                    raise ResultsError(f"{path}: no {key!r}")
            if s.get("status", "completed") != "completed":
                print(f"warning: {path}: status {s.get('status')!r}, skipped", file=sys.stderr)
                continue
            p = int(s["ranks"])
            if p in seen:
                print(f"warning: {path}: P = {p} already read from {seen[p]}, ignored",
                      file=sys.stderr)
                continue
            seen[p] = d
            s["_dir"] = d
            s["_cpu_seconds"] = read_cpu_seconds(d)
            runs.append(s)
    if not runs:
        raise ResultsError(f"{', '.join(roots)}: no P<n>/summary.json found")
    runs.sort(key=lambda s: s["ranks"])
    if nproc is None:
        nproc = machine.get("nproc")
    for s in runs:
        s["_oversubscribed"] = bool(nproc) and s["ranks"] > nproc
    return Series(runs, machine, nproc)


def _refuse_single_run(root):
    """Raise ResultsError when ROOT is one run directory rather than a series OUTROOT."""
    path = os.path.join(root, "summary.json")
    if not os.path.exists(path):
        return
    summary = read_summary(root)
    ranks = summary.get("ranks")
    what = f"one run on {ranks} rank{'s' if ranks != 1 else ''}" if ranks else "one run"
    raise ResultsError(
        f"{root}: {what} ({path}), not a scaling series: expected a series OUTROOT with "
        "P<n>/summary.json, as tools/scaling_series.sh writes (OUTROOT/P1, OUTROOT/P2, ...)")


def phase_seconds(summary):
    """{phase: seconds} for SERIES_PHASES plus "other" = wall_seconds minus their sum
    (clipped at 0: the timers are maxima over ranks, so their sum may exceed the wall)."""
    t = summary["timers"]
    out = {p: float(t.get(p, 0.0)) for p in SERIES_PHASES}
    out["other"] = max(0.0, float(summary["wall_seconds"]) - sum(out.values()))
    return out


def scaled_efficiency(runs):
    """E(P) = grind(P0) * P0 / (P * grind(P)) per run, P0 the smallest rank count (1 for
    the paper's definition grind(1) / (P grind(P)))."""
    base = runs[0]
    g0, p0 = float(base["grind_us"]), int(base["ranks"])
    return [g0 * p0 / (int(s["ranks"]) * float(s["grind_us"])) for s in runs]
