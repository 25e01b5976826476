// The VTU piece writer (io/vtu.hpp), which writes its appended arrays from where they lie
// after a header that gives their offsets: every offset names its array's byte count and
// bytes, in the header's order, and the block ends the file's XML. (The bytes of whole
// runs' outputs were compared with those of the earlier writer by hand: CHANGELOG, QA
// round 20.)
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

#include "anvil/io/vtu.hpp"

namespace {

std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "anvil_vtu_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <class T>
std::string bytes_of(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

TEST(Vtu, AppendedArraysLieAtTheirOffsets) {
  anvil::VtuPiece p;
  p.time = 0.25;
  p.points = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  p.connectivity = {0, 1, 2, 3, 4, 5, 6, 7};
  p.offsets = {8};
  p.types = {12};
  anvil::VtuArray vel{"velocity", 3}, id{"node_id", 1, true}, none{"empty", 1};
  for (int i = 0; i < 24; ++i) vel.f64.push_back(0.5 * i - 3);
  for (int i = 0; i < 8; ++i) id.i64.push_back(100 + i);
  p.point_data = {vel, id};
  anvil::VtuArray stress{"stress", 6}, rank{"fe_rank", 1, true};
  stress.f64 = {1, 2, 3, 4, 5, 6};
  rank.i64 = {-1};
  p.cell_data = {stress, none, rank};
  const std::string path = temp_path("piece.vtu");
  anvil::write_vtu(path, p);
  const std::string s = slurp(path);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));

  // The arrays in the header's order, as the writer appends them.
  const std::vector<std::string> want = {
      bytes_of(vel.f64),        bytes_of(id.i64),    bytes_of(stress.f64),
      bytes_of(none.f64),       bytes_of(rank.i64),  bytes_of(p.points),
      bytes_of(p.connectivity), bytes_of(p.offsets), bytes_of(p.types)};
  const std::string mark = "<AppendedData encoding=\"raw\">\n   _";
  const auto start = s.find(mark);
  ASSERT_NE(start, std::string::npos);
  const std::size_t base = start + mark.size();
  const std::regex offset_re("offset=\"([0-9]+)\"");
  const std::string header = s.substr(0, start);
  std::size_t k = 0, expected_offset = 0;
  for (auto it = std::sregex_iterator(header.begin(), header.end(), offset_re);
       it != std::sregex_iterator(); ++it, ++k) {
    ASSERT_LT(k, want.size());
    const std::size_t off = std::stoul((*it)[1].str());
    EXPECT_EQ(off, expected_offset) << "array " << k;
    std::uint64_t n = 0;
    ASSERT_LE(base + off + sizeof(n), s.size());
    std::memcpy(&n, s.data() + base + off, sizeof(n));
    ASSERT_EQ(n, want[k].size()) << "array " << k;
    EXPECT_EQ(s.substr(base + off + sizeof(n), n), want[k]) << "array " << k;
    expected_offset = off + sizeof(n) + n;
  }
  EXPECT_EQ(k, want.size());
  EXPECT_EQ(s.substr(base + expected_offset), "\n  </AppendedData>\n</VTKFile>\n");
  EXPECT_NE(header.find("NumberOfPoints=\"8\" NumberOfCells=\"1\""), std::string::npos);
  EXPECT_NE(header.find(">0.25</DataArray>"), std::string::npos);
}

// The appended arrays of a written piece, in the header's order.
std::vector<std::string> appended_arrays(const std::string& s) {
  std::vector<std::string> out;
  const std::string mark = "<AppendedData encoding=\"raw\">\n   _";
  const auto start = s.find(mark);
  if (start == std::string::npos) return out;
  const std::size_t base = start + mark.size();
  const std::regex offset_re("offset=\"([0-9]+)\"");
  const std::string header = s.substr(0, start);
  for (auto it = std::sregex_iterator(header.begin(), header.end(), offset_re);
       it != std::sregex_iterator(); ++it) {
    const std::size_t off = std::stoul((*it)[1].str());
    std::uint64_t n = 0;
    std::memcpy(&n, s.data() + base + off, sizeof(n));
    out.push_back(s.substr(base + off + sizeof(n), n));
  }
  return out;
}

// A hexahedron whose nodes repeat (a wedge a b c c d e f f, mesh.hpp) is written as VTK's
// wedge, a c b d f e (VTK's first triangle runs counter-clockwise seen from outside); a
// plain hexahedron and other cells as they are.
TEST(Vtu, RepeatedNodesAreWrittenAsTheSolidTheyAre) {
  anvil::VtuPiece p;
  p.points.assign(3 * 15, 0.0);
  p.connectivity = {0, 1, 2, 3, 4, 5, 6, 7, /* wedge */ 8, 9, 10, 10, 11, 12, 13, 13, 14};
  p.offsets = {8, 16, 17};
  p.types = {12, 12, 1};
  const std::string path = temp_path("wedge.vtu");
  anvil::write_vtu(path, p);
  const auto arrays = appended_arrays(slurp(path));
  ASSERT_EQ(arrays.size(), 4u); // points, connectivity, offsets, types
  EXPECT_EQ(arrays[1],
            bytes_of(std::vector<std::int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 9, 11, 13, 12, 14}));
  EXPECT_EQ(arrays[2], bytes_of(std::vector<std::int64_t>{8, 14, 15}));
  EXPECT_EQ(arrays[3], bytes_of(std::vector<std::uint8_t>{12, 13, 1}));
}

} // namespace
