#!/usr/bin/env bash
# Run the paper's scaled can crush (DESIGN.md section 5) at P = 1, 2, 4, 8, ... ranks.
#
# Each run is `mpirun -np P --oversubscribe anvil bench can-crush --cycles C` into
# OUTROOT/P<P>/ (summary.json, history.csv, results.pvd, plus run.log with anvil's output,
# time.txt with the elapsed/user/system seconds of the whole mpirun and deck.yaml, the
# deck for that rank count).  OUTROOT/machine.json
# records the machine (nproc, CPU model, load average), the anvil build and the options;
# OUTROOT/runs.tsv has one line per run.  The machine may be shared: the load average before
# each run is recorded, and --repeat N keeps the fastest of N runs of each rank count.  Runs with more ranks than cores are allowed
# (--oversubscribe) but their timings are not scaling data: the ranks time-share the cores.
# tools/plot_figure2.py and tools/plot_parallel_evidence.py read OUTROOT.
#
# A failed run is recorded (status column of runs.tsv, run.log kept) and the series goes on;
# the script then exits with status 1.  Bad arguments give status 2.

set -u -o pipefail

usage() {
  cat <<'EOF'
usage: scaling_series.sh [options] OUTROOT

Runs `anvil bench can-crush` at P = MIN, 2*MIN, ..., MAX ranks into OUTROOT/P<P>/.

options:
  --max-ranks P          largest rank count, a power of two times --min-ranks (default 8)
  --min-ranks P          first rank count (default 1)
  --ranks "P1 P2 ..."    explicit list of rank counts instead of the doubling series
  --cycles C             cycles per run (default 300; 0 would be a setup-only run)
  --elements-per-rank N  one-rank model size, passed to anvil (default: anvil's, 1875)
  --decomposition D      paper (default) or sectors, passed to anvil (docs/benchmark.md)
  --full                 run each problem to 3.2 ms instead of --cycles (slow)
  --anvil PATH           anvil executable (default: build/apps/anvil next to tools/)
  --mpirun CMD           MPI launcher (default: mpirun)
  --mpi-args "ARGS"      extra launcher arguments (default: "--bind-to none"; Open MPI
                         then polls while a rank waits when the ranks fit the cores and
                         yields the core when they do not. On a machine busy with other
                         work add "--mca mpi_yield_when_idle 1": a rank that polls there
                         starves its partner, and P = 2 looks 3-6x slower)
  --repeat N             run each rank count N times and keep the fastest (least
                         grind time) in P<P>/, the others in P<P>/rep<k>/ (default 1)
  --timeout SEC          kill a run after SEC seconds (default: none)
  --no-fields            delete OUTROOT/P<P>/fields and results.pvd after each run
  -h, --help             this text

examples:
  tools/scaling_series.sh --max-ranks 8 --cycles 1000 out/scaling
  tools/scaling_series.sh --ranks "16 32 64" --cycles 30 --no-fields out/scaling_big
EOF
}

die() { echo "scaling_series.sh: error: $*" >&2; exit 2; }

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
anvil="$here/../build/apps/anvil"
mpirun_cmd=mpirun
mpi_args="--bind-to none"
min_ranks=1
max_ranks=8
ranks_list=""
cycles=300
epr=""
decomposition=""
full=0
timeout_s=""
repeat=1
keep_fields=1
outroot=""

is_uint() { [[ "$1" =~ ^[0-9]+$ ]]; }

while [ $# -gt 0 ]; do
  case "$1" in
    --max-ranks) [ $# -ge 2 ] || die "$1 needs a value"; max_ranks=$2; shift 2 ;;
    --min-ranks) [ $# -ge 2 ] || die "$1 needs a value"; min_ranks=$2; shift 2 ;;
    --ranks) [ $# -ge 2 ] || die "$1 needs a value"; ranks_list=$2; shift 2 ;;
    --cycles) [ $# -ge 2 ] || die "$1 needs a value"; cycles=$2; shift 2 ;;
    --elements-per-rank) [ $# -ge 2 ] || die "$1 needs a value"; epr=$2; shift 2 ;;
    --decomposition) [ $# -ge 2 ] || die "$1 needs a value"; decomposition=$2; shift 2 ;;
    --full) full=1; shift ;;
    --anvil) [ $# -ge 2 ] || die "$1 needs a value"; anvil=$2; shift 2 ;;
    --mpirun) [ $# -ge 2 ] || die "$1 needs a value"; mpirun_cmd=$2; shift 2 ;;
    --mpi-args) [ $# -ge 2 ] || die "$1 needs a value"; mpi_args=$2; shift 2 ;;
    --repeat) [ $# -ge 2 ] || die "$1 needs a value"; repeat=$2; shift 2 ;;
    --timeout) [ $# -ge 2 ] || die "$1 needs a value"; timeout_s=$2; shift 2 ;;
    --no-fields) keep_fields=0; shift ;;
    -h|--help) usage; exit 0 ;;
    -*) usage >&2; die "unknown option $1" ;;
    *) [ -z "$outroot" ] || die "more than one OUTROOT ($outroot, $1)"; outroot=$1; shift ;;
  esac
done

[ -n "$outroot" ] || { usage >&2; die "OUTROOT is required"; }
is_uint "$cycles" || die "--cycles expects a non-negative integer, got '$cycles'"
[ -z "$epr" ] || is_uint "$epr" || die "--elements-per-rank expects an integer, got '$epr'"
case "$decomposition" in ""|paper|sectors) ;; *) die "--decomposition expects paper or sectors, got '$decomposition'" ;; esac
is_uint "$repeat" && [ "$repeat" -ge 1 ] || die "--repeat expects N >= 1, got '$repeat'"
[ -z "$timeout_s" ] || is_uint "$timeout_s" || die "--timeout expects seconds, got '$timeout_s'"
[ -x "$anvil" ] || die "$anvil: no executable (build it: cmake --build build -j2 --target anvil)"
command -v "$mpirun_cmd" >/dev/null || die "$mpirun_cmd: launcher not found"
"$anvil" bench can-crush --help >/dev/null 2>&1 || die "$anvil: no 'bench can-crush' subcommand"

if [ -n "$ranks_list" ]; then
  ranks=()
  for p in $ranks_list; do
    is_uint "$p" && [ "$p" -ge 1 ] || die "--ranks expects positive integers, got '$p'"
    ranks+=("$p")
  done
else
  is_uint "$min_ranks" && [ "$min_ranks" -ge 1 ] || die "--min-ranks expects P >= 1"
  is_uint "$max_ranks" && [ "$max_ranks" -ge "$min_ranks" ] ||
    die "--max-ranks expects P >= --min-ranks ($min_ranks), got '$max_ranks'"
  ranks=()
  p=$min_ranks
  while [ "$p" -le "$max_ranks" ]; do ranks+=("$p"); p=$((p * 2)); done
fi

# Running as root needs Open MPI's consent; oversubscription is allowed explicitly.
if [ "$(id -u)" = 0 ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fi
export OMPI_MCA_rmaps_base_oversubscribe=1

cores=$(nproc)
cpu_model=$(sed -n 's/^model name[[:space:]]*:[[:space:]]*//p' /proc/cpuinfo | head -n 1)
json_str() { printf '%s' "$1" | sed -e 's/\\/\\\\/g' -e 's/"/\\"/g'; }
loadavg() { cut -d' ' -f1-3 /proc/loadavg; }

mkdir -p "$outroot" || die "$outroot: cannot create"
version=$("$anvil" --version 2>/dev/null | head -n 1)
commit=$(git -C "$here/.." rev-parse --short HEAD 2>/dev/null || echo unknown)
ranks_json=$(printf '%s,' "${ranks[@]}"); ranks_json="[${ranks_json%,}]"
cat >"$outroot/machine.json" <<EOF
{
  "nproc": $cores,
  "cpu_model": "$(json_str "$cpu_model")",
  "hostname": "$(json_str "$(hostname)")",
  "date": "$(date -u +%Y-%m-%dT%H:%M:%SZ)",
  "loadavg_start": "$(loadavg)",
  "anvil": "$(json_str "$anvil")",
  "anvil_version": "$(json_str "$version")",
  "git_commit": "$commit",
  "mpirun": "$(json_str "$("$mpirun_cmd" --version 2>/dev/null | head -n 1)")",
  "mpi_args": "$(json_str "--oversubscribe $mpi_args")",
  "ranks": $ranks_json,
  "cycles": $([ "$full" = 1 ] && echo null || echo "$cycles"),
  "elements_per_rank": ${epr:-1875},
  "decomposition": "${decomposition:-paper}",
  "repeat": $repeat
}
EOF

echo "scaled can crush: P = ${ranks[*]}, $([ "$full" = 1 ] && echo "to 3.2 ms" || echo "$cycles cycles"), $cores cores ($cpu_model), load $(loadavg)"
over=()
for p in "${ranks[@]}"; do [ "$p" -gt "$cores" ] && over+=("$p"); done
if [ ${#over[@]} -gt 0 ]; then
  echo "note: P = ${over[*]} run more ranks than the $cores cores (oversubscribed); their timings"
  echo "      measure time-sharing, not parallel scaling. Only P <= $cores is scaling data."
fi

printf 'ranks\trep\telements\tcycles\tstatus\telapsed_s\tuser_s\tsys_s\tgrind_us\tloadavg_before\toversubscribed\n' \
  >"$outroot/runs.tsv"

# run_one P DIR REP: one mpirun into DIR; appends to runs.tsv; sets run_ok and run_grind.
run_one() {
  local p=$1 dir=$2 rep=$3
  mkdir -p "$dir"
  local args=(bench can-crush -o "$dir")
  [ "$full" = 1 ] || args+=(--cycles "$cycles")
  [ -z "$epr" ] || args+=(--elements-per-rank "$epr")
  [ -z "$decomposition" ] || args+=(--decomposition "$decomposition")
  local launcher=("$mpirun_cmd" -np "$p" --oversubscribe)
  # shellcheck disable=SC2206  # the extra launcher arguments are meant to split on spaces
  launcher+=($mpi_args)
  [ -z "$timeout_s" ] ||
    launcher=(timeout --signal=TERM --kill-after=30 "$timeout_s" "${launcher[@]}")
  local tag="" load_before status st
  [ "$p" -gt "$cores" ] && tag=" (oversubscribed: $p ranks on $cores cores)"
  load_before=$(loadavg)
  if [ "$repeat" -gt 1 ]; then printf 'P = %-4s #%-2s ... ' "$p" "$rep"; else printf 'P = %-4s ... ' "$p"; fi
  echo "${launcher[*]} $anvil ${args[*]}" >"$dir/command.txt"
  # the deck of this rank count, for the record (mesh divisions)
  "${launcher[@]}" "$anvil" bench can-crush --print-deck \
    ${epr:+--elements-per-rank "$epr"} ${decomposition:+--decomposition "$decomposition"} \
    >"$dir/deck.yaml" 2>/dev/null || rm -f "$dir/deck.yaml"
  /usr/bin/time -f '%e %U %S' -o "$dir/time.txt" "${launcher[@]}" "$anvil" "${args[@]}" \
    >"$dir/run.log" 2>&1
  status=$?
  # the last line of time.txt (a failed command adds a line before it)
  local elapsed=NA user=NA sys=NA elements=NA ncyc=NA
  run_grind=NA
  [ -s "$dir/time.txt" ] && read -r elapsed user sys < <(tail -n 1 "$dir/time.txt")
  if [ "$status" = 0 ] && [ -s "$dir/summary.json" ]; then
    elements=$(sed -n 's/^  "elements": \([0-9]*\),*$/\1/p' "$dir/summary.json")
    ncyc=$(sed -n 's/^  "cycles": \([0-9]*\),*$/\1/p' "$dir/summary.json")
    run_grind=$(sed -n 's/^  "grind_us": \([-0-9.eE+]*\),*$/\1/p' "$dir/summary.json")
    printf 'ok   %s elements, %s cycles, %ss, grind %.4g us, load %s%s\n' "${elements:-?}" \
      "${ncyc:-?}" "$elapsed" "${run_grind:-0}" "${load_before%% *}" "$tag"
    st=ok
    run_ok=1
  else
    st="failed($status)"
    [ "$status" = 124 ] && st="timeout"
    echo "FAILED (exit $status, see $dir/run.log)$tag"
    run_ok=0
  fi
  if [ "$keep_fields" = 0 ]; then rm -rf "$dir/fields" "$dir/results.pvd"; fi
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$p" "$rep" "${elements:-NA}" \
    "${ncyc:-NA}" "$st" "$elapsed" "$user" "$sys" "${run_grind:-NA}" "$load_before" \
    "$([ "$p" -gt "$cores" ] && echo yes || echo no)" >>"$outroot/runs.tsv"
}

failed=0
for p in "${ranks[@]}"; do
  dir="$outroot/P$p"
  rm -rf "$dir"
  if [ "$repeat" = 1 ]; then
    run_one "$p" "$dir" 1
    [ "$run_ok" = 1 ] || failed=$((failed + 1))
    continue
  fi
  # best of N: every repetition in P<P>/rep<k>/, the fastest (least grind) copied to P<P>/
  best="" best_grind=""
  for rep in $(seq 1 "$repeat"); do
    run_one "$p" "$dir/rep$rep" "$rep"
    if [ "$run_ok" = 1 ]; then
      if [ -z "$best" ] || awk -v a="$run_grind" -v b="$best_grind" 'BEGIN{exit !(a < b)}'; then
        best="$dir/rep$rep" best_grind=$run_grind
      fi
    else
      failed=$((failed + 1))
    fi
  done
  if [ -n "$best" ]; then
    find "$best" -mindepth 1 -maxdepth 1 -exec cp -r {} "$dir"/ \;
    echo "best of $repeat: $(basename "$best") (grind $best_grind us)" >"$dir/best_of.txt"
  fi
done

echo "wrote $outroot/runs.tsv and $outroot/machine.json"
if [ "$failed" -gt 0 ]; then
  echo "scaling_series.sh: $failed run(s) failed" >&2
  exit 1
fi
exit 0
