#!/bin/bash
# End-to-end check of the particle outputs: runs a tiny FE/SPH deck on 2 ranks, checks
# summary.json (particles, imbalance.sph) and particles.pvd, and draws the particles
# with tools/plot_particles.py. Arguments: anvil binary, source directory, work directory.
set -euo pipefail
anvil=$1; src=$2; out=$3/sph_outputs
rm -rf "$out"
mpirun -np 2 --oversubscribe "$anvil" run "$src/tests/data/decks/sph_tiny.yaml" -o "$out" > /dev/null
/usr/bin/python3 - "$out" <<'PY'
import json, sys
s = json.load(open(sys.argv[1] + "/summary.json"))
assert s["status"] == "completed", s
assert s["particles"] == 136, s["particles"]
assert s["imbalance"]["sph"] >= 1.0 and "sph" in s, s
head = open(sys.argv[1] + "/history.csv").readline()
assert "top.uz" in head, head
PY
grep -q "particles_step_" "$out/particles.pvd"
/usr/bin/python3 "$src/tools/plot_particles.py" "$out" --steps 0,-1 -o "$out/particles.png"
/usr/bin/python3 "$src/tools/plot_particles.py" "$out" --field velocity.z -o "$out/vz.png"
if /usr/bin/python3 "$src/tools/plot_particles.py" "$out" --field nope -o "$out/x.png" 2> /dev/null; then
  echo "an unknown field was accepted"; exit 1
fi
test -s "$out/particles.png"
echo "sph outputs: ok"
