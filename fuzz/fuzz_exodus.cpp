// libFuzzer target: the Exodus II reader (read_exodus) on netCDF classic files, which goes
// through the netCDF library and so needs a file: each input is written to a file of this
// process and read.
// Every input must read or end in InputError; anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "anvil/core/error.hpp"
#include "anvil/mesh/read_exodus.hpp"

namespace {

// Whether the input is a netCDF-4 (HDF5) file: it carries the HDF5 signature where that
// library looks for it. read_exodus reads those in a child process, because the HDF5
// library crashes on corrupt files (this target found hundreds in two minutes); a crash
// there is an InputError for anvil, but libFuzzer's crash handler, inherited by the child,
// would still report it. What anvil validates itself, the classic format, is fuzzed here;
// the isolation is tested by tests/unit/test_readers.cpp.
bool is_hdf5(const std::uint8_t* data, std::size_t size) {
  static constexpr std::uint8_t signature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
  for (std::size_t at = 0; at + 8 <= size; at = at == 0 ? 512 : 2 * at)
    if (std::memcmp(data + at, signature, 8) == 0) return true;
  return false;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (is_hdf5(data, size)) return 0;
  // One file per process (libFuzzer's -jobs run several), reused for every input.
  static const std::string path = "/tmp/anvil_fuzz_exodus_" + std::to_string(::getpid()) + ".exo";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    const anvil::Mesh m = anvil::read_exodus(path);
    (void)m;
  } catch (const anvil::InputError&) {
  }
  return 0;
}
