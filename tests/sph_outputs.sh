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

# Exodus output (QA round 5): a rank that holds no element (one element on 2 ranks) writes
# its piece, and a model of particles only writes particles.pvd and says there is no
# Exodus file; both ran into an Exodus library error and exit 2.
sed -e 's/divisions: \[4, 4, 1\]/divisions: [1, 1, 1]/' "$src/tests/data/decks/sph_tiny.yaml" \
  > "$out/one.yaml"
mpirun -np 2 --oversubscribe "$anvil" run "$out/one.yaml" -o "$out/one" -q --format exodus
# (One check per line: `set -e` does not stop at a failure before the last command of an
# && list, nor at a command negated with !; QA round 19.)
test -s "$out/one/results.exo.2.0"
test -s "$out/one/results.exo.2.1"
grep -q '"status": "completed"' "$out/one/summary.json"
sed -e '/^parts:/,/material: steel$/d' -e '/^contact:/,+1d' \
  "$src/tests/data/decks/sph_tiny.yaml" > "$out/ponly.yaml"
grep -q "^parts:" "$out/ponly.yaml" && { echo "the deck edit did not apply"; exit 1; }
mpirun -np 2 --oversubscribe "$anvil" run "$out/ponly.yaml" -o "$out/ponly" -q --format exodus \
  2> "$out/ponly.err"
grep -q "no Exodus II file is written" "$out/ponly.err" || { cat "$out/ponly.err"; exit 1; }
grep -q "particles_step_" "$out/ponly/particles.pvd"
if compgen -G "$out/ponly/results.exo*" > /dev/null; then
  echo "an Exodus file was written for a particles-only model"
  exit 1
fi
# Particle temperature (QA round 18: not written): a Johnson-Cook ball heats on impact, and
# particles.pvd lists `temperature` (absent for the elastic ball above).
fields=$(/usr/bin/python3 "$src/tools/anvil_vtu.py" "$out/particles.pvd")
grep -q "plastic_strain" <<< "$fields" # (the listing worked)
if grep -q "temperature" <<< "$fields"; then
  echo "temperature listed for an elastic ball"
  exit 1
fi
sed -e 's/^  steel: .*/&\n  jc: {model: johnson_cook, density: 7830, youngs_modulus: 200.0e9, poissons_ratio: 0.29, A: 3.0e8, B: 5.0e8, n: 0.3, melt_temperature: 1800, specific_heat: 450}/' \
  -e 's/         material: steel}/         material: jc}/' -e 's/cycles: 40/cycles: 150/' \
  "$src/tests/data/decks/sph_tiny.yaml" > "$out/jc.yaml"
grep -q "material: jc}" "$out/jc.yaml" || { echo "the deck edit did not apply"; exit 1; }
mpirun -np 2 --oversubscribe "$anvil" run "$out/jc.yaml" -o "$out/jc" -q
/usr/bin/python3 - "$src/tools" "$out/jc" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
from anvil_vtu import read_pvd, read_grid
last = read_pvd(sys.argv[2] + "/particles.pvd")[-1]
t = read_grid(last.path).point_data["temperature"]
assert t.min() >= 293.0 and t.max() > 293.0, (t.min(), t.max())
PY
echo "sph outputs: ok"
