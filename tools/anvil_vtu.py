#!/usr/bin/python3
"""Read anvil's field outputs (.vtu pieces, .pvtu indices, results.pvd) without VTK.

anvil writes VTK XML unstructured grids (src/anvil/io/vtu.cpp): an XML header whose
DataArrays are all ``format="appended"``, then ``<AppendedData encoding="raw">``, a
``_`` marker and a binary blob in which every array is a UInt64 byte count followed by
the raw little-endian values (Float64, Int64 or UInt8).  A .pvtu lists the per-rank
pieces; results.pvd lists one .pvtu per field output with its time.

Public interface:
    read_vtu(path) -> Grid          one piece
    read_pvtu(path) -> Grid         all pieces of one output, concatenated
    read_grid(path) -> Grid         either of the above, by extension
    read_pvd(path) -> [PvdEntry]    the time series, sorted by time
    select_entry(entries, step=None, time=None, tolerance=None, source=None) -> PvdEntry
    load_output(outdir, step=None, time=None, tolerance=None) -> (PvdEntry, Grid)
    DEFAULT_TIME_TOLERANCE          2e-5 s, the tools' --time-tolerance default
    time_text(t) -> str             't=T', or 't unknown' for NaN
    exodus_hint(outdir) -> str      why OUTDIR has no results.pvd when it holds Exodus II

Run as a script (anvil_vtu.py OUTDIR|FILE ...), it lists the arrays of the last output
(for a run directory with particles, the last of results.pvd and of particles.pvd).
Every failure on malformed or missing input raises VtuError whose message names the file.
"""

import argparse
import glob
import os
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np

VTK_HEXAHEDRON = 12
# VTK's solid cells as anvil's hexahedra: which of the cell's points each corner is
# (the inverse of vtk_cell() in src/anvil/mesh/mesh.cpp).
_AS_HEXAHEDRON = {
    12: (0, 1, 2, 3, 4, 5, 6, 7),
    13: (0, 2, 1, 1, 3, 5, 4, 4),  # wedge: VTK a c b, d f e
    14: (0, 1, 2, 3, 4, 4, 4, 4),  # pyramid
    10: (0, 1, 2, 2, 3, 3, 3, 3),  # tetrahedron
}

_DTYPES = {
    "Float64": "f8",
    "Float32": "f4",
    "Int64": "i8",
    "Int32": "i4",
    "Int16": "i2",
    "Int8": "i1",
    "UInt64": "u8",
    "UInt32": "u4",
    "UInt16": "u2",
    "UInt8": "u1",
}


class VtuError(Exception):
    """Malformed, unsupported or missing VTK XML input; the message names the file."""


@dataclass
class Grid:
    """An unstructured grid: one piece, or several pieces concatenated.

    points       (n_points, 3) float64 coordinates (the current, deformed positions)
    cell_conn    (total,) int64 point indices of all cells, flat
    offsets      (n_cells,) int64 end of each cell in cell_conn
    cell_types   (n_cells,) uint8 VTK cell types (12 = hexahedron)
    point_data   name -> (n_points,) or (n_points, components) array
    cell_data    name -> (n_cells,) or (n_cells, components) array
    piece_of_cell (n_cells,) int piece index each cell came from (0 for one .vtu)
    sources      the files read, in piece order
    Points shared between pieces appear once per piece; point_data["node_id"] identifies them.
    """

    points: np.ndarray
    cell_conn: np.ndarray
    offsets: np.ndarray
    cell_types: np.ndarray
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)
    piece_of_cell: np.ndarray = None
    sources: list = field(default_factory=list)

    @property
    def n_points(self):
        """Number of points (duplicates across pieces included)."""
        return len(self.points)

    @property
    def n_cells(self):
        """Number of cells."""
        return len(self.cell_types)

    @property
    def connectivity(self):
        """(n_cells, 8) int64 point indices; raises VtuError unless every cell has 8 points."""
        sizes = np.diff(self.offsets, prepend=0)
        if self.n_cells and not np.all(sizes == 8):
            raise VtuError(f"{self._name()}: not all cells have 8 points")
        return self.cell_conn.reshape(-1, 8)

    def hexahedra(self):
        """Indices of the solid cells: VTK hexahedra (type 12), and the wedges (13),
        pyramids (14) and tetrahedra (10) anvil writes for hexahedra whose nodes repeat."""
        return np.flatnonzero(np.isin(self.cell_types, list(_AS_HEXAHEDRON)))

    def hex_connectivity(self):
        """(n_solid, 8) point indices of the solid cells as anvil's hexahedra (a wedge,
        pyramid or tetrahedron with repeated corners, src/anvil/mesh/mesh.hpp), and
        (n_solid,) their cell indices."""
        cells = self.hexahedra()
        conn = np.empty((len(cells), 8), dtype=np.int64)
        for vtk_type, corners in _AS_HEXAHEDRON.items():
            mine = self.cell_types[cells] == vtk_type
            starts = self.offsets[cells[mine]] - len(set(corners))
            conn[mine] = self.cell_conn[starts[:, None] + np.array(corners)[None, :]]
        return conn, cells

    def _name(self):
        return ", ".join(self.sources) if self.sources else "grid"


@dataclass
class PvdEntry:
    """One dataset of a .pvd collection: its time, index in time order and absolute path."""

    time: float
    step: int
    path: str


# --------------------------------------------------------------------------- parsing helpers


def _read_bytes(path):
    """Return the bytes of `path`, or raise VtuError naming it."""
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError as e:
        raise VtuError(f"{path}: cannot read ({e.strerror or e})") from None


def _parse_xml(path, text):
    """Parse XML text (bytes or str) into an Element, or raise VtuError naming `path`."""
    try:
        return ET.fromstring(text)
    except ET.ParseError as e:
        raise VtuError(f"{path}: malformed XML ({e})") from None


def _read_xml(path):
    """Parse the XML part of `path` (binary appended data cut off) -> root Element."""
    xml, _ = _split_appended(path, _read_bytes(path))
    return _parse_xml(path, xml)


def _int_attr(path, elem, name):
    """Non-negative integer attribute `name` of `elem`, or raise VtuError."""
    value = elem.get(name)
    try:
        n = int(value)
    except (TypeError, ValueError):
        raise VtuError(f"{path}: <{elem.tag}> has no valid {name} (got {value!r})") from None
    if n < 0:
        raise VtuError(f"{path}: <{elem.tag}> {name}={n} is negative")
    return n


def _check_root(path, root, expected_type):
    """Check the <VTKFile> root element and return (byte-order prefix, header dtype)."""
    if root.tag != "VTKFile":
        raise VtuError(f"{path}: root element is <{root.tag}>, expected <VTKFile>")
    if root.get("type") != expected_type:
        raise VtuError(f"{path}: VTKFile type is {root.get('type')!r}, expected {expected_type!r}")
    if root.get("compressor"):
        raise VtuError(f"{path}: compressed data ({root.get('compressor')}) is not supported")
    order = root.get("byte_order", "LittleEndian")
    if order not in ("LittleEndian", "BigEndian"):
        raise VtuError(f"{path}: unknown byte_order {order!r}")
    endian = "<" if order == "LittleEndian" else ">"
    header = root.get("header_type", "UInt32")
    if header not in ("UInt32", "UInt64"):
        raise VtuError(f"{path}: unsupported header_type {header!r}")
    return endian, np.dtype(endian + _DTYPES[header])


def _split_appended(path, data):
    """Split raw .vtu bytes into (XML header text, binary blob after the '_' marker)."""
    tag = data.find(b"<AppendedData")
    if tag < 0:
        return data, b""
    close = data.find(b">", tag)
    if close < 0:
        raise VtuError(f"{path}: unterminated <AppendedData> tag")
    opening = data[tag : close + 1].decode("ascii", "replace")
    if 'encoding="raw"' not in opening:
        raise VtuError(f"{path}: only raw appended data is supported, found {opening}")
    mark = data.find(b"_", close)
    if mark < 0 or data[close + 1 : mark].strip():
        raise VtuError(f"{path}: no '_' marker after <AppendedData>")
    xml = data[: close + 1] + b"</AppendedData></VTKFile>"
    return xml, data[mark + 1 :]


class _Arrays:
    """Decodes the DataArrays of one .vtu file from its appended blob (or inline ASCII)."""

    def __init__(self, path, blob, endian, header_dtype):
        self.path, self.blob, self.endian, self.header = path, blob, endian, header_dtype

    def read(self, elem, count, what):
        """Return the DataArray `elem` as an array of `count` tuples (1-D if 1 component)."""
        ncomp = 1
        if elem.get("NumberOfComponents") is not None:
            ncomp = _int_attr(self.path, elem, "NumberOfComponents")
        vtype = elem.get("type")
        if vtype not in _DTYPES:
            raise VtuError(f"{self.path}: {what}: unsupported type {vtype!r}")
        dtype = np.dtype(self.endian + _DTYPES[vtype])
        fmt = elem.get("format", "")
        if fmt == "appended":
            values = self._appended(elem, dtype, what)
        elif fmt == "ascii":
            values = self._ascii(elem, dtype, what)
        else:
            raise VtuError(f"{self.path}: {what}: unsupported format {fmt!r}")
        if values.size != count * ncomp:
            raise VtuError(
                f"{self.path}: {what}: {values.size} values, expected {count} x {ncomp} components"
            )
        values = values.astype(dtype.newbyteorder("="), copy=False)
        return values.reshape(count, ncomp) if ncomp > 1 else values

    def _appended(self, elem, dtype, what):
        offset = _int_attr(self.path, elem, "offset")
        hsize = self.header.itemsize
        if offset + hsize > len(self.blob):
            raise VtuError(
                f"{self.path}: {what}: offset {offset} is beyond the appended data "
                f"({len(self.blob)} bytes; truncated file?)"
            )
        nbytes = int(np.frombuffer(self.blob, self.header, 1, offset)[0])
        start = offset + hsize
        if start + nbytes > len(self.blob):
            raise VtuError(
                f"{self.path}: {what}: needs {nbytes} bytes at offset {start} but the appended "
                f"data has {len(self.blob)} (truncated file?)"
            )
        if nbytes % dtype.itemsize:
            raise VtuError(f"{self.path}: {what}: {nbytes} bytes is not a whole number of values")
        return np.frombuffer(self.blob, dtype, nbytes // dtype.itemsize, start)

    def _ascii(self, elem, dtype, what):
        try:
            return np.array((elem.text or "").split(), dtype=dtype.newbyteorder("="))
        except ValueError:
            raise VtuError(f"{self.path}: {what}: malformed ASCII values") from None


def _find(path, parent, tag):
    """The child `tag` of `parent`, or raise VtuError."""
    child = parent.find(tag)
    if child is None:
        raise VtuError(f"{path}: missing <{tag}> in <{parent.tag}>")
    return child


def _named_arrays(path, section, arrays, count, kind):
    """Decode every DataArray of a PointData/CellData section into a name -> array dict."""
    out = {}
    if section is None:
        return out
    for elem in section.findall("DataArray"):
        name = elem.get("Name")
        if not name:
            raise VtuError(f"{path}: a {kind} DataArray has no Name")
        if name in out:
            raise VtuError(f"{path}: duplicate {kind} array {name!r}")
        out[name] = arrays.read(elem, count, f"{kind} array {name!r}")
    return out


def _cells_array(path, cells, name, arrays, count):
    """Decode the Cells DataArray called `name`."""
    for elem in cells.findall("DataArray"):
        if elem.get("Name") == name:
            return arrays.read(elem, count, f"cells {name}")
    raise VtuError(f"{path}: <Cells> has no DataArray {name!r}")


# --------------------------------------------------------------------------- readers


def read_vtu(path):
    """Read one .vtu piece at `path` and return a Grid (see Grid for the arrays)."""
    data = _read_bytes(path)
    xml, blob = _split_appended(path, data)
    root = _parse_xml(path, xml)
    endian, header = _check_root(path, root, "UnstructuredGrid")
    grid_el = _find(path, root, "UnstructuredGrid")
    pieces = grid_el.findall("Piece")
    if len(pieces) != 1:
        raise VtuError(f"{path}: expected one <Piece>, found {len(pieces)}")
    piece = pieces[0]
    npts = _int_attr(path, piece, "NumberOfPoints")
    ncells = _int_attr(path, piece, "NumberOfCells")
    arrays = _Arrays(path, blob, endian, header)

    pts_el = _find(path, _find(path, piece, "Points"), "DataArray")
    points = arrays.read(pts_el, npts, "points").reshape(npts, 3).astype(np.float64)
    cells = _find(path, piece, "Cells")
    offsets = _cells_array(path, cells, "offsets", arrays, ncells).astype(np.int64)
    types = _cells_array(path, cells, "types", arrays, ncells).astype(np.uint8)
    total = int(offsets[-1]) if ncells else 0
    conn = _cells_array(path, cells, "connectivity", arrays, total).astype(np.int64)
    _check_cells(path, conn, offsets, npts)
    return Grid(
        points=points,
        cell_conn=conn,
        offsets=offsets,
        cell_types=types,
        point_data=_named_arrays(path, piece.find("PointData"), arrays, npts, "point"),
        cell_data=_named_arrays(path, piece.find("CellData"), arrays, ncells, "cell"),
        piece_of_cell=np.zeros(ncells, dtype=np.int64),
        sources=[path],
    )


def _check_cells(path, conn, offsets, npts):
    """Raise VtuError unless offsets increase and every point index is in range."""
    if len(offsets) and (np.any(np.diff(offsets, prepend=0) <= 0)):
        raise VtuError(f"{path}: cell offsets are not increasing")
    if len(conn) and (conn.min() < 0 or conn.max() >= npts):
        raise VtuError(
            f"{path}: connectivity refers to point {conn.max() if conn.max() >= npts else conn.min()}"
            f" but there are {npts} points"
        )


def read_pvtu(path):
    """Read a .pvtu and all its pieces; return one Grid with the pieces concatenated.

    Point indices are shifted per piece; piece_of_cell tells which piece a cell came from.
    Every piece must carry the point and cell arrays the .pvtu declares.
    """
    root = _read_xml(path)
    _check_root(path, root, "PUnstructuredGrid")
    grid_el = _find(path, root, "PUnstructuredGrid")
    declared = {
        kind: [a.get("Name") for a in grid_el.findall(f"{tag}/PDataArray")]
        for kind, tag in (("point", "PPointData"), ("cell", "PCellData"))
    }
    sources = [p.get("Source") for p in grid_el.findall("Piece")]
    if not sources or not all(sources):
        raise VtuError(f"{path}: no <Piece Source=...> entries")
    base = os.path.dirname(os.path.abspath(path))
    grids = []
    for src in sources:
        piece_path = src if os.path.isabs(src) else os.path.join(base, src)
        if not os.path.exists(piece_path):
            raise VtuError(f"{path}: piece {src!r} does not exist ({piece_path})")
        g = read_vtu(piece_path)
        for kind, names in declared.items():
            have = g.point_data if kind == "point" else g.cell_data
            missing = [n for n in names if n not in have]
            if missing:
                raise VtuError(f"{piece_path}: lacks {kind} arrays {missing} declared in {path}")
        grids.append(g)
    return merge_grids(grids)


def merge_grids(grids):
    """Concatenate Grids (pieces of one output) into one; keeps the arrays common to all."""
    if not grids:
        raise VtuError("no pieces to merge")
    shift = np.cumsum([0] + [g.n_points for g in grids[:-1]])
    cshift = np.cumsum([0] + [len(g.cell_conn) for g in grids[:-1]])
    common_p = [n for n in grids[0].point_data if all(n in g.point_data for g in grids)]
    common_c = [n for n in grids[0].cell_data if all(n in g.cell_data for g in grids)]
    return Grid(
        points=np.concatenate([g.points for g in grids]),
        cell_conn=np.concatenate([g.cell_conn + s for g, s in zip(grids, shift)]),
        offsets=np.concatenate([g.offsets + s for g, s in zip(grids, cshift)]),
        cell_types=np.concatenate([g.cell_types for g in grids]),
        point_data={n: np.concatenate([g.point_data[n] for g in grids]) for n in common_p},
        cell_data={n: np.concatenate([g.cell_data[n] for g in grids]) for n in common_c},
        piece_of_cell=np.concatenate([np.full(g.n_cells, i) for i, g in enumerate(grids)]),
        sources=[s for g in grids for s in g.sources],
    )


def read_grid(path):
    """Read a .vtu or .pvtu file (chosen by extension) and return a Grid."""
    if path.endswith(".pvtu"):
        return read_pvtu(path)
    if path.endswith(".vtu"):
        return read_vtu(path)
    raise VtuError(f"{path}: expected a .vtu or .pvtu file")


def read_pvd(path):
    """Read a .pvd collection; return PvdEntry list sorted by time (paths made absolute)."""
    root = _read_xml(path)
    _check_root(path, root, "Collection")
    sets = root.findall("Collection/DataSet")
    if not sets:
        raise VtuError(f"{path}: the collection lists no <DataSet>")
    base = os.path.dirname(os.path.abspath(path))
    rows = []
    for ds in sets:
        fname = ds.get("file")
        try:
            t = float(ds.get("timestep"))
        except (TypeError, ValueError):
            raise VtuError(f"{path}: DataSet {fname!r} has no valid timestep") from None
        if not fname:
            raise VtuError(f"{path}: a DataSet has no file attribute")
        rows.append((t, fname if os.path.isabs(fname) else os.path.join(base, fname)))
    rows.sort(key=lambda r: r[0])
    return [PvdEntry(time=t, step=i, path=p) for i, (t, p) in enumerate(rows)]


# Largest accepted distance [s] between a time asked for (--time, --times) and the output
# chosen for it, unless the tool's --time-tolerance says otherwise.
DEFAULT_TIME_TOLERANCE = 2e-5


def select_entry(entries, step=None, time=None, tolerance=None, source=None):
    """Pick one PvdEntry: by index `step` (negative counts from the end), by nearest `time`,
    or the last one when neither is given.  Raises VtuError for an out-of-range step, and
    for a `time` farther than `tolerance` seconds from every output (when a tolerance is
    given; the message starts with `source`, the .pvd, and lists the output times)."""
    if step is not None and time is not None:
        raise VtuError("give a step or a time, not both")
    if time is not None:
        entry = min(entries, key=lambda e: abs(e.time - time))
        if tolerance is not None and not abs(entry.time - time) <= tolerance:
            raise VtuError(f"{source or 'series'}: no output within {tolerance:g} s of "
                           f"t = {time:g} s (nearest {entry.time:.4g} s; outputs at "
                           f"{_output_times(entries)})")
        return entry
    if step is None:
        step = -1
    if not -len(entries) <= step < len(entries):
        raise VtuError(f"step {step} is out of range: the series has {len(entries)} outputs")
    return entries[step]


def _output_times(entries):
    """The times of a series for a message: all of them, or the range when there are many."""
    if len(entries) <= 8:
        return ", ".join(f"{e.time:.4g}" for e in entries) + " s"
    return f"{len(entries)} times from {entries[0].time:.4g} to {entries[-1].time:.4g} s"


def load_output(outdir, step=None, time=None, tolerance=None):
    """Read one field output of an anvil output directory (or a .pvd/.pvtu/.vtu path).

    Returns (PvdEntry, Grid); `step`, `time` and `tolerance` as in select_entry.  For a
    .pvtu/.vtu path the entry's time is NaN (unknown: only the .pvd records it).
    """
    if not os.path.exists(outdir):
        raise VtuError(f"{outdir}: no such file or directory")
    if os.path.isdir(outdir):
        pvd = os.path.join(outdir, "results.pvd")
        if not os.path.exists(pvd):
            hint = exodus_hint(outdir)
            if hint:
                raise VtuError(f"{outdir}: no results.pvd: {hint}")
            raise VtuError(f"{outdir}: no results.pvd (is this an anvil output directory?)")
    else:
        pvd = outdir
    if pvd.endswith(".pvd"):
        entry = select_entry(read_pvd(pvd), step=step, time=time, tolerance=tolerance,
                             source=pvd)
    else:
        entry = PvdEntry(time=float("nan"), step=0, path=pvd)
    return entry, read_grid(entry.path)


def time_text(t, sep="=", unit=""):
    """'t=T' (with `sep` and `unit`) for an output's time, or 't unknown' for NaN (a .pvtu
    or .vtu read directly: only the .pvd records the time)."""
    return f"t{sep}{t:g}{unit}" if np.isfinite(t) else "t unknown"


def exodus_hint(outdir):
    """A hint for a run directory without results.pvd that holds Exodus II files
    (output.format exodus: results.exo on one rank, results.exo.P.R on P ranks), else ''."""
    exo = sorted(glob.glob(os.path.join(outdir, "results.exo*")))
    if not exo:
        return ""
    return ("this run wrote Exodus II output (output.format); open "
            f"{os.path.basename(exo[0])} in ParaView, or rerun with --format vtu")


def outputs_to_list(arg):
    """[(label, PvdEntry, Grid)] that `anvil_vtu.py ARG` lists: for a run directory the last
    output of results.pvd and, when the run has particles, of particles.pvd (a run of
    particles only has an empty FE output); for a file, that file."""
    if not os.path.isdir(arg):
        return [(None,) + load_output(arg)]
    series = [n for n in ("results.pvd", "particles.pvd") if os.path.exists(os.path.join(arg, n))]
    if "results.pvd" not in series:
        if not series:
            load_output(arg)  # raises: no results.pvd (with the Exodus II hint)
        hint = exodus_hint(arg)
        print(f"note: {arg}: no results.pvd{': ' + hint if hint else ''}; listing particles.pvd",
              file=sys.stderr)
    out = []
    for name in series:
        path = os.path.join(arg, name)
        entries = read_pvd(path)
        entry = select_entry(entries)
        out.append((f"last of {len(entries)} in {name}", entry, read_grid(entry.path)))
    return out


def main(argv=None):
    """List the arrays of the last field output of each OUTDIR (results.pvd and, if present,
    particles.pvd) or file; raises VtuError on bad input (run_main: exit status 2)."""
    p = argparse.ArgumentParser(
        description="List the point and cell arrays of an anvil field output (for a run "
        "directory the last one of results.pvd and, when the run has particles, the last "
        "one of particles.pvd).",
        epilog="example: anvil_vtu.py out/taylor_bar_np3 out/taylor_bar_np3/fields/step_000000.pvtu",
    )
    p.add_argument("paths", nargs="+", metavar="OUTDIR|FILE",
                   help="anvil output directory, or a .pvd, .pvtu or .vtu file")
    args = p.parse_args(argv)
    for arg in args.paths:
        for label, e, g in outputs_to_list(arg):
            where = f" ({label})" if label else ""
            print(f"{e.path}{where}: {time_text(e.time)} points={g.n_points} cells={g.n_cells}")
            for kind, d in (("point", g.point_data), ("cell", g.cell_data)):
                for name, a in d.items():
                    print(f"  {kind:5s} {name:16s} {str(a.shape):14s} {a.dtype}")
    return 0


if __name__ == "__main__":
    # Run the imported module's main, so that its VtuError is the class run_main catches
    # (this file run as a script is a second module, __main__, with a VtuError of its own).
    import anvil_vtu
    from anvil_results import run_main

    run_main(anvil_vtu.main, "anvil_vtu.py")
