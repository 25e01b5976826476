#!/usr/bin/env bash
# Restart with SPH particles reproduces the uninterrupted run bit for bit, on another
# number of ranks (tests/data/decks/sph_restart.yaml: particles in contact with a plate,
# plasticity, Johnson-Cook temperature, artificial stress, a prescribed velocity history):
#  1. the deck runs uninterrupted on 1 rank;
#  2. on 2 ranks it is stopped at cycle 150 (the path SIGTERM takes), and that checkpoint
#     is continued on 3 ranks and, separately, on 1;
# the final checkpoints (nodes, elements, particles), the history's times, steps and
# probe columns, results.pvd and particles.pvd must equal the uninterrupted run's.
# Last, a deck with another number of particles, or the same number elsewhere, must
# refuse the checkpoint (exit 2, naming the file).
set -euo pipefail
anvil=$1
compare=$2
deck_src=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cp "$deck_src" deck.yaml
run() { mpirun --oversubscribe -np "$@"; }

run 1 "$anvil" run deck.yaml -o full -q
set +e
run 2 "$anvil" run deck.yaml -o stopped -q --stop-at-cycle 150 2>/dev/null
status=$?
set -e
[ "$status" -ne 0 ] || { echo "a stopped run must not exit 0"; exit 1; }
cp -r stopped stopped1
run 3 "$anvil" run deck.yaml -o stopped -q --restart stopped/checkpoint.anvil
run 1 "$anvil" run deck.yaml -o stopped1 -q --restart stopped1/checkpoint.anvil
for d in stopped stopped1; do
  "$compare" full/checkpoint.anvil $d/checkpoint.anvil
  # Energies are sums over ranks (last bits may differ); times, steps and probes may not.
  cmp <(cut -d, -f1-3,10- full/history.csv) <(cut -d, -f1-3,10- $d/history.csv)
  cmp full/results.pvd $d/results.pvd
  cmp full/particles.pvd $d/particles.pvd
  grep -q '"status": "completed"' $d/summary.json
done

# The particle count of the deck must match the checkpoint's.
sed -e 's/radius: 3.0e-3, spacing: 6.0e-4/radius: 3.0e-3, spacing: 7.0e-4/' deck.yaml > other.yaml
cmp -s deck.yaml other.yaml && { echo "the deck edit did not apply"; exit 1; }
set +e
run 1 "$anvil" run other.yaml -o other -q --restart stopped1/checkpoint.anvil 2> other.err
status=$?
set -e
fail() { echo "$1"; cat other.err; exit 1; }
[ "$status" -eq 2 ] || fail "a mismatched checkpoint gave exit $status, not 2:"
grep -q "stopped1/checkpoint.anvil" other.err || fail "the error does not name the file:"
grep -q "particles" other.err || fail "the error does not mention particles:"
# So must its particles: the same count, the lattice moved (QA round 5: the run went on
# from the checkpoint's particles, the probes jumping by the move at the restart).
sed -e 's/center: \[0, 0, 0.0032\], radius: 3.0e-3/center: [0, 0, 0.0033], radius: 3.0e-3/' \
  deck.yaml > moved.yaml
cmp -s deck.yaml moved.yaml && { echo "the deck edit did not apply"; exit 1; }
set +e
run 2 "$anvil" run moved.yaml -o moved -q --restart stopped1/checkpoint.anvil 2> other.err
status=$?
set -e
[ "$status" -eq 2 ] || fail "a checkpoint of other particles gave exit $status, not 2:"
grep -q "written for other particles" other.err || fail "the error does not say why:"
echo "restart with particles: identical state after stop/restart on 2 -> 3 and 2 -> 1 ranks"
