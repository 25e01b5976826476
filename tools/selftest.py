#!/usr/bin/python3
"""Self-test of anvil's Python plotting tools, needing no anvil run.

Writes a small synthetic output directory in a temporary folder -- a box of hexahedra
split into two per-rank .vtu pieces written byte for byte as src/anvil/io/vtu.cpp does,
the .pvtu indices, results.pvd, history.csv and summary.json -- then checks the reader
(anvil_vtu.py) against the known mesh, checks that malformed input raises clear errors,
and runs every plot script to a PNG and with bad arguments.

Usage: selftest.py [--keep]   (--keep leaves the temporary directory and prints it)
Exit status 0 when every check passes, 1 otherwise (141, quietly, when the reader of its
output goes away: selftest.py | head).
"""

import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import traceback

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import anvil_vtu  # noqa: E402
from plot_decomposition import exterior_faces  # noqa: E402

NX, NY, NZ = 3, 2, 4  # box cells per direction
RANKS = 2
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


# --------------------------------------------------------------------------- writers (as vtu.cpp)


class Appender:
    """Mirror of vtu.cpp's Appender: XML header text plus a blob of (UInt64 bytes, data)."""

    def __init__(self):
        self.header, self.blob = "", bytearray()

    def add(self, values, fmt):
        """Append a UInt64 byte count and the values packed little-endian; return offset."""
        offset = len(self.blob)
        data = struct.pack(f"<{len(values)}{fmt}", *values)
        self.blob += struct.pack("<Q", len(data)) + data
        return offset


def array_tag(a, name, comps, values, is_int):
    """Mirror of vtu.cpp's array_tag for one named point/cell array."""
    off = a.add(values, "q" if is_int else "d")
    a.header += (
        f'        <DataArray type="{"Int64" if is_int else "Float64"}" Name="{name}" '
        f'NumberOfComponents="{comps}" format="appended" offset="{off}"/>\n'
    )


def write_vtu(path, piece):
    """Write `piece` (dict: points, connectivity, offsets, types, point_data, cell_data
    with data as [(name, comps, flat values, is_int)]) exactly as write_vtu in vtu.cpp."""
    a = Appender()
    np_, nc = len(piece["points"]) // 3, len(piece["types"])
    a.header += ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" '
                 'byte_order="LittleEndian" header_type="UInt64">\n  <UnstructuredGrid>\n')
    a.header += f'    <Piece NumberOfPoints="{np_}" NumberOfCells="{nc}">\n'
    a.header += "      <PointData>\n"
    for arr in piece["point_data"]:
        array_tag(a, *arr)
    a.header += "      </PointData>\n      <CellData>\n"
    for arr in piece["cell_data"]:
        array_tag(a, *arr)
    a.header += "      </CellData>\n      <Points>\n"
    a.header += ('        <DataArray type="Float64" NumberOfComponents="3" '
                 f'format="appended" offset="{a.add(piece["points"], "d")}"/>\n')
    a.header += "      </Points>\n      <Cells>\n"
    a.header += ('        <DataArray type="Int64" Name="connectivity" '
                 f'format="appended" offset="{a.add(piece["connectivity"], "q")}"/>\n')
    a.header += ('        <DataArray type="Int64" Name="offsets" format="appended" '
                 f'offset="{a.add(piece["offsets"], "q")}"/>\n')
    a.header += ('        <DataArray type="UInt8" Name="types" format="appended" '
                 f'offset="{a.add(piece["types"], "B")}"/>\n')
    a.header += ('      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData '
                 'encoding="raw">\n   _')
    with open(path, "wb") as f:
        f.write(a.header.encode() + bytes(a.blob) + b"\n  </AppendedData>\n</VTKFile>\n")


def write_pvtu(path, pieces, layout):
    """Mirror of write_pvtu in vtu.cpp."""
    s = ('<?xml version="1.0"?>\n<VTKFile type="PUnstructuredGrid" version="1.0" '
         'byte_order="LittleEndian" header_type="UInt64">\n  <PUnstructuredGrid '
         'GhostLevel="0">\n')

    def arrays(lst):
        return "".join(
            f'      <PDataArray type="{"Int64" if i else "Float64"}" Name="{n}" '
            f'NumberOfComponents="{c}"/>\n' for n, c, _, i in lst)

    s += "    <PPointData>\n" + arrays(layout["point_data"])
    s += "    </PPointData>\n    <PCellData>\n" + arrays(layout["cell_data"])
    s += ('    </PCellData>\n    <PPoints>\n      <PDataArray type="Float64" '
          'NumberOfComponents="3"/>\n    </PPoints>\n')
    s += "".join(f'    <Piece Source="{f}"/>\n' for f in pieces)
    s += "  </PUnstructuredGrid>\n</VTKFile>\n"
    with open(path, "w") as f:
        f.write(s)


def write_pvd(path, entries):
    """Mirror of write_pvd in vtu.cpp: entries are (time, relative file)."""
    s = '<?xml version="1.0"?>\n<VTKFile type="Collection" version="1.0">\n  <Collection>\n'
    s += "".join(f'    <DataSet timestep="{t:.17g}" part="0" file="{f}"/>\n' for t, f in entries)
    s += "  </Collection>\n</VTKFile>\n"
    with open(path, "w") as f:
        f.write(s)


# --------------------------------------------------------------------------- synthetic run


def box_mesh():
    """Global box mesh: (points (n,3), hex connectivity (m,8) in VTK order, cell centres)."""
    h = 1e-3
    idx = lambda i, j, k: i + (NX + 1) * (j + (NY + 1) * k)  # noqa: E731
    pts = np.array([(i * h, j * h, k * h) for k in range(NZ + 1) for j in range(NY + 1)
                    for i in range(NX + 1)])
    conn = []
    for k in range(NZ):
        for j in range(NY):
            for i in range(NX):
                conn.append([idx(i, j, k), idx(i + 1, j, k), idx(i + 1, j + 1, k),
                             idx(i, j + 1, k), idx(i, j, k + 1), idx(i + 1, j, k + 1),
                             idx(i + 1, j + 1, k + 1), idx(i, j + 1, k + 1)])
    conn = np.array(conn)
    return pts, conn, pts[conn].mean(axis=1)


def rank_piece(pts, conn, cells, rank, t):
    """The .vtu piece of `rank` owning global `cells`, at time t (displacement grows with t)."""
    nodes = np.unique(conn[cells])
    local = {g: l for l, g in enumerate(nodes)}
    disp = np.zeros((len(nodes), 3))
    disp[:, 2] = -0.1 * pts[nodes, 2] * (t / 1e-5)  # squash along z
    disp[:, 0] = 0.05 * pts[nodes, 0] * (t / 1e-5)
    x = pts[nodes] + disp
    lconn = [local[g] for c in cells for g in conn[c]]
    stress = np.zeros((len(cells), 6))
    stress[:, 2] = -1e8 * (1 + np.arange(len(cells)))
    return {
        "points": x.ravel().tolist(),
        "connectivity": lconn,
        "offsets": [8 * (e + 1) for e in range(len(cells))],
        "types": [12] * len(cells),
        "point_data": [("displacement", 3, disp.ravel().tolist(), False),
                       ("velocity", 3, (disp / 1e-5).ravel().tolist(), False),
                       ("node_id", 1, (nodes + 1).tolist(), True)],
        "cell_data": [("stress", 6, stress.ravel().tolist(), False),
                      ("von_mises", 1, (-stress[:, 2]).tolist(), False),
                      ("pressure", 1, (-stress[:, 2] / 3).tolist(), False),
                      ("plastic_strain", 1, (0.01 * cells * t / 1e-5).tolist(), False),
                      ("fe_rank", 1, [rank] * len(cells), True),
                      ("contact_rank", 1, [rank if t == 0 else 1 - rank] * len(cells), True),
                      ("element_id", 1, (cells + 1).tolist(), True),
                      ("part", 1, [0] * len(cells), True)],
    }


def write_run(outdir):
    """Write a complete synthetic anvil output directory; return the expected facts."""
    os.makedirs(os.path.join(outdir, "fields"))
    pts, conn, centres = box_mesh()
    owner = (centres[:, 2] > NZ * 1e-3 / 2).astype(int)  # split along z into 2 ranks
    times = [1e-5, 0.0]  # deliberately unsorted: the reader must sort the .pvd by time
    entries = []
    for step, t in enumerate(sorted(times)):
        stem = f"step_{step:06d}"
        names = []
        for r in range(RANKS):
            piece = rank_piece(pts, conn, np.flatnonzero(owner == r), r, t)
            names.append(f"{stem}_r{r:04d}.vtu")
            write_vtu(os.path.join(outdir, "fields", names[-1]), piece)
        write_pvtu(os.path.join(outdir, "fields", f"{stem}.pvtu"), names, piece)
        entries.append((t, f"fields/{stem}.pvtu"))
    write_pvd(os.path.join(outdir, "results.pvd"), [entries[1], entries[0]])
    write_history(outdir)
    with open(os.path.join(outdir, "summary.json"), "w") as f:
        json.dump({"title": "selftest box", "ranks": RANKS, "elements": len(conn),
                   "cycles": 100, "status": "completed",
                   "energy": {"balance_error": 1e-4}}, f)
    return {"n_cells": len(conn), "n_nodes": len(pts), "owner": owner,
            "exterior": 2 * (NX * NY + NY * NZ + NX * NZ)}


def write_history(outdir):
    """history.csv with the energy columns and one probe, formatted like outputs.cpp."""
    cols = "time,cycle,dt,kinetic,internal,hourglass,contact,external_work,total"
    cols += "".join(f",tip.{f}" for f in ("ux", "uy", "uz", "vx", "vy", "vz"))
    lines = [cols]
    for n in range(101):
        t = n * 1e-7
        k = 10.0 * (1 - n / 100) ** 2
        i = 10.0 - k - 0.01 * n / 100
        hg = 0.01 * n / 100
        row = [t, n, 1e-7, k, i, hg, 0.0, 0.0, k + i + hg,
               0, 0, -50.0 * t, 0, 0, -50.0 + 0.1 * n]
        lines.append(",".join(f"{v:.17g}" for v in row))
    with open(os.path.join(outdir, "history.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")


def write_particles(outdir, times):
    """particles.pvd and per-rank vertex-cell pieces as anvil writes them (docs/sph.md,
    "Outputs"): a 4 x 2 x 3 block of particles above the box, split in x over 2 ranks.
    Written into a run directory, or alone (as `anvil decompose` of a deck of particles
    only, which writes no results.pvd)."""
    os.makedirs(os.path.join(outdir, "fields"), exist_ok=True)
    h = 0.5e-3
    pts = np.array([(i * h, j * h, 4.5e-3 + k * h) for k in range(3) for j in range(2)
                    for i in range(4)])
    entries = []
    for step, t in enumerate(times):
        names = []
        for r in range(RANKS):
            mine = np.flatnonzero((pts[:, 0] >= 1e-3) == bool(r))
            x = pts[mine] + [0.0, 0.0, -10.0 * t]  # falling at 10 m/s
            n = len(mine)
            piece = {
                "points": x.ravel().tolist(), "connectivity": list(range(n)),
                "offsets": list(range(1, n + 1)), "types": [1] * n,
                "point_data": [("velocity", 3, [0.0, 0.0, -10.0] * n, False),
                               ("pressure", 1, (1e6 * x[:, 2]).tolist(), False),
                               ("smoothing_length", 1, [1.2 * h] * n, False),
                               ("sph_rank", 1, [r] * n, True),
                               ("particle_id", 1, (mine + 1).tolist(), True)],
                "cell_data": [],
            }
            names.append(f"particles_step_{step:06d}_r{r:04d}.vtu")
            write_vtu(os.path.join(outdir, "fields", names[-1]), piece)
        write_pvtu(os.path.join(outdir, "fields", f"particles_step_{step:06d}.pvtu"), names, piece)
        entries.append((t, f"fields/particles_step_{step:06d}.pvtu"))
    write_pvd(os.path.join(outdir, "particles.pvd"), entries)


# --------------------------------------------------------------------------- checks


class Checks:
    """Collects named check results and prints them."""

    def __init__(self):
        self.failed = []

    def run(self, name, fn, *args):
        """Run fn(*args); a raised exception (AssertionError or other) is a failure."""
        try:
            fn(*args)
            print(f"ok    {name}")
        except Exception:  # noqa: BLE001 - report every failure, keep going
            print(f"FAIL  {name}")
            traceback.print_exc(limit=3)
            self.failed.append(name)


def check_reader(outdir, facts):
    """The reader returns the synthetic mesh: sizes, pieces merged, fields, time order."""
    entries = anvil_vtu.read_pvd(os.path.join(outdir, "results.pvd"))
    assert [e.time for e in entries] == [0.0, 1e-5], entries
    entry, g = anvil_vtu.load_output(outdir, step=0)
    assert entry.time == 0.0
    assert g.n_cells == facts["n_cells"], g.n_cells
    assert g.connectivity.shape == (facts["n_cells"], 8)
    assert set(g.cell_types.tolist()) == {12}
    assert len(np.unique(g.point_data["node_id"])) == facts["n_nodes"]
    assert g.n_points > facts["n_nodes"]  # shared nodes appear once per piece
    assert g.cell_data["stress"].shape == (facts["n_cells"], 6)
    assert g.point_data["displacement"].shape == (g.n_points, 3)
    assert g.cell_data["fe_rank"].dtype == np.int64
    # cells are in piece order: rank 0's then rank 1's
    assert np.array_equal(g.cell_data["fe_rank"], g.piece_of_cell)
    assert np.array_equal(np.sort(g.cell_data["element_id"]), np.arange(1, facts["n_cells"] + 1))
    # points of a cell coincide with the global mesh's (undeformed at t=0)
    pts, conn, _ = box_mesh()
    eid = g.cell_data["element_id"] - 1
    assert np.allclose(g.points[g.connectivity], pts[conn[eid]])
    last = anvil_vtu.select_entry(entries)
    near = anvil_vtu.select_entry(entries, time=0.8e-5)
    assert last.time == near.time == 1e-5
    _, g1 = anvil_vtu.load_output(outdir, time=1e-5)
    und = g1.points - g1.point_data["displacement"]
    assert np.allclose(und[g1.connectivity], pts[conn[g1.cell_data["element_id"] - 1]])


def check_single_vtu(outdir, facts):
    """A single piece reads on its own, and through load_output given its path."""
    path = os.path.join(outdir, "fields", "step_000000_r0000.vtu")
    g = anvil_vtu.read_vtu(path)
    assert g.n_cells == int((facts["owner"] == 0).sum())
    _, g2 = anvil_vtu.load_output(path)
    assert g2.n_cells == g.n_cells


def check_exterior(outdir, facts):
    """Exterior faces of the two-piece box: 2(nx ny + ny nz + nx nz), none at the rank
    boundary, and every normal outward."""
    _, g = anvil_vtu.load_output(outdir, step=0)
    conn, _ = g.hex_connectivity()
    faces, owner = exterior_faces(conn, g.point_data["node_id"])
    assert len(faces) == facts["exterior"], len(faces)
    q = g.points[faces]
    n = np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1])
    outward = q.mean(axis=1) - g.points[conn[owner]].mean(axis=1)
    assert np.all((n * outward).sum(axis=1) > 0)


def expect_error(fn, *words):
    """fn() must raise VtuError whose message contains every word."""
    try:
        fn()
    except anvil_vtu.VtuError as e:
        for w in words:
            assert w in str(e), f"{w!r} not in {e}"
        return
    raise AssertionError("no VtuError raised")


def check_malformed(outdir, tmp):
    """Truncated, non-XML, missing-piece and wrong-type inputs give VtuError naming files."""
    good = os.path.join(outdir, "fields", "step_000001_r0001.vtu")
    data = open(good, "rb").read()
    bad = os.path.join(tmp, "truncated.vtu")
    with open(bad, "wb") as f:
        f.write(data[: len(data) - 200])
    expect_error(lambda: anvil_vtu.read_vtu(bad), "truncated.vtu")
    junk = os.path.join(tmp, "junk.vtu")
    with open(junk, "wb") as f:
        f.write(b"not xml at all")
    expect_error(lambda: anvil_vtu.read_vtu(junk), "junk.vtu")
    expect_error(lambda: anvil_vtu.read_vtu(os.path.join(tmp, "absent.vtu")), "absent.vtu")
    pvtu = os.path.join(tmp, "lonely.pvtu")
    text = open(os.path.join(outdir, "fields", "step_000000.pvtu")).read()
    with open(pvtu, "w") as f:
        f.write(text)  # its pieces are not next to it
    expect_error(lambda: anvil_vtu.read_pvtu(pvtu), "lonely.pvtu", "step_000000_r0000.vtu")
    expect_error(lambda: anvil_vtu.read_pvtu(good), "step_000001_r0001.vtu", "PUnstructuredGrid")
    expect_error(lambda: anvil_vtu.select_entry(
        anvil_vtu.read_pvd(os.path.join(outdir, "results.pvd")), step=5), "out of range")


def run_tool(args, expect):
    """Run a tool with /usr/bin/python3 (this interpreter); assert its exit status."""
    cmd = [sys.executable, os.path.join(HERE, args[0])] + args[1:]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == expect, (
        f"{' '.join(cmd)}: exit {r.returncode}, expected {expect}\n{r.stdout}{r.stderr}")
    if expect == 2:
        assert "error" in r.stderr, r.stderr
    # A user error is a message, never a traceback (tools/README.md).
    assert "Traceback" not in r.stderr, f"{' '.join(cmd)}: traceback\n{r.stderr}"
    return r


def expect_usage_error(args, *words):
    """The tool exits 2 with a message containing every word (a file or an argument)."""
    r = run_tool(args, 2)
    for w in words:
        assert w in r.stderr, f"{' '.join(args)}: {w!r} not in {r.stderr!r}"


def check_png(path):
    """`path` exists and is a non-trivial PNG."""
    with open(path, "rb") as f:
        head = f.read(8)
    assert head == PNG_MAGIC, f"{path} is not a PNG"
    assert os.path.getsize(path) > 5000, f"{path} is suspiciously small"


def write_series(root, ranks=(1, 2, 4, 8), nproc=2, contact=True):
    """A synthetic scaling_series.sh output root: machine.json and P<n>/summary.json with
    the keys plot_figure2.py and plot_parallel_evidence.py read; P = 8 lacks its summary
    (a failed run) and P = 4's repeats sit in rep<k>/ as with --repeat.  contact=False
    leaves out the contact block (a model without contact)."""
    os.makedirs(root)
    with open(os.path.join(root, "machine.json"), "w") as f:
        json.dump({"nproc": nproc, "cpu_model": "Synthetic CPU", "ranks": list(ranks),
                   "cycles": 100}, f)
    for p in ranks:
        d = os.path.join(root, f"P{p}")
        os.makedirs(os.path.join(d, "rep1"))
        if p == ranks[-1]:
            continue
        wall = 1.0 + 0.2 * np.log2(p)
        phases = {"fe": 0.4 * wall, "halo": 0.02 * p, "contact_search": 0.2 * wall,
                  "contact_force": 0.05, "transfer": 0.1 * p, "rebalance": 0.01,
                  "predict": 0.01, "update": 0.01, "output": 0.02, "sph": 0.0}
        summary = {"ranks": p, "elements": 1864 * p, "cycles": 100, "status": "completed",
                   "wall_seconds": wall, "grind_us": wall / 100 / (1864 * p) * 1e6,
                   "timers": phases, "imbalance": {"fe": 1 + 0.01 * p, "contact": 1 + 0.05 * p},
                   "contact": {"rebalances": p, "load_imbalance_last": 1.02,
                               "load_imbalance_max": 1.1, "pairs_last_cycle": 10 * p,
                               "bytes_sent_per_rank_per_cycle_max": 1.5e6 + 1e4 * p}}
        if not contact:
            del summary["contact"]
        for where in (d, os.path.join(d, "rep1")):
            with open(os.path.join(where, "summary.json"), "w") as f:
                json.dump(summary, f)


def check_series_tools(tmp):
    """plot_figure2.py and plot_parallel_evidence.py on a synthetic series (P = 4 over the
    2 cores of machine.json, P = 8 missing), their tables, and exit status 2 on bad input."""
    root = os.path.join(tmp, "series")
    write_series(root)
    r = run_tool(["plot_figure2.py", root, "-o", f"{tmp}/fig2_scaling.png", "--table"], 0)
    check_png(os.path.join(tmp, "fig2_scaling.png"))
    check_png(os.path.join(tmp, "fig2_phases.png"))
    rows = [line for line in r.stdout.splitlines() if line.startswith("| ")]
    assert len(rows) == 4, r.stdout  # header + P = 1, 2, 4
    assert rows[3].split("|")[1].strip() == "4" and rows[3].rstrip(" |").endswith("yes"), rows
    assert "no summary.json" in r.stderr, r.stderr  # P = 8
    # E(2) = grind(1) / (2 grind(2)) = (1 / 1864) / (2 * 1.2 / (2 * 1864)) = 1 / 1.2
    assert rows[2].split("|")[6].strip() == f"{1 / 1.2:.2f}", rows[2]
    r = run_tool(["plot_parallel_evidence.py", root, "-o", f"{tmp}/evidence.png", "--table"], 0)
    check_png(os.path.join(tmp, "evidence.png"))
    assert r.stdout.count("\n| ") == 4, r.stdout
    for bad in (["plot_figure2.py", os.path.join(tmp, "no_such_dir")],
                ["plot_figure2.py", os.path.join(tmp, "run", "fields")],
                ["plot_parallel_evidence.py", os.path.join(tmp, "no_such_dir")]):
        run_tool(bad, 2)
    # One run directory, even one of a series, is not a series (it printed E = 1.00 and
    # nan; QA round 16).
    run = os.path.join(root, "P2")
    for tool in ("plot_figure2.py", "plot_parallel_evidence.py"):
        expect_usage_error([tool, run, "-o", f"{tmp}/x.png", "--table"],
                           os.path.join(run, "summary.json"), "P<n>/summary.json",
                           "scaling_series.sh")
    assert not os.path.exists(os.path.join(tmp, "x.png"))


def check_particles(outdir, tmp):
    """plot_particles.py: a run with mesh and particles, a particles-only decomposition
    (no results.pvd), the PNG path printed, and exit 2 on impossible arguments."""
    write_particles(outdir, [0.0, 1e-5])
    png = f"{tmp}/particles.png"
    r = run_tool(["plot_particles.py", outdir, "--steps", "0,-1", "-o", png], 0)
    check_png(png)
    assert r.stdout.strip() == png, r.stdout
    ponly = os.path.join(tmp, "particles_only")
    write_particles(ponly, [0.0])
    png = f"{tmp}/particles_only.png"
    r = run_tool(["plot_particles.py", ponly, "--field", "pressure", "-o", png], 0)
    check_png(png)
    assert "no results.pvd" in r.stderr, r.stderr
    for args, words in ((["--steps", "a,b"], ["--steps", "'a,b'"]),
                        (["--steps", ""], ["--steps"]),
                        (["--steps", "2"], ["particles.pvd", "out of range"]),
                        (["--steps", "0,-3"], ["particles.pvd", "out of range"]),
                        (["--slab", "0"], ["--slab"]),
                        (["--slab", "-1e-3"], ["--slab"]),
                        (["--cut", "y=abc"], ["--cut"])):
        expect_usage_error(["plot_particles.py", outdir] + args + ["-o", f"{tmp}/x.png"], *words)


def check_summary_shapes(outdir, tmp):
    """summary.json that is valid JSON of the wrong shape: a ResultsError naming the file
    from anvil_results (checked once there), and exit 2 from the tools that read it."""
    from anvil_results import ResultsError, read_summary

    bad = os.path.join(tmp, "bad_summary")
    os.makedirs(bad)
    shutil.copy(os.path.join(outdir, "history.csv"), bad)
    path = os.path.join(bad, "summary.json")
    for text, word in (('[1, 2]', "JSON object"), ('{"cycles": "many"}', "'cycles'"),
                       ('{"ranks": null}', "'ranks'"), ('{"title": 3}', "'title'"),
                       ('{"energy": 3}', "'energy'"),
                       ('{"energy": {"initial": "x"}}', "'energy.initial'")):
        with open(path, "w") as f:
            f.write(text)
        try:
            read_summary(bad)
        except ResultsError as e:
            assert path in str(e) and word in str(e), e
        else:
            raise AssertionError(f"{text}: no ResultsError")
        if word in ("JSON object", "'cycles'"):  # the two cases of the QA report
            expect_usage_error(["plot_history.py", bad, "-o", f"{tmp}/x.png"], path)
            expect_usage_error(["plot_probe.py", bad, "tip.uz", "-o", f"{tmp}/x.png"], path)
    assert read_summary(outdir)["title"] == "selftest box"  # the good one still reads


def write_rcb(path):
    """A small JSON of bench/rcb_dump's shape: 2 ranks split at x = 0.5."""
    pts = [[0.1 * i, 0.05 * i, int(i >= 5)] for i in range(10)]
    with open(path, "w") as f:
        json.dump({"points_xy_owner": pts, "ranks": 2, "points": 10, "total_iterations": 3,
                   "domain": {"lo": [0, 0, 0], "hi": [1, 1, 0]}, "counts": [5, 5],
                   "cut_segments": [{"level": 0, "from": [0.5, 0], "to": [0.5, 1]}],
                   "boxes": [{"lo": [0, 0, 0], "hi": [0.5, 1, 0]},
                             {"lo": [0.5, 0, 0], "hi": [1, 1, 0]}]}, f)


def check_rcb(tmp):
    """plot_rcb.py draws a rcb_dump JSON; a missing file, or JSON without its keys, is exit 2."""
    good = os.path.join(tmp, "rcb.json")
    write_rcb(good)
    run_tool(["plot_rcb.py", good, "-o", f"{tmp}/rcb.png"], 0)
    check_png(os.path.join(tmp, "rcb.png"))
    missing = os.path.join(tmp, "no_rcb.json")
    expect_usage_error(["plot_rcb.py", missing, "-o", f"{tmp}/x.png"], missing)
    empty = os.path.join(tmp, "rcb_empty.json")
    with open(empty, "w") as f:
        f.write("{}")
    expect_usage_error(["plot_rcb.py", empty, "-o", f"{tmp}/x.png"], empty, "points_xy_owner")


def check_vtu_cli(outdir, tmp):
    """anvil_vtu.py as a command: --help, no argument (usage, exit 2), a missing directory
    (exit 2), a run of Exodus II output only (a hint, also from plot_decomposition.py)."""
    r = run_tool(["anvil_vtu.py", "--help"], 0)
    assert r.stdout.startswith("usage:"), r.stdout
    r = run_tool(["anvil_vtu.py"], 2)
    assert "usage:" in r.stderr, r.stderr
    missing = os.path.join(tmp, "no_such_dir")
    expect_usage_error(["anvil_vtu.py", missing], missing)
    r = run_tool(["anvil_vtu.py", outdir], 0)
    assert "fe_rank" in r.stdout, r.stdout
    # A .pvtu given directly has no time (only the .pvd has it): no t=nan (QA round 16).
    pvtu = os.path.join(outdir, "fields", "step_000001.pvtu")
    r = run_tool(["anvil_vtu.py", pvtu], 0)
    assert r.stdout.startswith(f"{pvtu}: t unknown points="), r.stdout
    assert "nan" not in r.stdout, r.stdout
    # A run with particles lists the last output of particles.pvd too (QA round 16), and a
    # directory with particles.pvd alone lists it with a note.
    sph = os.path.join(tmp, "run_sph")
    write_run(sph)
    write_particles(sph, [0.0, 1e-5])
    r = run_tool(["anvil_vtu.py", sph], 0)
    heads = [line for line in r.stdout.splitlines() if not line.startswith("  ")]
    assert len(heads) == 2, r.stdout
    assert heads[0].startswith(os.path.join(sph, "fields", "step_000001.pvtu")), heads
    assert "(last of 2 in results.pvd): t=1e-05 points=" in heads[0], heads
    assert "(last of 2 in particles.pvd): t=1e-05 points=24 cells=24" in heads[1], heads
    assert "particle_id" in r.stdout and "fe_rank" in r.stdout, r.stdout
    ponly = os.path.join(tmp, "vtu_particles_only")
    write_particles(ponly, [0.0])
    r = run_tool(["anvil_vtu.py", ponly], 0)
    assert "(last of 1 in particles.pvd)" in r.stdout and "sph_rank" in r.stdout, r.stdout
    assert "no results.pvd" in r.stderr, r.stderr
    exo = os.path.join(tmp, "exodus_only")
    os.makedirs(exo)
    for name in ("results.exo", "history.csv"):
        open(os.path.join(exo, name), "w").close()
    for tool in ("anvil_vtu.py", "plot_decomposition.py"):
        expect_usage_error([tool, exo], exo, "Exodus II", "results.exo", "--format vtu")


def check_no_contact_series(tmp):
    """plot_parallel_evidence.py on runs without contact bytes draws the other panels and
    says panel (b) is empty (it raised on NaN axis limits)."""
    root = os.path.join(tmp, "series_no_contact")
    write_series(root, ranks=(1, 2, 4), contact=False)
    r = run_tool(["plot_parallel_evidence.py", root, "-o", f"{tmp}/evidence_nc.png"], 0)
    check_png(os.path.join(tmp, "evidence_nc.png"))
    assert "panel (b)" in r.stderr, r.stderr


def check_one_row_history(outdir, tmp):
    """A history.csv of one row plots without matplotlib's singular-limits warning."""
    one = os.path.join(tmp, "one_row")
    os.makedirs(one)
    with open(os.path.join(outdir, "history.csv")) as f:
        lines = f.read().splitlines()
    with open(os.path.join(one, "history.csv"), "w") as f:
        f.write(lines[0] + "\n" + lines[1] + "\n")
    for args in (["plot_history.py", one, "-o", f"{tmp}/one.png"],
                 ["plot_probe.py", one, "tip.uz", "-o", f"{tmp}/one_probe.png"]):
        r = run_tool(args, 0)
        assert "Warning" not in r.stderr, r.stderr
    check_png(os.path.join(tmp, "one.png"))


def check_broken_pipe(outdir, tmp):
    """A reader that closes the pipe (`TOOL | head`) ends the tool quietly: status 141 and no
    traceback or 'Exception ignored' line (it printed a BrokenPipeError traceback; QA round
    16). The read end is closed before the tool starts, so every write fails."""
    series = os.path.join(tmp, "series_pipe")
    write_series(series, ranks=(1, 2))
    for args in (["anvil_vtu.py", outdir, outdir],
                 ["anvil_vtu.py", "--help"],
                 ["plot_figure2.py", series, "--table", "-o", f"{tmp}/pipe.png"],
                 ["plot_parallel_evidence.py", series, "--table", "-o", f"{tmp}/pipe.png"],
                 ["plot_history.py", outdir, "-o", f"{tmp}/pipe.png"],
                 ["corner_census.py", outdir]):
        read_end, write_end = os.pipe()
        os.close(read_end)
        try:
            r = subprocess.run([sys.executable, os.path.join(HERE, args[0])] + args[1:],
                               stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=300)
        finally:
            os.close(write_end)
        assert r.returncode == 141, f"{' '.join(args)}: exit {r.returncode}\n{r.stderr}"
        for word in ("Traceback", "Exception ignored", "BrokenPipe"):
            assert word not in r.stderr, f"{' '.join(args)}: {word}\n{r.stderr}"


def check_figures_documented():
    """Every PNG in docs/figures has the command that makes it in tools/README.md
    ("Regenerating all figures"; it covered 4 of 14, QA round 16). Skipped outside a
    source tree."""
    figures = os.path.join(HERE, os.pardir, "docs", "figures")
    if not os.path.isdir(figures):
        return
    with open(os.path.join(HERE, "README.md"), encoding="utf-8") as f:
        readme = f.read()
    section = readme[readme.index("**Regenerating all figures"):]
    missing = [n for n in sorted(os.listdir(figures))
               if n.endswith(".png") and f"-o docs/figures/{n}" not in section
               and f"--phases-output docs/figures/{n}" not in section]
    assert not missing, f"tools/README.md has no command for {missing}"


def check_scaling_usage():
    """tools/README.md's usage line of scaling_series.sh names every option its --help
    lists (it lacked --decomposition, --anvil, --mpirun and --mpi-args; QA round 16)."""
    r = subprocess.run(["bash", os.path.join(HERE, "scaling_series.sh"), "--help"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    options = [line.split()[0] for line in r.stdout.splitlines()
               if line.startswith("  --") and not line.startswith("  --help")]
    assert len(options) >= 13, options
    with open(os.path.join(HERE, "README.md"), encoding="utf-8") as f:
        readme = f.read()
    start = readme.index("**`scaling_series.sh ")
    usage = readme[start:readme.index("`**", start)]
    missing = [o for o in options if o not in usage]
    assert not missing, f"tools/README.md's scaling_series.sh usage lacks {missing}"


def check_executable():
    """Every tool with a #! line is executable (the docs run mpi_trace.py, corner_census.py
    and scaling_series.sh directly; the mode comes from git)."""
    for name in sorted(os.listdir(HERE)):
        path = os.path.join(HERE, name)
        if name.endswith((".py", ".sh")):
            with open(path, "rb") as f:
                if f.read(2) == b"#!":
                    assert os.access(path, os.X_OK), f"{path} has a #! line but is not executable"


def check_figure3(outdir, tmp):
    """plot_figure3.py on the synthetic run (both outputs; a time that is missing fails)."""
    run_tool(["plot_figure3.py", outdir, "--times", "0", "1e-5", "1e-5", "-o",
              f"{tmp}/fig3.png"], 0)
    check_png(os.path.join(tmp, "fig3.png"))
    run_tool(["plot_figure3.py", outdir, "--t0", outdir, "--times", "0", "0", "1e-5",
              "--cut", "y=1e-3", "-o", f"{tmp}/fig3b.png"], 0)
    run_tool(["plot_figure3.py", outdir, "-o", f"{tmp}/fig3c.png"], 2)  # no 1.6 ms output


def check_tools(outdir, tmp):
    """Every plot script writes a PNG, and fails with status 2 on bad input."""
    plots = [
        (["plot_history.py", outdir, "-o", f"{tmp}/energy.png"], "energy.png"),
        (["plot_decomposition.py", outdir, "-o", f"{tmp}/ranks.png"], "ranks.png"),
        (["plot_decomposition.py", outdir, "--step", "0", "--undeformed", "-o",
          f"{tmp}/ranks0.png"], "ranks0.png"),
        (["plot_decomposition.py", outdir, "--field", "plastic_strain", "--cut", "y=1e-3",
          "--elev", "-20", "-o", f"{tmp}/eps.png"], "eps.png"),
        (["plot_decomposition.py", outdir, "--field", "displacement.z", "--time", "1e-5",
          "-o", f"{tmp}/uz.png"], "uz.png"),
        (["plot_probe.py", outdir, "tip.uz", "tip.v*", "-o", f"{tmp}/probe.png"], "probe.png"),
        (["plot_probe.py", outdir, "tip.vz", "--x", "tip.uz", "--negate", "--negate-x", "-o",
          f"{tmp}/probe_x.png"], "probe_x.png"),
    ]
    for args, png in plots:
        run_tool(args, 0)
        check_png(os.path.join(tmp, png))
    missing = os.path.join(tmp, "no_such_dir")
    for bad in (["plot_history.py", missing],
                ["plot_decomposition.py", missing],
                ["plot_decomposition.py", outdir, "--field", "nope"],
                ["plot_decomposition.py", outdir, "--field", "stress"],
                ["plot_decomposition.py", outdir, "--step", "7"],
                ["plot_decomposition.py", outdir, "--time-tolerance", "-1"],
                ["plot_decomposition.py", outdir, "--cut", "w=0"],
                ["plot_probe.py", outdir, "nope.ux"],
                ["plot_probe.py", missing, "tip.ux"]):
        run_tool(bad, 2)


def check_time_tolerance(outdir, tmp):
    """--time farther than --time-tolerance from every output is exit status 2 naming the
    .pvd and the output times (it drew the last output; QA round 16), in plot_decomposition.py
    as in plot_figure3.py and corner_census.py; within the tolerance it draws."""
    pvd = os.path.join(outdir, "results.pvd")
    png = f"{tmp}/late.png"
    expect_usage_error(["plot_decomposition.py", outdir, "--time", "1", "-o", png],
                       pvd, "no output within 2e-05 s of t = 1 s", "0, 1e-05 s")
    assert not os.path.exists(png)
    expect_usage_error(["plot_decomposition.py", outdir, "--time", "1e-4",
                        "--time-tolerance", "5e-5", "-o", png], pvd, "5e-05 s")
    expect_usage_error(["corner_census.py", outdir, "--time", "1"], pvd, "no output within")
    run_tool(["plot_decomposition.py", outdir, "--time", "2e-5", "-o", png], 0)
    check_png(png)
    run_tool(["plot_decomposition.py", outdir, "--time", "1", "--time-tolerance", "2",
              "-o", png], 0)


def check_balance(tmp):
    """plot_history's balance error: E0 from summary.json, else the first row's E - W."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import plot_history  # noqa: E402 - the tool under test

    class H:  # a fixed node's initial kinetic energy (2 J of 12) booked as work at t=0
        data = {"total": np.array([10.0, 9.0, 8.0]), "external_work": np.array([-2.0, -3.0, -4.0])}

        def __getitem__(self, k):
            return self.data[k]

    h = H()
    e0 = plot_history.initial_energy(h, None)
    assert e0 == 12.0, e0
    assert np.allclose(plot_history.balance_error(h, e0), 0.0)
    e0 = plot_history.initial_energy(h, {"energy": {"initial": 12.3}})
    assert e0 == 12.3, e0
    assert np.allclose(plot_history.balance_error(h, e0), 0.3 / 12.3)


def check_mpi_trace(tmp):
    """mpi_trace.py on synthetic records: 3 cycles of (reduction, wait, wait), a message
    each; cycle and call counts, and exit status 2 on missing or foreign files."""
    import numpy as np
    rec = np.dtype([("t0", "f8"), ("t1", "f8"), ("site", "u8"), ("kind", "i4"),
                    ("bytes", "i4")])
    rows, t = [], 0.0
    for _ in range(4):
        for site, kind, size in ((0x10, 1, 0), (0x20, 7, 4096), (0x30, 3, 0), (0x30, 3, 0)):
            rows.append((t, t + 1e-6, site, kind, size))
            t += 1e-5
    np.array(rows, dtype=rec).tofile(f"{tmp}/tr.0.bin")
    r = run_tool(["mpi_trace.py", sys.executable, f"{tmp}/tr"], 0)
    assert "12 calls" in r.stdout and "cycles: 3" in r.stdout, r.stdout
    assert "3 cycles of 3 calls" in r.stdout, r.stdout
    assert "4096 / 4096" in r.stdout, r.stdout
    run_tool(["mpi_trace.py", sys.executable, f"{tmp}/none"], 2)
    with open(f"{tmp}/junk.0.bin", "wb") as f:
        f.write(b"\x07" * 64)
    run_tool(["mpi_trace.py", sys.executable, f"{tmp}/junk"], 2)


def main():
    """Build the synthetic run, run all checks, return the exit status."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--keep", action="store_true", help="keep the temporary directory")
    args = p.parse_args()
    tmp = tempfile.mkdtemp(prefix="anvil_tools_selftest_")
    try:
        outdir = os.path.join(tmp, "run")
        facts = write_run(outdir)
        c = Checks()
        c.run("reader: pvd, pvtu merge, arrays", check_reader, outdir, facts)
        c.run("reader: single .vtu piece", check_single_vtu, outdir, facts)
        c.run("exterior faces across pieces", check_exterior, outdir, facts)
        c.run("reader: malformed input errors", check_malformed, outdir, tmp)
        c.run("plot tools: PNGs and exit status 2", check_tools, outdir, tmp)
        c.run("plot_figure2 / plot_parallel_evidence on a synthetic series",
              check_series_tools, tmp)
        c.run("plot_figure3 on the synthetic run", check_figure3, outdir, tmp)
        c.run("plot_history: balance error against E0", check_balance, tmp)
        c.run("mpi_trace on synthetic records", check_mpi_trace, tmp)
        c.run("plot_particles: run, particles only, bad arguments", check_particles, outdir, tmp)
        c.run("summary.json of the wrong shape", check_summary_shapes, outdir, tmp)
        c.run("plot_rcb: PNG, missing file, JSON without its keys", check_rcb, tmp)
        c.run("anvil_vtu.py command line, Exodus-only run", check_vtu_cli, outdir, tmp)
        c.run("plot_parallel_evidence without contact bytes", check_no_contact_series, tmp)
        c.run("one-row history.csv: no matplotlib warning", check_one_row_history, outdir, tmp)
        c.run("--time outside the outputs: exit status 2", check_time_tolerance, outdir, tmp)
        c.run("a closed pipe (TOOL | head): quiet exit 141", check_broken_pipe, outdir, tmp)
        c.run("every figure in docs/figures has its command in tools/README.md",
              check_figures_documented)
        c.run("scaling_series.sh usage line in tools/README.md", check_scaling_usage)
        c.run("tools with #! are executable", check_executable)
    finally:
        if args.keep:
            print(f"kept {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    if c.failed:
        print(f"{len(c.failed)} check(s) failed: {', '.join(c.failed)}")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    from anvil_results import run_main  # noqa: E402

    run_main(main, "selftest.py")
