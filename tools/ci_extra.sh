#!/usr/bin/env bash
# CI's checks after the main test suite (docs/fuzzing.md), on the same machine:
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
echo "ci_extra: sanitizer build $((t1 - t0)) s, sanitized unit tests $((t2 - t1)) s," \
     "fuzzing $((t3 - t2)) s, total $((t3 - t0)) s"
