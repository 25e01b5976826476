// libFuzzer target: the Exodus II reader (read_exodus), which goes through the netCDF
// library and so needs a file: each input is written to a file of this process and read.
// Every input must read or end in InputError; anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "anvil/core/error.hpp"
#include "anvil/mesh/read_exodus.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
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
