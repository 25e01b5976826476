#!/usr/bin/env bash
# A checkpoint that cannot continue the deck is refused on every rank, with exit status 2
# and a message naming the file, within seconds (never a hang, a crash, a physics failure
# or a silently different run):
#  - damaged (one flipped bit in a velocity), truncated, or followed by extra bytes;
#  - of a deck whose thick-shell part has other points through the thickness (found on
#    the ranks holding that part only: this hung on 2 ranks);
#  - of a deck without the thick shell, or whose termination comes before the checkpoint;
#  - of another mesh with the same numbers of nodes and elements;
#  - at the end of the deck's run (a finished run's final checkpoint: nothing to continue);
# and a checkpoint or a field piece that cannot be written stops the run with exit 2 and
# a failed summary.
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
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.04], divisions: [4, 4, 16]}
    material: steel
  plate:
    mesh: {generate: box, min: [0.02, 0, 0], max: [0.03, 0.01, 0.001], divisions: [2, 2, 1]}
    material: steel
    thick_shell: {points: 3}
initial_conditions:
  - {part: bar, velocity: [0, 0, -50.0]}
  - {part: plate, velocity: [0, 0, 50.0]}
EOF
run() { timeout 60 mpirun --oversubscribe -np "$@"; }

set +e
run 2 "$anvil" run deck.yaml -o first -q --stop-at-cycle 20 2>/dev/null
set -e
[ -f first/checkpoint.anvil ] || { echo "no checkpoint written"; exit 1; }

# Expects `anvil run DECK --restart CHECKPOINT` on 2 ranks to exit 2 saying FRAGMENT.
refused() {
  local deck=$1 checkpoint=$2 fragment=$3 status
  rm -rf out
  set +e
  run 2 "$anvil" run "$deck" -o out -q --restart "$checkpoint" 2> err.txt
  status=$?
  set -e
  # Refused before anything is written: no output directory is left behind.
  [ ! -e out ] || { echo "the refused restart of $deck left an output directory"; exit 1; }
  if [ "$status" -ne 2 ] || ! grep -q "$checkpoint" err.txt || ! grep -q -- "$fragment" err.txt; then
    echo "restart of $deck from $checkpoint: exit $status (expected 2 and '$fragment'):"
    cat err.txt
    exit 1
  fi
}

size=$(stat -c %s first/checkpoint.anvil)
# One flipped bit a third into the file (node data).
cp first/checkpoint.anvil flipped.anvil
offset=$((size / 3))
byte=$(od -An -tu1 -j "$offset" -N1 flipped.anvil | tr -d ' ')
printf "$(printf '\\%03o' $((byte ^ 4)))" | dd of=flipped.anvil bs=1 seek="$offset" conv=notrunc 2>/dev/null
refused deck.yaml flipped.anvil "is corrupt"
head -c $((size - 5)) first/checkpoint.anvil > short.anvil
refused deck.yaml short.anvil "is truncated"
{ cat first/checkpoint.anvil; echo garbage; } > long.anvil
refused deck.yaml long.anvil "bytes follow its end"

sed -e 's/points: 3/points: 5/' deck.yaml > points5.yaml
refused points5.yaml first/checkpoint.anvil "with thick_shell {points: 3} for element 257 (part plate, element 1 of the part), the deck gives thick_shell {points: 5}"
# Without the thick shell (QA round 12: accepted silently, its points' state dropped, or
# refused as "another mesh" where the thick shell had turned the elements).
grep -v "thick_shell" deck.yaml > no_shell.yaml
refused no_shell.yaml first/checkpoint.anvil "the deck gives no thick_shell: a part's thick_shell cannot change"
# A termination before the checkpoint (QA round 12: "completed" with a meaningless energy
# block and no final fields).
sed -e 's/cycles: 60/cycles: 10/' deck.yaml > short.yaml
refused short.yaml first/checkpoint.anvil "past the deck's termination (10 cycles)"
sed -e 's/divisions: \[4, 4, 16\]/divisions: [16, 4, 4]/' deck.yaml > other_mesh.yaml
refused other_mesh.yaml first/checkpoint.anvil "was written for another mesh"

# Expects `anvil run deck.yaml -o OUTDIR ARGS...` on 2 ranks to exit 2 naming FILE, with
# a failed summary naming it too (an output that cannot be written).
unwritable() {
  local outdir=$1 file=$2
  shift 2
  set +e
  run 2 "$anvil" run deck.yaml -o "$outdir" -q "$@" 2> err.txt
  local status=$?
  set -e
  if [ "$status" -ne 2 ] || ! grep -q "$file" err.txt; then
    echo "unwritable $file: exit $status (expected 2 naming the file):"; cat err.txt; exit 1
  fi
  grep -q '"status": "failed"' "$outdir/summary.json"
  grep -q "$file" "$outdir/summary.json"
}

# A checkpoint that cannot be written (its path taken by a directory) stops the run.
mkdir -p blocked/checkpoint.anvil
unwritable blocked checkpoint.anvil --stop-at-cycle 20

# A field piece that one rank cannot write (its temporary's path taken by a directory)
# stops every rank (alone, that rank left the other waiting: QA round 20), and
# results.pvd lists the complete outputs only.
mkdir -p piece/fields/step_000001_r0001.vtu.tmp/keep
unwritable piece step_000001_r0001.vtu.tmp
grep -q 'step_000000.pvtu' piece/results.pvd
if grep -q 'step_000001' piece/results.pvd; then echo "results.pvd names the failed output"; exit 1; fi

# The checkpoint itself still continues the run.
run 2 "$anvil" run deck.yaml -o first -q --restart first/checkpoint.anvil
grep -q '"status": "completed"' first/summary.json

# The final checkpoint of a finished run has nothing left to run with the same deck: it is
# refused, and the finished run's outputs are not rewritten (QA round 33: its summary.json
# was rewritten with time 0 and the initial kinetic energy).
sed -e 's/termination: {cycles: 60}/termination: {cycles: 60}\ncheckpoint: {cycles: 25}/' deck.yaml > done.yaml
run 2 "$anvil" run done.yaml -o done -q
cp done/summary.json done/summary.before
refused done.yaml done/checkpoint.anvil "nothing to continue"
set +e
run 2 "$anvil" run done.yaml -o done -q --restart done/checkpoint.anvil 2>/dev/null
status=$?
set -e
[ "$status" -eq 2 ] || { echo "an in-place restart at the end: exit $status"; exit 1; }
cmp -s done/summary.json done/summary.before || { echo "the refused restart rewrote summary.json"; exit 1; }
echo "damaged and mismatched checkpoints refused with exit 2 on 2 ranks"
