// File helpers for outputs that must never be seen half-written.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

namespace anvil {

// Writes `content` to `path` through a temporary file in the same directory, flushed to
// disk and renamed over the target, so readers see the old file or the new one.
void write_file_atomic(const std::string& path, std::string_view content);
// The same for a file made of `pieces` in order, written from where they lie (a large
// file need not be copied into one string first).
void write_file_atomic(const std::string& path, std::span<const std::string_view> pieces);

// `j` as JSON text (`indent` < 0: one line), with any bytes that are not UTF-8 (a deck or
// file name in Latin-1) replaced by U+FFFD rather than thrown at, after a completed run.
std::string json_text(const nlohmann::json& j, int indent = -1);

// Throws an InputError naming `path` unless it is a regular file: "cannot open the WHAT"
// when it does not exist, "is a directory, not a WHAT", or "is not a regular file". Every
// reader checks its file with it before opening it: a directory opens as a stream that
// reads nothing (an "empty" file) and whose size is nonsense.
void expect_regular_file(const std::string& path, const std::string& what);

// The whole text of an input file (`what`: a deck file, a mesh file); InputError naming
// `path` if it is not a regular file (a directory, a device), cannot be read, or is
// larger than `max_bytes`.
std::string read_input_file(const std::string& path, std::uintmax_t max_bytes,
                            const std::string& what = "deck file");

// Creates a directory and its parents; InputError if that is impossible.
void make_directories(const std::string& path);

} // namespace anvil
