#!/usr/bin/python3
"""Writes the corrupt Exodus II files that tests/unit/test_readers.cpp reads: copies of
box_2x2x2.exo with one defect each that the Exodus library itself does not survive (it
writes past fixed-size buffers), made with python3-netcdf4:
  bad_attr_array.exo      the global attribute maximum_name_length holds 100 values
  bad_int64_status.exo    the global attribute int64_status holds 200 values
  bad_elem_type.exo       the element type of the first block is 3000 characters long
  bad_degenerate_hex.exo  the first element (id 500) names node 13 twice (N7 and N8): a
                          well-formed file the reader must refuse as a degenerate hexahedron
(bad_set_shape.exo, a side set variable larger than its count, is an input the fuzzer
found; it is checked in as found.) Run from this folder: /usr/bin/python3 make_corrupt_exodus.py
"""
import shutil

import netCDF4
import numpy as np

CASES = {
    "bad_attr_array.exo": lambda d: d.setncattr("maximum_name_length", np.arange(100, dtype="i4") + 32),
    "bad_int64_status.exo": lambda d: d.setncattr("int64_status", np.zeros(200, dtype="i4")),
    "bad_elem_type.exo": lambda d: d["connect1"].setncattr("elem_type", "HEX8" + "x" * 2996),
    "bad_degenerate_hex.exo": lambda d: d["connect1"].__setitem__((0, 6), 13),
}

for name, damage in CASES.items():
    shutil.copy("box_2x2x2.exo", name)
    with netCDF4.Dataset(name, "a") as d:
        damage(d)
