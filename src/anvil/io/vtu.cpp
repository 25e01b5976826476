#include "anvil/io/vtu.hpp"

#include <cstring>

#include <fmt/format.h>

#include "anvil/io/files.hpp"

namespace anvil {

namespace {

struct Appender {
  std::string header, blob;
  template <class T>
  std::size_t add(const std::vector<T>& v) {
    const std::size_t offset = blob.size();
    const std::uint64_t bytes = v.size() * sizeof(T);
    blob.append(reinterpret_cast<const char*>(&bytes), sizeof(bytes));
    if (bytes) blob.append(reinterpret_cast<const char*>(v.data()), bytes);
    return offset;
  }
};

void array_tag(Appender& a, const VtuArray& arr) {
  const std::size_t off = arr.is_int ? a.add(arr.i64) : a.add(arr.f64);
  a.header += fmt::format(
      "        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" "
      "offset=\"{}\"/>\n",
      arr.is_int ? "Int64" : "Float64", arr.name, arr.components, off);
}

} // namespace

void write_vtu(const std::string& path, const VtuPiece& p) {
  Appender a;
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
                          a.add(p.connectivity));
  a.header += fmt::format(
      "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{}\"/>\n",
      a.add(p.offsets));
  a.header += fmt::format(
      "        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"{}\"/>\n",
      a.add(p.types));
  a.header += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData "
              "encoding=\"raw\">\n   _";
  std::string out = std::move(a.header);
  out += a.blob;
  out += "\n  </AppendedData>\n</VTKFile>\n";
  write_file_atomic(path, out);
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
