#!/usr/bin/env bash
# Restart reproduces the uninterrupted run bit for bit, on another number of ranks:
#  1. the can crush (contact, self-contact, prescribed block: its velocity slows along a
#     time history through the restart, so that the curve is taken up mid-way; a ramped
#     pressure and nodal forces) runs uninterrupted on 1 rank;
#  2. on 2 ranks it is stopped at cycle 700 (the path SIGTERM takes) and restarted on 3,
#     into another output directory (whose history and field series must continue the
#     stopped run's: the same rows as the uninterrupted run, every series entry readable);
#  3. on 2 ranks it is killed with a real SIGTERM while running, restarted on 4;
# the final checkpoints of 2 and 3 must hold the same state as 1's, bit for bit.
set -euo pipefail
anvil=$1
compare=$2
deck_src=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
sed -e 's/termination: {time: 3.2e-3}/termination: {time: 2.5e-4}/' \
    -e 's/velocity: \[0, 0, -10.0\]}/velocity: [0, 0, -10.0], curve: [[0, 1], [2.5e-4, 0.5]]}/' \
    "$deck_src" > deck.yaml
grep -q "termination: {time: 2.5e-4}" deck.yaml || { echo "the deck edit did not apply"; exit 1; }
grep -q "curve: \[\[0, 1\], \[2.5e-4, 0.5\]\]" deck.yaml || { echo "the curve edit did not apply"; exit 1; }
echo "checkpoint: {every: 5.0e-5}" >> deck.yaml
# External loads ramped through the restart (a pressure on the can's outside, forces on its
# rim): nothing of them is in the checkpoint, all of it follows from the time and state.
printf 'loads:\n  - {surface: can.outer, pressure: 2.0e5, curve: [[0, 0], [2.5e-4, 1]]}\n  - {set: can.top, force: [0, 0, -0.5]}\n' >> deck.yaml
run() { mpirun --oversubscribe -np "$@"; }

run 1 "$anvil" run deck.yaml -o full -q
set +e
run 2 "$anvil" run deck.yaml -o stopped -q --stop-at-cycle 700 2>stopped.err
status=$?
set -e
[ "$status" -ne 0 ] || { echo "a stopped run must not exit 0"; exit 1; }
# It stops once cycle 700 is done, not one cycle later.
grep -q "(cycle 700)" stopped.err || { cat stopped.err; exit 1; }
grep -q '"status": "stopped"' stopped/summary.json
run 3 "$anvil" run deck.yaml -o elsewhere -q --restart stopped/checkpoint.anvil
"$compare" full/checkpoint.anvil elsewhere/checkpoint.anvil
/usr/bin/python3 - full elsewhere <<'PY'
import csv, os, re, sys
full, other = sys.argv[1], sys.argv[2]
rows = lambda d: [r[:2] for r in csv.reader(open(os.path.join(d, "history.csv")))]
assert rows(full) == rows(other), "the restarted history's (time, cycle) rows differ"
pvd = open(os.path.join(other, "results.pvd")).read()
files = re.findall(r'file="([^"]+)"', pvd)
assert len(files) == len(re.findall(r'file="', open(os.path.join(full, "results.pvd")).read()))
missing = [f for f in files if not os.path.isfile(os.path.join(other, f))]
assert not missing, missing
PY
# A checkpoint copied alone elsewhere: the restart says what it lacks, and lists only
# field files that exist.
mkdir lone && cp stopped/checkpoint.anvil lone/
run 2 "$anvil" run deck.yaml -o lone_out -q --restart lone/checkpoint.anvil 2> lone.err
grep -q "history.csv starts at the checkpoint" lone.err || { cat lone.err; exit 1; }
grep -q "results.pvd's outputs before the checkpoint are not in" lone.err
/usr/bin/python3 - lone_out <<'PY'
import os, re, sys
files = re.findall(r'file="([^"]+)"', open(os.path.join(sys.argv[1], "results.pvd")).read())
assert files and all(os.path.isfile(os.path.join(sys.argv[1], f)) for f in files), files
PY

# A real SIGTERM, mid-run, delivered to the ranks as a batch system delivers it (Slurm's
# scancel signals every task). mpirun forwards a SIGTERM of its own only after about half
# a second here, longer than this whole run lasts (QA round 19: the run completed and the
# check passed without testing the handler). mpirun goes to the background, not the `run`
# function: a function in the background is a subshell, which would leave mpirun
# orphaned, writing into killed/ while the restart reads it.
mpirun --oversubscribe -np 2 "$anvil" run deck.yaml -o killed -q 2>killed.err &
pid=$!
# Wait for the first periodic checkpoint (20% into the run), however loaded the machine:
# a signal that came before the handlers are installed would kill the run outright.
for _ in $(seq 1 4000); do
  [ -f killed/checkpoint.anvil ] && break
  sleep 0.05
done
ranks=$(cat /proc/"$pid"/task/*/children)
[ -n "$ranks" ] || { echo "no rank processes under mpirun $pid"; exit 1; }
kill -TERM $ranks
set +e
wait "$pid"
status=$?
set -e
# The signal comes at the first of five checkpoints: the run cannot have finished. It
# must have stopped through the handler (its message, "stopped" in the summary), not by
# the signal's default action, which would leave the periodic checkpoint to restart from
# all the same (QA round 19).
[ "$status" -ne 0 ] || { echo "the run finished before the signal: the SIGTERM path was not tested"; exit 1; }
grep -q "anvil: stopped by signal 15" killed.err || { echo "no checkpoint-and-stop on SIGTERM"; cat killed.err; exit 1; }
grep -q '"status": "stopped"' killed/summary.json
run 4 "$anvil" run deck.yaml -o killed -q --restart killed/checkpoint.anvil
"$compare" full/checkpoint.anvil killed/checkpoint.anvil
# The outputs of the restarted run are complete and readable.
grep -q '"status": "completed"' killed/summary.json
grep -q 'step_' killed/results.pvd
# Each phase's seconds per rank: one entry for each of the restarted run's 3 or 4 ranks.
for d in elsewhere killed; do
  test -f "$d/summary.json"
  /usr/bin/python3 - "$d/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
by_rank = s["timers_by_rank"]
assert set(by_rank) == set(s["timers"]), by_rank.keys()
for phase, seconds in by_rank.items():
    assert len(seconds) == s["ranks"], (phase, seconds)
    assert max(seconds) == s["timers"][phase], (phase, seconds, s["timers"][phase])
PY
done
echo "restart: identical state after stop/restart on 2 -> 3 (another directory) and SIGTERM/restart on 2 -> 4 ranks"
