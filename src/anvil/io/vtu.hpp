// VTK XML unstructured-grid output: one .vtu piece per rank, a .pvtu that lists them,
// and a .pvd time series, all readable by ParaView. Binary data are appended raw
// (little endian, UInt64 headers). Files are written atomically.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace anvil {

struct VtuArray {
  VtuArray() = default;
  VtuArray(std::string n, int c, bool integer = false)
      : name(std::move(n)), components(c), is_int(integer) {}
  std::string name;
  int components = 1;
  std::vector<double> f64;       // used when is_int is false
  std::vector<std::int64_t> i64; // used when is_int is true
  bool is_int = false;
};

struct VtuPiece {
  std::vector<double> points;             // x, y, z per point
  std::vector<std::int64_t> connectivity; // point indices of every cell
  std::vector<std::int64_t> offsets;      // end of each cell in connectivity
  std::vector<std::uint8_t> types;        // VTK cell type per cell (12 hexahedron, 1 vertex);
                                          // a hexahedron whose nodes repeat is written as
                                          // the wedge, pyramid or tetrahedron it is
  std::vector<VtuArray> point_data, cell_data;
  double time = 0; // written as the TimeValue field (ParaView reads it)
};

void write_vtu(const std::string& path, const VtuPiece& piece);
// Lists `pieces` (file names relative to the .pvtu) with the array layout of `layout`.
void write_pvtu(const std::string& path, const std::vector<std::string>& pieces,
                const VtuPiece& layout);
// A ParaView collection: (time, file relative to the .pvd) per entry.
void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& entries);

} // namespace anvil
