#!/usr/bin/env bash
# One command from a fresh Debian 12 machine (root, apt reachable) to a result:
#   bash tools/bootstrap.sh example   install, build, run the main example on 2 ranks
#   bash tools/bootstrap.sh test      install, build, run the whole test suite
# Set ANVIL_SKIP_APT=1 to skip the package installation (already done).
set -euo pipefail
mode=${1:-example}
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"

packages=(build-essential cmake clang-format libopenmpi-dev openmpi-bin libmetis-dev
          libexodusii-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libfmt-dev libgtest-dev
          libbenchmark-dev python3-matplotlib python3-numpy python3-netcdf4
          clang libclang-rt-14-dev)  # clang + compiler-rt: sanitizers and libFuzzer (tools/ci_extra.sh)
if [ "${ANVIL_SKIP_APT:-0}" != 1 ]; then
  missing=()
  for p in "${packages[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
  if [ ${#missing[@]} -gt 0 ]; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
  fi
fi

# mpirun as root in a container, more ranks than cores (../TOOLCHAIN facts).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)"

case "$mode" in
  example)
    mpirun -np 2 build/apps/anvil run examples/taylor_bar.yaml -o out/taylor_bar
    /usr/bin/python3 tools/plot_history.py out/taylor_bar -o out/taylor_bar/energy.png
    echo "results: out/taylor_bar (open results.pvd in ParaView; summary.json; history.csv)"
    ;;
  test)
    cmake --build build --target format-check
    ctest --test-dir build --output-on-failure -j "$(nproc)" --timeout 900
    ;;
  *)
    echo "usage: bash tools/bootstrap.sh example|test" >&2
    exit 2
    ;;
esac
