#!/usr/bin/env bash
# Erosion survives a restart (checkpoint format version 3 records each element's eroded
# flag): tests/data/decks/erosion_restart.yaml erodes 50 of its 64 elements by cycle 1000
# and the other 14 after it (18 in all before the centre Jacobian's sign counted as
# inversion, QA round 21).
#  1. the deck runs uninterrupted on 1 rank;
#  2. on 2 ranks it is stopped at cycle 1000, after the erosion, and restarted on 3;
# the final checkpoints must hold the same state bit for bit (eroded flags included), and
# both summaries count the 64 eroded elements, and the energy balance holds (2%). Before version 3 the restarted run brought
# the eroded elements back (it ended after 12,278 cycles instead of 13,337).
set -euo pipefail
anvil=$1
compare=$2
deck=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
run() { mpirun --oversubscribe -np "$@"; }

run 1 "$anvil" run "$deck" -o full -q
set +e
run 2 "$anvil" run "$deck" -o stopped -q --stop-at-cycle 1000 2>/dev/null
status=$?
set -e
[ "$status" -ne 0 ] || { echo "a stopped run must not exit 0"; exit 1; }
eroded() { /usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["eroded_elements"])' "$1"; }
[ "$(eroded stopped/summary.json)" = 50 ] ||
  { echo "the stopped run should have eroded 50 elements by cycle 1000, not $(eroded stopped/summary.json)"; exit 1; }
run 3 "$anvil" run "$deck" -o stopped -q --restart stopped/checkpoint.anvil
"$compare" full/checkpoint.anvil stopped/checkpoint.anvil
[ "$(eroded full/summary.json)" = 64 ] || { echo "the full run eroded $(eroded full/summary.json), not 64"; exit 1; }
[ "$(eroded stopped/summary.json)" = 64 ] || { echo "the restarted run eroded $(eroded stopped/summary.json), not 64"; exit 1; }
# The energy balance stays a number: an element that inverts and erodes does not count
# the increments of its last, inverted step (they were not finite, and the balance was
# NaN from the first erosion on). Measured 0.65% (0.77% with 18 eroded); the eroded elements take their energy
# with them but for that step, so the balance holds to about a percent: tolerance 2%.
/usr/bin/python3 - full/summary.json <<'PY'
import json, math, sys
b = json.load(open(sys.argv[1]))["energy"]["balance_error"]
if b is None or not math.isfinite(b) or abs(b) > 0.02:
    sys.exit(f"energy balance error {b}: expected finite and under 2%")
PY
echo "restart with erosion: identical state after stop on 2 ranks and restart on 3"
