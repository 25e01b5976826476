// File helpers for outputs that must never be seen half-written.
#pragma once

#include <string>
#include <string_view>

namespace anvil {

// Writes `content` to `path` through a temporary file in the same directory, flushed to
// disk and renamed over the target, so readers see the old file or the new one.
void write_file_atomic(const std::string& path, std::string_view content);

// Creates a directory and its parents; InputError if that is impossible.
void make_directories(const std::string& path);

} // namespace anvil
