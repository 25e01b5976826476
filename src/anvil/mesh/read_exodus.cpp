#include "anvil/mesh/read_exodus.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <exodusII.h>
#include <fmt/format.h>
#include <netcdf.h>

#include "anvil/core/error.hpp"
#include "anvil/io/files.hpp"

namespace anvil {

namespace {

// The open file and its path; closes the file when the reader leaves by any path, so
// that an InputError thrown halfway does not leak a netCDF handle.
class ExodusFile {
public:
  explicit ExodusFile(const std::string& path) : path_(path) {
    int cpu_word_size = sizeof(double), io_word_size = 0;
    float version = 0;
    // 64-bit integers through the API whatever the file stores: ids and counts of large
    // meshes do not fit an int, and one integer type keeps the code below simple.
    id_ =
        ex_open(path.c_str(), EX_READ | EX_ALL_INT64_API, &cpu_word_size, &io_word_size, &version);
    if (id_ < 0) fail("cannot open as an Exodus II file" + library_message());
  }
  ~ExodusFile() {
    if (id_ >= 0) ex_close(id_);
  }
  ExodusFile(const ExodusFile&) = delete;
  ExodusFile& operator=(const ExodusFile&) = delete;

  int id() const { return id_; }
  const std::string& path() const { return path_; }
  // Whether the coordinates are three variables (coordx, ...) rather than one (coord).
  bool stored_coordinates_separately() const { return has("coordx"); }
  // Whether the file has the netCDF variable `var`.
  bool has(const std::string& var) const { return stored_values(var) >= 0; }

  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(SourceLocation{path_, 0, ""}, message);
  }

  // Throws unless `rc` reports success (Exodus: negative is an error, positive a warning).
  void check(int rc, const std::string& what) const {
    if (rc < 0) fail(fmt::format("cannot read {}{}", what, library_message()));
  }

  // Throws unless the netCDF variable `var` stores exactly `n` values. The Exodus library
  // reads whole variables into the caller's buffer, sized from the counts it reports
  // (dimensions of their own): in a corrupt file the two disagree, and the read would
  // write past the buffer. Every bulk read is checked with this first.
  void expect_values(const std::string& var, std::int64_t n, const std::string& what) const {
    const std::int64_t have = stored_values(var);
    if (have != n)
      fail(fmt::format("{} is corrupt: its variable {} {} where the counts give {}", what, var,
                       have < 0 ? std::string("is missing or malformed")
                                : fmt::format("holds {} values", have),
                       n));
  }

private:
  // Values the netCDF variable `var` holds (the product of its dimensions, the record
  // dimension at its current length), or -1 when the file has no such variable. The
  // Exodus file id is the netCDF id.
  std::int64_t stored_values(const std::string& var) const {
    int varid = -1, ndims = 0;
    if (nc_inq_varid(id_, var.c_str(), &varid) != NC_NOERR) return -1;
    if (nc_inq_varndims(id_, varid, &ndims) != NC_NOERR || ndims < 0 || ndims > NC_MAX_VAR_DIMS)
      return -1;
    int dims[NC_MAX_VAR_DIMS];
    if (nc_inq_vardimid(id_, varid, dims) != NC_NOERR) return -1;
    std::int64_t total = 1;
    for (int d = 0; d < ndims; ++d) {
      std::size_t len = 0;
      if (nc_inq_dimlen(id_, dims[d], &len) != NC_NOERR) return -1;
      if (len != 0 &&
          static_cast<std::uint64_t>(total) >
              static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) / len)
        return -1;
      total *= static_cast<std::int64_t>(len);
    }
    return total;
  }

  // The Exodus library's own explanation of its last error, for the user.
  static std::string library_message() {
    const char* msg = nullptr;
    const char* func = nullptr;
    int code = 0;
    ex_get_err(&msg, &func, &code);
    if (!msg || !*msg) return "";
    return fmt::format(" ({})", msg);
  }

  std::string path_;
  int id_ = -1;
};

// Walks the header of a netCDF classic file (CDF-1, CDF-2 or CDF-5: the formats Exodus
// writes by default) and returns what is inconsistent with the file's size, or an empty
// string. The netCDF library trusts the header's counts and allocates by them: a corrupt
// byte can make it ask for tens of gigabytes before it notices anything wrong. Checking
// that every count, name, attribute and variable fits in the file first bounds what
// the library can allocate by the file size. Not a classic file (netCDF-4/HDF5, or not
// netCDF at all): empty, and the library decides.
std::string classic_netcdf_problem(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return ""; // ex_open reports it
  in.seekg(0, std::ios::end);
  const auto end = in.tellg();
  if (end < 0) return "";
  const auto size = static_cast<std::uint64_t>(end);
  in.seekg(0);
  char magic[4] = {};
  if (!in.read(magic, 4) || magic[0] != 'C' || magic[1] != 'D' || magic[2] != 'F') return "";
  const int version = magic[3];
  if (version != 1 && version != 2 && version != 5) return "";
  const int count_bytes = version == 5 ? 8 : 4;  // NON_NEG
  const int offset_bytes = version == 1 ? 4 : 8; // OFFSET
  std::uint64_t pos = 4;

  // Big-endian unsigned integer of `n` bytes; false at the end of the file.
  auto uint = [&](int n, std::uint64_t& v) {
    unsigned char b[8];
    if (pos + n > size || !in.read(reinterpret_cast<char*>(b), n)) return false;
    pos += n;
    v = 0;
    for (int i = 0; i < n; ++i) v = (v << 8) | b[i];
    return true;
  };
  auto skip = [&](std::uint64_t n) {
    if (n > size - pos) return false;
    pos += n;
    in.seekg(static_cast<std::streamoff>(pos));
    return true;
  };
  auto padded = [](std::uint64_t n) { return (n + 3) / 4 * 4; };
  auto name = [&]() {
    std::uint64_t len = 0;
    return uint(count_bytes, len) && len <= size && skip(padded(len));
  };
  auto type_size = [](std::uint64_t t) -> std::uint64_t {
    static constexpr std::uint64_t sizes[12] = {0, 1, 1, 2, 4, 4, 8, 1, 2, 4, 8, 8};
    return t >= 1 && t <= 11 ? sizes[t] : 0;
  };
  // A list header: tag and number of elements; ABSENT is tag 0 with 0 elements.
  auto list = [&](std::uint64_t tag, std::uint64_t& n) {
    std::uint64_t t = 0;
    if (!uint(4, t) || !uint(count_bytes, n)) return false;
    return (t == tag || (t == 0 && n == 0)) && n <= size;
  };
  auto attributes = [&]() {
    std::uint64_t n = 0;
    if (!list(0x0C, n)) return false;
    for (std::uint64_t i = 0; i < n; ++i) {
      std::uint64_t type = 0, count = 0;
      if (!name() || !uint(4, type) || !uint(count_bytes, count)) return false;
      const auto ts = type_size(type);
      if (ts == 0 || count > size / ts || !skip(padded(count * ts))) return false;
    }
    return true;
  };

  std::uint64_t numrecs = 0, ndims = 0, nvars = 0;
  if (!uint(count_bytes, numrecs)) return "the netCDF header is truncated";
  const bool streaming = numrecs == (count_bytes == 4 ? 0xFFFFFFFFull : ~0ull);
  if (!streaming && numrecs > size) return "the netCDF header declares more records than fit";
  if (!list(0x0A, ndims)) return "the netCDF dimension list is corrupt";
  std::vector<std::uint64_t> dims;
  for (std::uint64_t i = 0; i < ndims; ++i) {
    std::uint64_t len = 0;
    if (!name() || !uint(count_bytes, len)) return "the netCDF dimension list is corrupt";
    dims.push_back(len);
  }
  if (!attributes()) return "the netCDF global attributes are corrupt";
  if (!list(0x0B, nvars)) return "the netCDF variable list is corrupt";
  for (std::uint64_t v = 0; v < nvars; ++v) {
    std::uint64_t nd = 0;
    if (!name() || !uint(count_bytes, nd) || nd > size)
      return "the netCDF variable list is corrupt";
    std::uint64_t extent = 1; // bytes of one record (record variable) or of all the data
    bool record = false;
    for (std::uint64_t d = 0; d < nd; ++d) {
      std::uint64_t id = 0;
      if (!uint(count_bytes, id) || id >= dims.size())
        return "a netCDF variable refers to an undefined dimension";
      if (dims[id] == 0 && d == 0) {
        record = true;
        continue;
      }
      if (dims[id] != 0 && extent > size / dims[id])
        return "a netCDF variable is larger than the file";
      extent *= dims[id];
    }
    std::uint64_t type = 0, vsize = 0, begin = 0;
    if (!attributes() || !uint(4, type) || !uint(count_bytes, vsize) ||
        !uint(offset_bytes, begin) || type_size(type) == 0)
      return "the netCDF variable list is corrupt";
    if (extent > size / type_size(type)) return "a netCDF variable is larger than the file";
    extent *= type_size(type);
    const std::uint64_t records = record ? (streaming ? 0 : numrecs) : 1;
    if (records > 0 && extent > size / records) return "a netCDF variable is larger than the file";
    if (begin > size || extent * records > size - begin)
      return "a netCDF variable lies beyond the end of the file (truncated file?)";
  }
  return "";
}

// Returns what in the file would make the Exodus library write past its own buffers, or an
// empty string. Opening the file reads global attributes into single numbers (more values
// overflow them), and reading a block copies its element type into a buffer of
// MAX_STR_LENGTH + 1 characters: both are checked through netCDF before the library sees
// the file. A file netCDF cannot open is left to ex_open to report.
std::string exodus_attribute_problem(const std::string& path) {
  int ncid = -1;
  if (nc_open(path.c_str(), NC_NOWRITE, &ncid) != NC_NOERR) return "";
  std::string problem;
  for (const char* att : {"api_version", "version", "floating_point_word_size", "file_size",
                          "maximum_name_length", "int64_status", "last_written_time"}) {
    std::size_t len = 0;
    if (nc_inq_attlen(ncid, NC_GLOBAL, att, &len) == NC_NOERR && len != 1) {
      problem = fmt::format("the global attribute {} has {} values instead of one", att, len);
      break;
    }
  }
  int nvars = 0;
  if (problem.empty() && nc_inq_nvars(ncid, &nvars) == NC_NOERR) {
    for (int v = 0; v < nvars && problem.empty(); ++v) {
      std::size_t len = 0;
      char name[NC_MAX_NAME + 1] = {};
      if (nc_inq_varname(ncid, v, name) != NC_NOERR) continue;
      if (std::string_view(name).substr(0, 7) != "connect") continue;
      if (nc_inq_attlen(ncid, v, "elem_type", &len) == NC_NOERR && len > MAX_STR_LENGTH)
        problem = fmt::format("the element type of {} has {} characters (at most {})", name, len,
                              MAX_STR_LENGTH);
    }
  }
  nc_close(ncid);
  return problem;
}

// Names of the `count` entities of `type` in file order; an empty string where the file
// gives none.
std::vector<std::string> entity_names(const ExodusFile& f, ex_entity_type type, std::int64_t count,
                                      const char* what) {
  std::vector<std::string> out(static_cast<std::size_t>(count));
  if (count == 0) return out;
  const auto len = std::max<std::int64_t>(ex_inquire_int(f.id(), EX_INQ_MAX_READ_NAME_LENGTH), 32);
  std::vector<std::vector<char>> storage(out.size(), std::vector<char>(len + 1, '\0'));
  std::vector<char*> ptrs;
  for (auto& s : storage) ptrs.push_back(s.data());
  f.check(ex_get_names(f.id(), type, ptrs.data()), what);
  for (std::size_t i = 0; i < out.size(); ++i) {
    storage[i].back() = '\0';
    out[i] = storage[i].data();
    // Names padded with blanks by some writers are the same names.
    while (!out[i].empty() && std::isspace(static_cast<unsigned char>(out[i].back())))
      out[i].pop_back();
  }
  return out;
}

// Ids of the `count` entities of `type` in file order; two entities with one id are an
// error (the library would give both the first one's data).
std::vector<std::int64_t> entity_ids(const ExodusFile& f, ex_entity_type type, std::int64_t count,
                                     const char* what) {
  std::vector<std::int64_t> ids(static_cast<std::size_t>(count));
  if (count == 0) return ids;
  const char* var = type == EX_ELEM_BLOCK ? "eb_prop1"
                    : type == EX_NODE_SET ? "ns_prop1"
                                          : "ss_prop1";
  f.expect_values(var, count, what);
  f.check(ex_get_ids(f.id(), type, ids.data()), what);
  std::vector<std::int64_t> sorted = ids;
  std::sort(sorted.begin(), sorted.end());
  if (const auto dup = std::adjacent_find(sorted.begin(), sorted.end()); dup != sorted.end())
    f.fail(fmt::format("{}: two entities have id {}", what, *dup));
  return ids;
}

// The solids anvil reads, by their corners: the first nodes of every higher-order form
// are the corners in the order of the linear one (Exodus II manual, element topologies).
// The type is known by its first three letters, as the Exodus library knows it (HEX8 and
// HEXAHEDRON, TETRA4 and TET4), in any case; the node count tells the form.
std::optional<Shape> solid_of(const std::string& type, std::int64_t nodes_per_element) {
  std::string t;
  for (char c : type.substr(0, 3))
    t += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const auto n = nodes_per_element;
  if (t == "HEX" && (n == 8 || n == 20 || n == 27)) return Shape::hexahedron;
  if (t == "TET" && (n == 4 || n == 8 || n == 10 || n == 14 || n == 15)) return Shape::tetrahedron;
  if (t == "WED" && (n == 6 || n == 15 || n == 16 || n == 18)) return Shape::wedge;
  if (t == "PYR" && (n == 5 || n == 13 || n == 14)) return Shape::pyramid;
  return std::nullopt;
}

// Exodus's orders are anvil's (solid_hex): TETRA 1 2 3 counter-clockwise seen from 4
// (side 4 is 1 3 2, outward); WEDGE 1 2 3 counter-clockwise seen from 4 5 6 (side 4 is
// 1 3 2, side 5 is 4 5 6, both outward), edges 1-4, 2-5, 3-6; PYRAMID base 1 2 3 4
// counter-clockwise seen from the apex 5 (side 5 is 1 4 3 2, outward).

// The number of Exodus sides of a solid.
int side_count(Shape s) {
  return s == Shape::hexahedron ? 6 : s == Shape::tetrahedron ? 4 : 5;
}

// The face (0..5, hex_faces) of a solid's canonical hexahedron that is Exodus side `side`
// (1-based) of a tetrahedron, wedge or pyramid: the face with the side's nodes, found by
// face_key on the canonical hexahedron of corners 0, 1, 2, ... The Exodus sides, by
// 1-based corner (the Exodus library's side tables, ex_get_side_set_node_list):
//   TETRA   1: 1 2 4, 2: 2 3 4, 3: 1 4 3, 4: 1 3 2
//   WEDGE   1: 1 2 5 4, 2: 2 3 6 5, 3: 1 4 6 3, 4: 1 3 2, 5: 4 5 6
//   PYRAMID 1: 1 2 5, 2: 2 3 5, 3: 3 4 5, 4: 1 5 4, 5: 1 4 3 2
int side_face(Shape s, int side) {
  using Sides = std::array<std::array<std::int64_t, 4>, 5>;
  static constexpr Sides tetra = {{{1, 2, 4, 4}, {2, 3, 4, 4}, {1, 4, 3, 3}, {1, 3, 2, 2}, {}}};
  static constexpr Sides wedge = {
      {{1, 2, 5, 4}, {2, 3, 6, 5}, {1, 4, 6, 3}, {1, 3, 2, 2}, {4, 5, 6, 6}}};
  static constexpr Sides pyramid = {
      {{1, 2, 5, 5}, {2, 3, 5, 5}, {3, 4, 5, 5}, {1, 5, 4, 4}, {1, 4, 3, 2}}};
  static const auto faces = [] {
    std::array<std::array<int, 5>, 3> out{};
    const std::int64_t corners[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    const Sides* sides[3] = {&tetra, &wedge, &pyramid};
    const Shape solids[3] = {Shape::tetrahedron, Shape::wedge, Shape::pyramid};
    for (int k = 0; k < 3; ++k) {
      const Hex h = solid_hex(solids[k], corners);
      for (int i = 0; i < side_count(solids[k]); ++i) {
        const FaceKey key = face_key((*sides[k])[i]);
        out[k][i] = -1;
        for (int f = 0; f < 6; ++f)
          if (face_key(h, f) == key) out[k][i] = f;
      }
    }
    return out;
  }();
  const int k = s == Shape::tetrahedron ? 0 : s == Shape::wedge ? 1 : 2;
  return faces[k][side - 1];
}

// Throws unless every id of an id map is positive (Exodus ids are, and the outputs carry
// them), naming the first that is not by its 1-based position, as keyword and Gmsh input
// are refused for an id <= 0.
void expect_positive_ids(const ExodusFile& f, const std::vector<std::int64_t>& ids, const char* map,
                         const char* entity) {
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (ids[i] <= 0)
      f.fail(fmt::format("the id map {} gives {} {} the id {}: ids must be positive", map, entity,
                         i + 1, ids[i]));
}

Mesh read_all(const ExodusFile& f) {
  ex_init_params init{};
  f.check(ex_get_init_ext(f.id(), &init), "the file header");
  if (init.num_dim != 3)
    f.fail(fmt::format("the mesh is {}-dimensional; anvil reads 3-D meshes only", init.num_dim));
  if (init.num_nodes < 0 || init.num_elem < 0 || init.num_elem_blk < 0 || init.num_node_sets < 0 ||
      init.num_side_sets < 0)
    f.fail("the file header has negative counts");

  // Every entity takes more than a byte in the file, even compressed: a count beyond the
  // file's size is a corrupt header, caught before it becomes an allocation.
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(f.path(), ec);
  const auto limit =
      ec ? std::numeric_limits<std::int64_t>::max() : static_cast<std::int64_t>(bytes);
  auto fits = [&](std::int64_t n, const std::string& what) {
    if (n > limit)
      f.fail(fmt::format("the file declares {} {}, more than a file of {} bytes can hold", n, what,
                         limit));
  };
  fits(init.num_nodes, "nodes");
  fits(init.num_elem_blk, "element blocks");
  fits(init.num_node_sets, "node sets");
  fits(init.num_side_sets, "side sets");

  Mesh mesh;
  const std::int64_t nn = init.num_nodes;
  if (nn > 0) {
    std::vector<double> x(nn), y(nn), z(nn);
    if (f.stored_coordinates_separately()) {
      for (const char* var : {"coordx", "coordy", "coordz"})
        f.expect_values(var, nn, "the node coordinates");
    } else {
      f.expect_values("coord", 3 * nn, "the node coordinates");
    }
    f.check(ex_get_coord(f.id(), x.data(), y.data(), z.data()), "the node coordinates");
    mesh.nodes.resize(nn);
    for (std::int64_t i = 0; i < nn; ++i) {
      if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || !std::isfinite(z[i]))
        f.fail(fmt::format("node {} has a non-finite coordinate", i + 1));
      mesh.nodes[i] = Vec3{x[i], y[i], z[i]};
    }
    // The file's node ids (node_num_map; 1 to N without one).
    if (f.has("node_num_map")) {
      f.expect_values("node_num_map", nn, "the node ids");
      mesh.node_ids.resize(static_cast<std::size_t>(nn));
      f.check(ex_get_id_map(f.id(), EX_NODE_MAP, mesh.node_ids.data()), "the node ids");
      expect_positive_ids(f, mesh.node_ids, "node_num_map", "node");
    }
  }

  // Element blocks, in file order: the file's element numbering runs through them.
  const auto block_ids = entity_ids(f, EX_ELEM_BLOCK, init.num_elem_blk, "the element block ids");
  const auto block_names =
      entity_names(f, EX_ELEM_BLOCK, init.num_elem_blk, "the element block names");
  // The file's element ids (elem_num_map; 1 to N without one), for messages.
  fits(init.num_elem, "elements");
  std::vector<std::int64_t> element_ids(static_cast<std::size_t>(init.num_elem));
  if (init.num_elem > 0) {
    if (f.has("elem_num_map")) f.expect_values("elem_num_map", init.num_elem, "the element ids");
    f.check(ex_get_id_map(f.id(), EX_ELEM_MAP, element_ids.data()), "the element ids");
    if (f.has("elem_num_map")) expect_positive_ids(f, element_ids, "elem_num_map", "element");
  }
  std::int64_t elements = 0;
  // Each block's first element and solid, for the side sets; and the file's hexahedra
  // that canonical_hex rewrote, by global element.
  struct BlockSolid {
    std::int64_t first;
    Shape solid;
  };
  std::vector<BlockSolid> solids;
  std::unordered_map<std::int64_t, Hex> rewritten;
  for (std::size_t b = 0; b < block_ids.size(); ++b) {
    const std::int64_t bid = block_ids[b];
    const std::string name = block_names[b].empty() ? fmt::format("block_{}", bid) : block_names[b];
    const std::string label = fmt::format("element block '{}' (id {})", name, bid);
    // The library copies the element type attribute into this buffer; its length was
    // checked against MAX_STR_LENGTH before the file was opened (exodus_attribute_problem).
    const std::string conn_var = fmt::format("connect{}", b + 1);
    std::vector<char> type(MAX_STR_LENGTH + 2, '\0');
    std::int64_t count = 0, npe = 0, edges = 0, faces = 0, attrs = 0;
    f.check(
        ex_get_block(f.id(), EX_ELEM_BLOCK, bid, type.data(), &count, &npe, &edges, &faces, &attrs),
        "the parameters of " + label);
    type.back() = '\0';
    const std::string type_name = type.data();
    if (count < 0 || npe < 0) f.fail(label + " has negative counts");
    const auto solid = solid_of(type_name, npe);
    if (!solid && count == 0) continue; // nothing to number, nothing to reject
    if (!solid)
      f.fail(fmt::format("{} has elements of type {} with {} nodes; anvil reads solids only: "
                         "HEX/HEX8, TETRA/TETRA4, WEDGE/WEDGE6, PYRAMID/PYRAMID5 (and HEX20, "
                         "HEX27, TETRA8, TETRA10, TETRA14, TETRA15, WEDGE15, WEDGE16, WEDGE18, "
                         "PYRAMID13, PYRAMID14 by their corners)",
                         label, type_name.empty() ? "(none)" : type_name, npe));
    fits(count, "elements in " + label);
    fits(count * npe, "connectivity entries in " + label);
    if (count > init.num_elem - elements)
      f.fail(
          fmt::format("the header declares {} elements but the blocks hold more", init.num_elem));
    ElementBlock eb{name, {}, {}};
    eb.ids.assign(element_ids.begin() + elements, element_ids.begin() + elements + count);
    if (count > 0) {
      f.expect_values(conn_var, count * npe, "the connectivity of " + label);
      std::vector<std::int64_t> conn(static_cast<std::size_t>(count * npe));
      f.check(ex_get_conn(f.id(), EX_ELEM_BLOCK, bid, conn.data(), nullptr, nullptr),
              "the connectivity of " + label);
      const int nc = corner_count(*solid);
      for (std::int64_t e = 0; e < count; ++e)
        for (int a = 0; a < nc; ++a) {
          std::int64_t& n = conn[e * npe + a];
          if (n < 1 || n > nn)
            f.fail(fmt::format("{}: element {} (element {} of the block) uses node {}, but the "
                               "file has nodes 1 to {}",
                               label, elements + e + 1, e + 1, n, nn));
          --n; // 0-based from here
        }
      eb.elements.resize(static_cast<std::size_t>(count));
      for (std::int64_t e = 0; e < count; ++e) {
        const std::int64_t* v = &conn[e * npe];
        if (*solid == Shape::hexahedron) {
          Hex numbers; // the file's node numbers, 1-based
          for (int a = 0; a < 8; ++a) numbers[a] = v[a] + 1;
          if (const std::string why = canonical_hex(numbers, eb.ids[e]); !why.empty())
            f.fail(label + ": " + why);
          const Hex given = solid_hex(Shape::hexahedron, v);
          eb.elements[e] = given;
          canonical_hex(eb.elements[e], eb.ids[e]); // the same repeats: the same rewrite
          // A side of a rewritten hexahedron names a face of the file's hexahedron.
          if (eb.elements[e] != given) rewritten.emplace(elements + e, given);
          continue;
        }
        // A tetrahedron, wedge or pyramid names each of its corners once.
        for (int a = 1; a < nc; ++a)
          for (int c = 0; c < a; ++c)
            if (v[a] == v[c])
              f.fail(fmt::format("{}: element {} ({} of type {}) uses node {} twice (corners {} "
                                 "and {})",
                                 label, eb.ids[e], shape_name(*solid), type_name, v[a] + 1, c + 1,
                                 a + 1));
        eb.elements[e] = solid_hex(*solid, v);
      }
    }
    solids.push_back({elements, *solid});
    elements += count;
    mesh.blocks.push_back(std::move(eb));
  }
  if (elements != init.num_elem)
    f.fail(fmt::format("the header declares {} elements but the blocks hold {}", init.num_elem,
                       elements));

  const auto ns_ids = entity_ids(f, EX_NODE_SET, init.num_node_sets, "the node set ids");
  const auto ns_names = entity_names(f, EX_NODE_SET, init.num_node_sets, "the node set names");
  for (std::size_t s = 0; s < ns_ids.size(); ++s) {
    const std::string name =
        ns_names[s].empty() ? fmt::format("nodeset_{}", ns_ids[s]) : ns_names[s];
    const std::string label = fmt::format("node set '{}' (id {})", name, ns_ids[s]);
    std::int64_t count = 0, factors = 0;
    f.check(ex_get_set_param(f.id(), EX_NODE_SET, ns_ids[s], &count, &factors),
            "the size of " + label);
    if (count < 0) f.fail(label + " has a negative size");
    fits(count, "entries in " + label);
    std::vector<std::int64_t> ids(static_cast<std::size_t>(count));
    if (count > 0) {
      f.expect_values(fmt::format("node_ns{}", s + 1), count, label);
      f.check(ex_get_set(f.id(), EX_NODE_SET, ns_ids[s], ids.data(), nullptr), label);
    }
    for (auto& n : ids) {
      if (n < 1 || n > nn)
        f.fail(fmt::format("{} contains node {}, but the file has nodes 1 to {}", label, n, nn));
      --n;
    }
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    if (!mesh.node_sets.emplace(name, std::move(ids)).second)
      f.fail(fmt::format("two node sets are named '{}'", name));
  }

  const auto ss_ids = entity_ids(f, EX_SIDE_SET, init.num_side_sets, "the side set ids");
  const auto ss_names = entity_names(f, EX_SIDE_SET, init.num_side_sets, "the side set names");
  for (std::size_t s = 0; s < ss_ids.size(); ++s) {
    const std::string name =
        ss_names[s].empty() ? fmt::format("sideset_{}", ss_ids[s]) : ss_names[s];
    const std::string label = fmt::format("side set '{}' (id {})", name, ss_ids[s]);
    std::int64_t count = 0, factors = 0;
    f.check(ex_get_set_param(f.id(), EX_SIDE_SET, ss_ids[s], &count, &factors),
            "the size of " + label);
    if (count < 0) f.fail(label + " has a negative size");
    fits(count, "entries in " + label);
    std::vector<std::int64_t> elems(static_cast<std::size_t>(count)), sides(elems.size());
    if (count > 0) {
      f.expect_values(fmt::format("elem_ss{}", s + 1), count, label);
      f.expect_values(fmt::format("side_ss{}", s + 1), count, label);
      f.check(ex_get_set(f.id(), EX_SIDE_SET, ss_ids[s], elems.data(), sides.data()), label);
    }
    std::vector<SideEntry> entries;
    entries.reserve(elems.size());
    for (std::size_t i = 0; i < elems.size(); ++i) {
      if (elems[i] < 1 || elems[i] > elements)
        f.fail(fmt::format("{} refers to element {}, but the file has elements 1 to {}", label,
                           elems[i], elements));
      const std::int64_t e = elems[i] - 1;
      // The block holding e: the last to start at or before it (an empty block starts
      // where the next one does).
      const auto at = std::prev(
          std::upper_bound(solids.begin(), solids.end(), e,
                           [](std::int64_t g, const BlockSolid& bs) { return g < bs.first; }));
      const Shape solid = at->solid;
      if (sides[i] < 1 || sides[i] > side_count(solid))
        f.fail(fmt::format("{} refers to side {} of element {}; a {} has sides 1 to {}", label,
                           sides[i], elems[i], shape_name(solid), side_count(solid)));
      const int side = static_cast<int>(sides[i]);
      int face = side - 1;
      if (solid != Shape::hexahedron) {
        face = side_face(solid, side);
      } else {
        // A hexahedron with repeated nodes: its side must be a face of the solid it is,
        // found by its nodes where canonical_hex renumbered the corners.
        const Hex& h = mesh.blocks[static_cast<std::size_t>(at - solids.begin())]
                           .elements[static_cast<std::size_t>(e - at->first)];
        const auto it = rewritten.find(e);
        if (it != rewritten.end()) {
          const FaceKey key = face_key(it->second, side - 1);
          face = -1;
          for (int g = 0; g < 6 && is_face(key); ++g)
            if (face_key(h, g) == key) face = g;
        } else if (!is_face(face_key(h, face))) {
          face = -1;
        }
        if (face < 0)
          f.fail(fmt::format("{} refers to side {} of element {}, a {} written as a "
                             "hexahedron, whose side {} is none of its faces (it collapses to "
                             "an edge or a point, or spans two faces)",
                             label, side, elems[i], shape_name(shape_of(h)), side));
      }
      entries.push_back({e, face});
    }
    if (!mesh.side_sets.emplace(name, std::move(entries)).second)
      f.fail(fmt::format("two side sets are named '{}'", name));
  }
  return mesh;
}

} // namespace

namespace {

// Reads the file in this process: the path for files whose format anvil validates itself.
Mesh read_here(const std::string& path) {
  try {
    if (const auto problem = classic_netcdf_problem(path); !problem.empty())
      throw InputError(SourceLocation{path, 0, ""}, "not a readable Exodus II file: " + problem);
    if (const auto problem = exodus_attribute_problem(path); !problem.empty())
      throw InputError(SourceLocation{path, 0, ""}, "not a readable Exodus II file: " + problem);
    const ExodusFile f(path);
    // Names longer than the library's default of 32 characters would come back cut.
    // The setting is the library's (per process); raising it is harmless for any other
    // reader, and the cap keeps a corrupt header from asking for absurd buffers.
    const auto used = ex_inquire_int(f.id(), EX_INQ_DB_MAX_USED_NAME_LENGTH);
    if (used > 32)
      ex_set_max_name_length(f.id(), static_cast<int>(std::min<std::int64_t>(used, 255)));
    return read_all(f);
  } catch (const std::bad_alloc&) {
    // Counts in a corrupt header can ask for more memory than there is.
    throw InputError(SourceLocation{path, 0, ""},
                     "the file declares more entities than fit in memory (corrupt header?)");
  } catch (const std::length_error&) {
    throw InputError(SourceLocation{path, 0, ""},
                     "the file declares more entities than fit in memory (corrupt header?)");
  }
}

// A byte stream for the child's answer: a Mesh or an error, length-prefixed fields.
struct Writer {
  std::string out;
  template <class T>
  void pod(const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void str(const std::string& s) {
    pod<std::uint64_t>(s.size());
    out += s;
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    pod<std::uint64_t>(v.size());
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
};

struct Reader {
  std::string_view in;
  bool ok = true;
  template <class T>
  T pod() {
    T v{};
    if (in.size() < sizeof v) {
      ok = false;
      return v;
    }
    std::memcpy(&v, in.data(), sizeof v);
    in.remove_prefix(sizeof v);
    return v;
  }
  std::string str() {
    const auto n = pod<std::uint64_t>();
    if (!ok || n > in.size()) return ok = false, std::string();
    std::string s(in.substr(0, n));
    in.remove_prefix(n);
    return s;
  }
  template <class T>
  std::vector<T> vec() {
    const auto n = pod<std::uint64_t>();
    if (!ok || n > in.size() / sizeof(T)) return ok = false, std::vector<T>();
    std::vector<T> v(n);
    std::memcpy(v.data(), in.data(), n * sizeof(T));
    in.remove_prefix(n * sizeof(T));
    return v;
  }
};

std::string encode(const Mesh& m) {
  Writer w;
  w.pod<char>('M');
  w.vec(m.nodes);
  w.vec(m.node_ids);
  w.pod<std::uint64_t>(m.blocks.size());
  for (const auto& b : m.blocks) {
    w.str(b.name);
    w.vec(b.elements);
    w.vec(b.ids);
  }
  w.pod<std::uint64_t>(m.node_sets.size());
  for (const auto& [name, ids] : m.node_sets) {
    w.str(name);
    w.vec(ids);
  }
  w.pod<std::uint64_t>(m.side_sets.size());
  for (const auto& [name, sides] : m.side_sets) {
    w.str(name);
    w.vec(sides);
  }
  return w.out;
}

std::optional<Mesh> decode(std::string_view bytes) {
  Reader r{bytes};
  Mesh m;
  m.nodes = r.vec<Vec3>();
  m.node_ids = r.vec<std::int64_t>();
  for (auto n = r.pod<std::uint64_t>(); r.ok && n > 0; --n) {
    ElementBlock b;
    b.name = r.str();
    b.elements = r.vec<Hex>();
    b.ids = r.vec<std::int64_t>();
    m.blocks.push_back(std::move(b));
  }
  for (auto n = r.pod<std::uint64_t>(); r.ok && n > 0; --n) {
    auto name = r.str();
    m.node_sets[name] = r.vec<std::int64_t>();
  }
  for (auto n = r.pod<std::uint64_t>(); r.ok && n > 0; --n) {
    auto name = r.str();
    m.side_sets[name] = r.vec<SideEntry>();
  }
  if (!r.ok || !r.in.empty()) return std::nullopt;
  return m;
}

// Reads the file in a child process and returns its mesh or rethrows its InputError. For
// netCDF-4 (HDF5) files, which only the HDF5 library can check: it crashes on corrupt
// files (fuzz/fuzz_exodus found several in seconds), and a crash in the child is an input
// error here. The child uses no MPI and leaves by _exit.
Mesh read_in_child(const std::string& path) {
  int fds[2];
  if (::pipe(fds) != 0) return read_here(path); // no pipe: no isolation, but a reading
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return read_here(path);
  }
  if (pid == 0) {
    ::close(fds[0]);
    // A crash here is the parent's input error: no backtrace from the handlers that MPI
    // (or a sanitizer) installed in the parent.
    for (int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL}) std::signal(sig, SIG_DFL);
    std::string out;
    try {
      out = encode(read_here(path));
    } catch (const InputError& e) {
      // The location and the bare message (what() is "location: message").
      const std::string prefix = e.where().str() + ": ";
      std::string message = e.what();
      if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
      Writer w;
      w.pod<char>('E');
      w.str(e.where().file);
      w.pod<std::int64_t>(e.where().line);
      w.str(e.where().key);
      w.str(message);
      out = w.out;
    } catch (...) {
      Writer w;
      w.pod<char>('E');
      w.str(path);
      w.pod<std::int64_t>(0);
      w.str("");
      w.str("the file cannot be read");
      out = w.out;
    }
    for (std::size_t done = 0; done < out.size();) {
      const auto n = ::write(fds[1], out.data() + done, out.size() - done);
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string in;
  char buf[65536];
  for (;;) {
    const auto n = ::read(fds[0], buf, sizeof buf);
    if (n > 0) {
      in.append(buf, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const SourceLocation where{path, 0, ""};
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw InputError(
        where, fmt::format("not a readable Exodus II file: the netCDF-4/HDF5 library "
                           "failed on it ({}); the file is corrupt",
                           WIFSIGNALED(status) ? strsignal(WTERMSIG(status)) : "abnormal exit"));
  if (!in.empty() && in[0] == 'E') {
    Reader r{std::string_view(in).substr(1)};
    SourceLocation at;
    at.file = r.str();
    at.line = static_cast<int>(r.pod<std::int64_t>());
    at.key = r.str();
    const std::string message = r.str();
    if (r.ok) throw InputError(at, message);
    throw InputError(where, "not a readable Exodus II file (its reading ended early)");
  }
  std::optional<Mesh> m;
  if (!in.empty() && in[0] == 'M') m = decode(std::string_view(in).substr(1));
  if (!m) throw InputError(where, "not a readable Exodus II file (its reading ended early)");
  return std::move(*m);
}

// Whether the file carries the HDF5 signature where the HDF5 library looks for it (at 0,
// 512, 1024, 2048, ... bytes): a netCDF-4 file, read by the HDF5 library.
// The path is a regular file (read_exodus checks it first): its size is its length, not
// the nonsense a directory's stream reports.
bool is_hdf5(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::int64_t>(in.tellg());
  static constexpr char signature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  for (std::int64_t at = 0; size >= 8 && at <= size - 8; at = at == 0 ? 512 : 2 * at) {
    char magic[8] = {};
    in.seekg(at);
    if (in.read(magic, 8) && std::memcmp(magic, signature, 8) == 0) return true;
  }
  return false;
}

} // namespace

Mesh read_exodus(const std::string& path) {
  expect_regular_file(path, "mesh file");
  return is_hdf5(path) ? read_in_child(path) : read_here(path);
}

} // namespace anvil
