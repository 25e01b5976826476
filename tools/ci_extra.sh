#!/usr/bin/env bash
# CI's checks after the main test suite (docs/fuzzing.md), on the same machine:
#   0. every source of the main build (build/compile_commands.json) compiles for the
#      vector width this machine does not have (-fsyntax-only: core/simd.hpp has 4-lane
#      AVX2 and 8-lane AVX-512 paths, and -march=native compiles only one of them);
#   1. a sanitizer build in build-san: clang, AddressSanitizer + UBSan (UB is fatal) and
#      libFuzzer's coverage instrumentation (ANVIL_FUZZ=ON), of anvil, the unit tests and
#      the four fuzz targets;
#   2. the unit tests under the sanitizers, leaks included (one process: every test
#      process pays for MPI_Init under ASan);
#   3. each fuzzer over its seed corpus in fuzz/corpus (regression inputs included), then
#      FUZZ_SECONDS (default 25) of fuzzing from it.
# Prints the time of each step. Needs the packages of tools/bootstrap.sh (clang,
# libclang-rt-14-dev).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
fuzz_seconds=${FUZZ_SECONDS:-25}
build=${ANVIL_SAN_BUILD:-build-san}
jobs=$(nproc)

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# OpenMPI's start-up allocations live until exit; the suppressions name its libraries,
# which the slow unwinder reaches through frames without frame pointers.
export ASAN_OPTIONS=fast_unwind_on_malloc=0:detect_stack_use_after_return=1
export LSAN_OPTIONS=suppressions=$here/tools/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

stamp() { date +%s; }
t0=$(stamp)
if grep -qw avx512f /proc/cpuinfo; then other=x86-64-v3; else other=skylake-avx512; fi
/usr/bin/python3 - "$other" build/compile_commands.json <<'PY' | xargs -0 -n 1 -P "$jobs" sh -c
import json, shlex, sys
other, db = sys.argv[1], sys.argv[2]
for entry in json.load(open(db)):
    args = shlex.split(entry["command"])
    out = []
    skip = False
    for a in args:
        if skip:
            skip = False
        elif a == "-o":
            skip = True
        elif a.startswith("-march="):
            out.append("-march=" + other)
        else:
            out.append(a)
    cmd = "cd " + shlex.quote(entry["directory"]) + " && " + shlex.join(out + ["-fsyntax-only"])
    sys.stdout.write(cmd + "\0")
PY
echo "ci_extra: every source compiles with -march=$other"
t0b=$(stamp)
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g" -DANVIL_FUZZ=ON -DANVIL_BENCH=OFF > /dev/null
cmake --build "$build" -j "$jobs" --target anvil anvil_unit_tests fuzz_deck fuzz_exodus \
  fuzz_gmsh fuzz_keyword
t1=$(stamp)

"$build/tests/anvil_unit_tests" --gtest_brief=1
t2=$(stamp)

# The fuzzers run without MPI_Init: the fast unwinder suffices and leaks are anvil's.
for target in deck exodus gmsh keyword; do
  work=$(mktemp -d)
  dict=()
  [ -f "fuzz/$target.dict" ] && dict=("-dict=fuzz/$target.dict")
  echo "fuzz_$target: seed corpus, then ${fuzz_seconds} s"
  status=0
  ASAN_OPTIONS=detect_stack_use_after_return=1 "$build/fuzz/fuzz_$target" "${dict[@]}" \
    -max_total_time="$fuzz_seconds" -timeout=10 -max_len=8192 -print_final_stats=1 \
    -artifact_prefix="$work/" "$work" "fuzz/corpus/$target" > "$work/log" 2>&1 || status=$?
  grep -E "INITED|DONE|stat::number_of_executed_units" "$work/log" || true
  if [ "$status" != 0 ]; then
    tail -n 60 "$work/log" >&2
    echo "fuzz_$target failed (status $status); input and log in $work" >&2
    exit 1
  fi
  rm -rf "$work"
done
t3=$(stamp)
echo "ci_extra: other width $((t0b - t0)) s, sanitizer build $((t1 - t0b)) s, sanitized unit tests $((t2 - t1)) s," \
     "fuzzing $((t3 - t2)) s, total $((t3 - t0)) s"
