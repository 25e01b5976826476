#include "anvil/io/files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "anvil/core/error.hpp"

namespace anvil {

void write_file_atomic(const std::string& path, std::span<const std::string_view> pieces) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(fmt::format("cannot write '{}': {}", tmp, std::strerror(errno)));
  // A failure at any point leaves no temporary (a partial file is no use; the previous
  // file stays). fsync's and close's errors count too: a write the disk refuses late is
  // reported there (QA round 20), not taken for a complete file.
  auto fail = [&](const char* what, int err) {
    ::close(fd);
    std::remove(tmp.c_str());
    throw InputError(fmt::format("cannot {} '{}': {}", what, tmp, std::strerror(err)));
  };
  for (const std::string_view piece : pieces)
    for (std::size_t done = 0; done < piece.size();) {
      const auto n = ::write(fd, piece.data() + done, piece.size() - done);
      if (n < 0 && errno == EINTR) continue; // (a signal, caught for a checkpoint)
      if (n <= 0) fail("write", n < 0 ? errno : ENOSPC);
      done += static_cast<std::size_t>(n);
    }
  if (::fsync(fd) != 0) fail("write", errno);
  if (::close(fd) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw InputError(fmt::format("cannot write '{}': {}", tmp, std::strerror(err)));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw InputError(fmt::format("cannot rename '{}' to '{}': {}", tmp, path, std::strerror(err)));
  }
}

void write_file_atomic(const std::string& path, std::string_view content) {
  write_file_atomic(path, std::span<const std::string_view>(&content, 1));
}

std::string json_text(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

void expect_regular_file(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (!fs::exists(st))
    throw InputError({path, 0, ""},
                     "cannot open the " + what + (ec ? ": " + ec.message() : std::string()));
  if (fs::is_directory(st)) throw InputError({path, 0, ""}, "is a directory, not a " + what);
  if (!fs::is_regular_file(st))
    throw InputError({path, 0, ""}, "is not a regular file (a device or a pipe?)");
}

std::string read_input_file(const std::string& path, std::uintmax_t max_bytes,
                            const std::string& what) {
  namespace fs = std::filesystem;
  expect_regular_file(path, what);
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (!ec && size > max_bytes)
    throw InputError(
        {path, 0, ""},
        fmt::format("the file holds {} bytes; a deck may hold at most {}", size, max_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, 0, ""}, "cannot open the " + what);
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError({path, 0, ""}, "cannot read the " + what);
  return ss.str();
}

void make_directories(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec || !std::filesystem::is_directory(path))
    throw InputError("cannot create output directory '" + path + "': " + ec.message());
}

} // namespace anvil
