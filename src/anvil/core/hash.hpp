// A 64-bit FNV-1a hash of bytes: the checkpoint's checksum and the mesh fingerprint a
// checkpoint carries. Not cryptographic; it catches damaged files and changed inputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace anvil {

class Fnv1a {
public:
  Fnv1a& bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ULL;
    return *this;
  }
  Fnv1a& bytes(std::string_view s) { return bytes(s.data(), s.size()); }
  template <class T>
  Fnv1a& values(const std::vector<T>& v) {
    return bytes(v.data(), v.size() * sizeof(T));
  }
  std::uint64_t value() const { return h_; }

private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

} // namespace anvil
