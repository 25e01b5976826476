#!/usr/bin/env bash
# Regenerates the reader tests' meshes in this folder (needs the Debian packages gmsh and
# libexodusii-dev). The files are checked in; run this only after changing a generator.
set -euo pipefail
cd "$(dirname "$0")"
gmsh -3 box_2x2x2.geo -o box_2x2x2.msh -format msh41 > /dev/null
gmsh -3 box_2x2x2.geo -o box_2x2x2_v22.msh -format msh22 > /dev/null
tmp=$(mktemp -d)
g++ -std=c++20 -O1 make_exodus.cpp -o "$tmp/make_exodus" -lexoIIv2c
"$tmp/make_exodus" .
rm -rf "$tmp"
/usr/bin/python3 make_corrupt_exodus.py # needs python3-netcdf4
