#!/usr/bin/python3
"""Exodus II output (src/anvil/io/exodus.hpp), read back with python3-netcdf4.

1. A 2-rank run with output.format both: one file per rank named results.exo.2.R, the
   field output times of results.pvd, and per time step the same values as the VTU output
   (joined by the global node and element ids): reference coordinates + displacement =
   VTU points, velocity, stress, von Mises, plastic strain, fe_rank. The node ids of the
   files cover the model's nodes, the elements sum to its element count.
2. A run killed with SIGKILL after some field outputs leaves files that read, with every
   recorded time step complete (finite values for every variable).

Usage: test_exodus_output.py --anvil BIN --mpiexec MPIEXEC --source DIR
"""
import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import netCDF4
import numpy as np

DECK = """title: exodus check
termination: {{cycles: {cycles}}}
materials:
  steel: {{model: j2_plasticity, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3,
          yield_stress: 0.3e9, hardening_modulus: 1.0e9}}
parts:
  block:
    mesh: {{generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.02], divisions: [4, 4, 8]}}
    material: steel
initial_conditions:
  - {{part: block, velocity: [0, 0, -200.0]}}
boundary_conditions:
  - {{set: block.zmin, fix: [z]}}
output: {{fields_every: {every}, format: {fmt}}}
"""


def names(var):
    return [str(netCDF4.chartostring(n)) for n in var[:]]


def read_exo(path):
    """Time values, node ids, reference coordinates, nodal and element variables
    (element values concatenated over blocks in block order), element ids."""
    with netCDF4.Dataset(path) as d:
        times = np.array(d["time_whole"][:])
        node_ids = np.array(d["node_num_map"][:])
        elem_ids = np.array(d["elem_num_map"][:])
        coords = np.stack([np.array(d[c][:]) for c in ("coordx", "coordy", "coordz")], axis=1)
        nodal = {n: np.array(d[f"vals_nod_var{i + 1}"][:]) for i, n in enumerate(names(d["name_nod_var"]))}
        nblk = len(d.dimensions["num_el_blk"])
        elem = {}
        for i, n in enumerate(names(d["name_elem_var"])):
            parts = []
            for b in range(nblk):
                key = f"vals_elem_var{i + 1}eb{b + 1}"
                if key in d.variables:
                    parts.append(np.array(d[key][:]))
            elem[n] = np.concatenate(parts, axis=1)
        blocks = names(d["eb_names"])
    return times, node_ids, coords, nodal, elem, elem_ids, blocks


def run(cmd, **kw):
    return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)


def check_against_vtu(args, work):
    sys.path.insert(0, os.path.join(args.source, "tools"))
    import anvil_vtu

    deck = os.path.join(work, "deck.yaml")
    with open(deck, "w") as f:
        f.write(DECK.format(cycles=120, every=2.0e-6, fmt="both"))
    out = os.path.join(work, "out")
    r = run([args.mpiexec, "-np", "2", "--oversubscribe", args.anvil, "run", deck, "-q", "-o", out])
    assert r.returncode == 0, r.stdout
    files = sorted(f for f in os.listdir(out) if f.startswith("results.exo"))
    assert files == ["results.exo.2.0", "results.exo.2.1"], files
    summary = json.load(open(os.path.join(out, "summary.json")))
    entries = anvil_vtu.read_pvd(os.path.join(out, "results.pvd"))
    assert len(entries) >= 3, len(entries)

    pieces = [read_exo(os.path.join(out, f)) for f in files]
    all_nodes = np.unique(np.concatenate([p[1] for p in pieces]))
    assert len(all_nodes) == summary["nodes"], (len(all_nodes), summary["nodes"])
    assert sum(len(p[5]) for p in pieces) == summary["elements"]
    for p in pieces:
        assert p[6] == ["block"], p[6]
        np.testing.assert_array_equal(p[0], [e.time for e in entries])

    worst = 0.0
    for step, entry in enumerate(entries):
        grid = anvil_vtu.read_pvtu(entry.path)
        vtu_node = {int(i): k for k, i in enumerate(grid.point_data["node_id"])}
        vtu_elem = {int(i): k for k, i in enumerate(grid.cell_data["element_id"])}
        for times, node_ids, coords, nodal, elem, elem_ids, _ in pieces:
            idx = np.array([vtu_node[int(i)] for i in node_ids])
            disp = np.stack([nodal[f"displacement_{c}"][step] for c in "xyz"], axis=1)
            vel = np.stack([nodal[f"velocity_{c}"][step] for c in "xyz"], axis=1)
            # The reference coordinates plus the displacement are the VTU points up to
            # round-off of (x - x0) + x0.
            np.testing.assert_allclose(coords + disp, grid.points[idx], rtol=0, atol=1e-15)
            np.testing.assert_array_equal(disp, grid.point_data["displacement"][idx])
            np.testing.assert_array_equal(vel, grid.point_data["velocity"][idx])
            eidx = np.array([vtu_elem[int(i)] for i in elem_ids])
            stress = np.stack([elem[f"stress_{c}"][step] for c in ("xx", "yy", "zz", "xy", "yz", "zx")], axis=1)
            np.testing.assert_array_equal(stress, grid.cell_data["stress"][eidx])
            for name in ("von_mises", "pressure", "plastic_strain", "fe_rank"):
                np.testing.assert_array_equal(elem[name][step], grid.cell_data[name][eidx])
            worst = max(worst, float(np.max(np.abs(disp))))
    assert worst > 1e-6, "nothing moved"
    print(f"exodus vs vtu: {len(entries)} steps on 2 ranks agree (largest displacement {worst:.3e} m)")


def check_killed_run(args, work):
    deck = os.path.join(work, "long.yaml")
    with open(deck, "w") as f:
        f.write(DECK.format(cycles=10000000, every=2.0e-7, fmt="exodus"))
    out = os.path.join(work, "killed")
    path = os.path.join(out, "results.exo")
    proc = subprocess.Popen([args.anvil, "run", deck, "-q", "-o", out],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 60
        steps = 0
        while time.time() < deadline and steps < 4:
            time.sleep(0.05)
            if proc.poll() is not None:
                raise AssertionError(f"anvil ended early with status {proc.returncode}")
            try:
                with netCDF4.Dataset(path) as d:
                    steps = len(d.dimensions["time_step"])
            except (OSError, KeyError, RuntimeError):
                steps = 0  # not created yet, or caught between header writes
        assert steps >= 4, f"only {steps} steps after 60 s"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    # Nothing of a step the kill interrupted: no fill values (netCDF4 masks them).
    with netCDF4.Dataset(path) as d:
        for name, var in d.variables.items():
            if name.startswith("vals_") or name == "time_whole":
                assert not np.ma.is_masked(var[:]), f"{name} holds fill values"
    times, node_ids, coords, nodal, elem, elem_ids, _ = read_exo(path)
    n = len(times)
    assert n >= 4, n
    assert np.all(np.diff(times) > 0), times
    for name, v in list(nodal.items()) + list(elem.items()):
        assert v.shape[0] == n, (name, v.shape)
        assert np.all(np.isfinite(v)), name
    print(f"killed run: {n} complete time steps read back")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--anvil", required=True)
    ap.add_argument("--mpiexec", required=True)
    ap.add_argument("--source", required=True)
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="anvil_exodus_")
    try:
        check_against_vtu(args, work)
        check_killed_run(args, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
