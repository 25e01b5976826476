#include "anvil/io/files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
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
  if (fd < 0) throw InputError("cannot write '" + tmp + "'");
  for (const std::string_view piece : pieces)
    for (std::size_t done = 0; done < piece.size();) {
      const auto n = ::write(fd, piece.data() + done, piece.size() - done);
      if (n <= 0) {
        ::close(fd);
        std::remove(tmp.c_str()); // (a partial file is no use; the previous one stays)
        throw InputError("cannot write '" + tmp + "' (disk full?)");
      }
      done += static_cast<std::size_t>(n);
    }
  ::fsync(fd);
  ::close(fd);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError("cannot rename '" + tmp + "' to '" + path + "'");
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
