#!/usr/bin/env bash
# A restart continues the outputs of the run that wrote its checkpoint, and only those
# (QA round 12):
#  1. the deck's history columns changed (a probe added): history.csv starts at the
#     checkpoint, every row as wide as its header, and the earlier rows keep their own
#     header in history-before-sCYCLE.csv, with a warning (before: rows of two widths
#     under one header, which tools/plot_history.py refused);
#  2. a later run of another deck wrote over the checkpoint's directory: its rows and
#     fields are not taken as the checkpoint's run's; a warning, history.csv and the field
#     series start at the checkpoint (before: copied without a word);
#  3. the same deck run again over the directory is the same run: no warning, its rows
#     continue;
#  4. chained restarts into other directories list the earlier fields by normal paths
#     (`../a/fields/...`, not `../b/../a/fields/...`), every one of them readable;
#  5. and 6. below.
set -euo pipefail
anvil=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cat > deck.yaml <<'EOF'
termination: {cycles: 60}
materials:
  steel: {model: j2_plasticity, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3, yield_stress: 250.0e6, hardening_modulus: 1.0e9}
parts:
  bar:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.04], divisions: [2, 2, 8]}
    material: steel
initial_conditions:
  - {part: bar, velocity: [0, 0, -50.0]}
rigid_walls:
  - {point: [0, 0, -1.0e-4], normal: [0, 0, 1]}
probes:
  - {name: tip, at: [0, 0, 0]}
output: {fields_every: 1.0e-6}
EOF
run() { timeout 120 mpirun --oversubscribe -np "$@"; }
stop() { # run DECK on P ranks into DIR, stopped after cycle C
  set +e
  run "$1" "$anvil" run "$2" -o "$3" -q --stop-at-cycle "$4" 2>/dev/null
  set -e
  [ -f "$3/checkpoint.anvil" ] || { echo "no checkpoint in $3"; exit 1; }
}
widths() { # every row of DIR/history.csv has the header's number of fields
  /usr/bin/python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
bad = [i for i, r in enumerate(rows) if len(r) != len(rows[0])]
assert not bad, f"{sys.argv[1]}: rows {bad[:5]} differ in width from the header"
print(len(rows) - 1)
PY
}

# 1. A probe added on restart.
stop 2 deck.yaml a 20
sed -e 's/  - {name: tip, at: \[0, 0, 0\]}/&\n  - {name: top, at: [0, 0, 0.04]}/' deck.yaml > probe2.yaml
run 3 "$anvil" run probe2.yaml -o b -q --restart a/checkpoint.anvil 2> b.err
grep -q "history columns (probes, rigid walls, boundary conditions) differ" b.err || { cat b.err; exit 1; }
grep -q "history-before-s000020.csv" b.err
[ "$(widths b/history-before-s000020.csv)" -eq 20 ]
widths b/history.csv > /dev/null
head -1 b/history.csv | grep -q "top.ux"
/usr/bin/python3 - b <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1] + "/history.csv")))
assert int(rows[1][1]) == 20, rows[1][:2]  # it starts at the checkpoint's cycle
PY

# 2. A later run of another deck over the checkpoint's directory.
stop 2 deck.yaml c 20
cp c/checkpoint.anvil c/ck20.anvil
sed -e 's/velocity: \[0, 0, -50.0\]/velocity: [0, 0, -60.0]/' deck.yaml > faster.yaml
run 2 "$anvil" run faster.yaml -o c -q
run 2 "$anvil" run deck.yaml -o c -q --restart c/ck20.anvil 2> c.err
grep -q "is not the history of the run that wrote the checkpoint" c.err || { cat c.err; exit 1; }
/usr/bin/python3 - c <<'PY'
import csv, os, re, sys
rows = list(csv.reader(open(sys.argv[1] + "/history.csv")))
assert int(rows[1][1]) == 20, rows[1][:2]
files = re.findall(r'file="([^"]+)"', open(sys.argv[1] + "/results.pvd").read())
times = [float(t) for t in re.findall(r'timestep="([^"]+)"', open(sys.argv[1] + "/results.pvd").read())]
assert files and all(os.path.isfile(os.path.join(sys.argv[1], f)) for f in files), files
assert min(times) > 0, times  # the faster run's earlier fields are not listed
PY

# 3. The same deck run again over the directory: the same run, no warning.
stop 2 deck.yaml d 20
cp d/checkpoint.anvil d/ck20.anvil
run 2 "$anvil" run deck.yaml -o d -q
rows=$(widths d/history.csv)
run 2 "$anvil" run deck.yaml -o d -q --restart d/ck20.anvil 2> d.err
if grep -q "warning" d.err; then cat d.err; exit 1; fi
[ "$(widths d/history.csv)" -eq "$rows" ]

# 4. A chain a -> e -> f into other directories.
rm -rf a && stop 1 deck.yaml a 20
set +e
run 3 "$anvil" run deck.yaml -o e -q --restart a/checkpoint.anvil --stop-at-cycle 40 2>/dev/null
set -e
run 2 "$anvil" run deck.yaml -o f -q --restart e/checkpoint.anvil
/usr/bin/python3 - f <<'PY'
import os, re, sys
files = re.findall(r'file="([^"]+)"', open(sys.argv[1] + "/results.pvd").read())
assert any(f.startswith("../a/") for f in files), files
assert not any(re.search(r"[^./]/\.\./", f) for f in files), files
assert all(os.path.isfile(os.path.join(sys.argv[1], f)) for f in files), files
PY
# 5. A run ended by its cycle limit, continued with a longer one (QA rounds 29, 30): the
#    first run's end-of-run row, off the history series, is not kept; the continued
#    history is the uninterrupted run's, row for row.
sed -e 's/termination: {cycles: 60}/termination: {cycles: 28}\ncheckpoint: {every: 1.0}/' \
    -e 's/output: {fields_every: 1.0e-6}/output: {fields_every: 1.0e-6, history_every: 2.5e-6}/' \
    deck.yaml > short.yaml
sed -e 's/output: {fields_every: 1.0e-6}/output: {fields_every: 1.0e-6, history_every: 2.5e-6}/' \
    deck.yaml > long.yaml
run 1 "$anvil" run short.yaml -o g -q
run 2 "$anvil" run long.yaml -o h -q --restart g/checkpoint.anvil
run 3 "$anvil" run long.yaml -o i -q
/usr/bin/python3 - g h i <<'PY'
import csv, sys
g, h, i = (list(csv.reader(open(d + "/history.csv")))[1:] for d in sys.argv[1:])
cycles = lambda rows: [r[1] for r in rows]
assert cycles(h) == cycles(i), (cycles(h), cycles(i))
assert [r[:3] for r in h] == [r[:3] for r in i]  # time, cycle, dt: the same bits
assert cycles(g)[-1] not in cycles(i), cycles(g)  # the short run's end row is off the series
PY
# 6. summary.json's balance_error is scaled by the largest energy of the run (QA round 31:
#    a body driven and brought back to rest read 1.0, its round-off over energies of
#    0): about 0 here, and the same bits after a restart (on the same rank count: energies
#    are MPI sums, docs/cycle.md) from cycle 150, past the spin's end, whose scale comes
#    from the earlier rows of the checkpoint's history.
cat > driven.yaml <<'EOF'
termination: {time: 3.0e-5}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  wheel:
    mesh: {generate: box, min: [-0.01, -0.01, 0], max: [0.01, 0.01, 0.004], divisions: [4, 4, 1]}
    material: steel
    rigid: true
  far:
    mesh: {generate: box, min: [0.1, 0.1, 0.1], max: [0.102, 0.102, 0.102], divisions: [1, 1, 1]}
    material: steel
boundary_conditions:
  - {part: wheel, fix: all}
  - {part: wheel, velocity: [0, 0, 2.0], components: [z], birth: 5.0e-6, death: 1.5e-5}
  - {part: wheel, angular_velocity: [0, 0, 500.0], components: [rz], birth: 1.0e-5, death: 2.0e-5}
  - {part: wheel, displacement: [1.0e-4, 0, 0], components: [x], curve: [[0, 0], [1.0e-5, 0], [2.5e-5, 1]]}
EOF
run 1 "$anvil" run driven.yaml -o j -q
stop 1 driven.yaml k 150
run 1 "$anvil" run driven.yaml -o k -q --restart k/checkpoint.anvil
/usr/bin/python3 - j k <<'PY'
import json, sys
j, k = (json.load(open(d + "/summary.json"))["energy"] for d in sys.argv[1:])
assert j["balance_error"] < 1e-12, j  # (1.0 before: total 0, external work 1e-16)
assert j["balance_error"] == k["balance_error"], (j, k)
PY
echo "restart outputs: changed columns kept apart, a later run's outputs not taken, paths normal, no end-of-run row kept, the balance scaled by the run's energies"
