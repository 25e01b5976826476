#include "anvil/io/vtu.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <deque>
#include <string_view>

#include <fmt/format.h>

#include "anvil/io/files.hpp"
#include "anvil/mesh/mesh.hpp"

namespace anvil {

namespace {

// The appended data block, laid out before a byte of it is written: each array's offset
// follows from the sizes of those before it (a UInt64 byte count, then the bytes), so the
// header can be written first and every array written from where it lies. A piece costs
// its header in memory, not another copy of its arrays (QA round 20: the block assembled
// in a string and copied once more held the piece three times over).
struct Appended {
  std::string header;
  std::deque<std::uint64_t> counts; // (a deque: the views of its elements stay valid)
  std::vector<std::string_view> blocks;
  std::size_t size = 0;
  template <class T>
  std::size_t add(const std::vector<T>& v) {
    const std::size_t offset = size;
    const std::uint64_t& bytes = counts.emplace_back(v.size() * sizeof(T));
    blocks.emplace_back(reinterpret_cast<const char*>(&bytes), sizeof(bytes));
    blocks.emplace_back(reinterpret_cast<const char*>(v.data()), bytes);
    size += sizeof(bytes) + bytes;
    return offset;
  }
};

void array_tag(Appended& a, const VtuArray& arr) {
  const std::size_t off = arr.is_int ? a.add(arr.i64) : a.add(arr.f64);
  a.header += fmt::format(
      "        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" "
      "offset=\"{}\"/>\n",
      arr.is_int ? "Int64" : "Float64", arr.name, arr.components, off);
}

} // namespace

namespace {

// Hexahedra whose nodes repeat (wedges, pyramids, tetrahedra; mesh.hpp) as VTK's own cells,
// which ParaView's filters (surfaces, slices, volumes) take as the solids they are. False
// (and nothing written) when the piece has none.
bool own_cells(const VtuPiece& p, std::vector<std::int64_t>& connectivity,
               std::vector<std::int64_t>& offsets, std::vector<std::uint8_t>& types) {
  auto repeats = [&](std::size_t c) {
    const auto* h = &p.connectivity[static_cast<std::size_t>(p.offsets[c]) - 8];
    for (int a = 1; a < 8; ++a)
      for (int b = 0; b < a; ++b)
        if (h[a] == h[b]) return true;
    return false;
  };
  bool any = false;
  for (std::size_t c = 0; c < p.types.size() && !any; ++c) any = p.types[c] == 12 && repeats(c);
  if (!any) return false;
  connectivity.reserve(p.connectivity.size());
  offsets.reserve(p.offsets.size());
  types.reserve(p.types.size());
  std::size_t begin = 0;
  for (std::size_t c = 0; c < p.types.size(); ++c) {
    const auto end = static_cast<std::size_t>(p.offsets[c]);
    if (p.types[c] == 12) {
      Hex h;
      std::copy(p.connectivity.begin() + static_cast<std::ptrdiff_t>(begin),
                p.connectivity.begin() + static_cast<std::ptrdiff_t>(end), h.begin());
      std::array<std::int64_t, 8> cell;
      int n = 0;
      types.push_back(static_cast<std::uint8_t>(vtk_cell(h, cell, n)));
      connectivity.insert(connectivity.end(), cell.begin(), cell.begin() + n);
    } else {
      types.push_back(p.types[c]);
      connectivity.insert(connectivity.end(),
                          p.connectivity.begin() + static_cast<std::ptrdiff_t>(begin),
                          p.connectivity.begin() + static_cast<std::ptrdiff_t>(end));
    }
    offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
    begin = end;
  }
  return true;
}

} // namespace

void write_vtu(const std::string& path, const VtuPiece& p) {
  std::vector<std::int64_t> own_connectivity, own_offsets;
  std::vector<std::uint8_t> own_types;
  const bool own = own_cells(p, own_connectivity, own_offsets, own_types);
  Appended a;
  const std::size_t np = p.points.size() / 3, nc = p.types.size();
  a.header += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
              "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n";
  a.header +=
      fmt::format("    <FieldData>\n      <DataArray type=\"Float64\" Name=\"TimeValue\" "
                  "NumberOfTuples=\"1\" format=\"ascii\">{:.17g}</DataArray>\n    </FieldData>\n",
                  p.time);
  a.header += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", np, nc);
  a.header += "      <PointData>\n";
  for (const auto& arr : p.point_data) array_tag(a, arr);
  a.header += "      </PointData>\n      <CellData>\n";
  for (const auto& arr : p.cell_data) array_tag(a, arr);
  a.header += "      </CellData>\n      <Points>\n";
  a.header += fmt::format("        <DataArray type=\"Float64\" NumberOfComponents=\"3\" "
                          "format=\"appended\" offset=\"{}\"/>\n",
                          a.add(p.points));
  a.header += "      </Points>\n      <Cells>\n";
  a.header += fmt::format("        <DataArray type=\"Int64\" Name=\"connectivity\" "
                          "format=\"appended\" offset=\"{}\"/>\n",
                          a.add(own ? own_connectivity : p.connectivity));
  a.header += fmt::format(
      "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{}\"/>\n",
      a.add(own ? own_offsets : p.offsets));
  a.header += fmt::format(
      "        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"{}\"/>\n",
      a.add(own ? own_types : p.types));
  a.header += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData "
              "encoding=\"raw\">\n   _";
  std::vector<std::string_view> pieces;
  pieces.reserve(a.blocks.size() + 2);
  pieces.push_back(a.header);
  pieces.insert(pieces.end(), a.blocks.begin(), a.blocks.end());
  pieces.push_back("\n  </AppendedData>\n</VTKFile>\n");
  write_file_atomic(path, pieces);
}

void write_pvtu(const std::string& path, const std::vector<std::string>& pieces,
                const VtuPiece& layout) {
  std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" "
                  "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PUnstructuredGrid "
                  "GhostLevel=\"0\">\n";
  auto arrays = [&](const std::vector<VtuArray>& list) {
    for (const auto& a : list)
      s += fmt::format("      <PDataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"/>\n",
                       a.is_int ? "Int64" : "Float64", a.name, a.components);
  };
  s += "    <PPointData>\n";
  arrays(layout.point_data);
  s += "    </PPointData>\n    <PCellData>\n";
  arrays(layout.cell_data);
  s += "    </PCellData>\n    <PPoints>\n      <PDataArray type=\"Float64\" "
       "NumberOfComponents=\"3\"/>\n    </PPoints>\n";
  for (const auto& f : pieces) s += fmt::format("    <Piece Source=\"{}\"/>\n", f);
  s += "  </PUnstructuredGrid>\n</VTKFile>\n";
  write_file_atomic(path, s);
}

void write_pvd(const std::string& path,
               const std::vector<std::pair<double, std::string>>& entries) {
  std::string s =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n  <Collection>\n";
  for (const auto& [t, f] : entries)
    s += fmt::format("    <DataSet timestep=\"{:.17g}\" part=\"0\" file=\"{}\"/>\n", t, f);
  s += "  </Collection>\n</VTKFile>\n";
  write_file_atomic(path, s);
}

} // namespace anvil
