// Mesh file readers (Exodus II, Gmsh MSH): the 2x2x2 box of tests/data/meshes in every
// format reads to the same mesh, sets and faces mean what they say, every kind of bad
// input is an InputError (exit status 2 from `anvil check`), never a crash.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <exodusII.h>
#include <fmt/format.h>

#include "anvil/core/error.hpp"
#include "anvil/mesh/mesh.hpp"
#include "anvil/mesh/read_exodus.hpp"
#include "anvil/mesh/read_gmsh.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;
namespace fs = std::filesystem;

std::string data(const std::string& file) {
  return std::string(test::source_dir()) + "/tests/data/meshes/" + file;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

// A fresh directory for one test (tests may run in parallel), removed at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = fs::temp_directory_path() /
           fmt::format("anvil_{}_{}_{}", info->test_suite_name(), info->name(), ::getpid());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

std::array<Vec3, 8> corners(const Mesh& m, const Hex& h) {
  std::array<Vec3, 8> x;
  for (int a = 0; a < 8; ++a) x[a] = m.nodes[h[a]];
  return x;
}

// The box [0,2] x [0,1] x [0,3] in 2x2x2 hexahedra: counts, positive volumes summing to
// the box's.
void expect_box(const Mesh& m) {
  ASSERT_EQ(m.num_nodes(), 27);
  ASSERT_EQ(m.num_elements(), 8);
  double total = 0;
  for (const auto& b : m.blocks)
    for (const auto& h : b.elements) {
      const double v = hex_volume(corners(m, h));
      EXPECT_NEAR(v, 0.75, 1e-9);
      total += v;
    }
  EXPECT_LT(test::relative_error(total, 6.0), 1e-12);
}

// Ids of the nodes satisfying `pred`, sorted.
std::vector<std::int64_t> nodes_where(const Mesh& m, const std::function<bool(const Vec3&)>& pred) {
  std::vector<std::int64_t> out;
  for (std::int64_t i = 0; i < m.num_nodes(); ++i)
    if (pred(m.nodes[i])) out.push_back(i);
  return out;
}

bool near(double a, double b) {
  return std::abs(a - b) < 1e-9;
}

// Element `e` (global id) of the mesh.
const Hex& element(const Mesh& m, std::int64_t e) {
  for (const auto& b : m.blocks) {
    if (e < static_cast<std::int64_t>(b.elements.size())) return b.elements[e];
    e -= static_cast<std::int64_t>(b.elements.size());
  }
  throw std::out_of_range("element");
}

// The outward normal (right-hand rule over hex_faces) of a face, not normalised.
Vec3 face_normal(const Mesh& m, const SideEntry& s) {
  const auto& h = element(m, s.element);
  const auto& f = hex_faces[s.face];
  const Vec3 a = m.nodes[h[f[2]]] - m.nodes[h[f[0]]];
  const Vec3 b = m.nodes[h[f[3]]] - m.nodes[h[f[1]]];
  return cross(a, b);
}

// ---------------------------------------------------------------------------------------
// Exodus II

// A generated mesh (no file ids: id = position + 1) followed by a file's (ids kept): the
// ids of both, in order. (append_nodes read past its id list for the generated nodes
// after the first, AddressSanitizer found; QA round 25's side-set test met it.)
TEST(Mesh, AppendingAFilesIdsAfterGeneratedNodes) {
  Mesh generated, file;
  generated.nodes = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  file.nodes = {{5, 0, 0}, {6, 0, 0}};
  file.node_ids = {70, 40};
  generated.append(file, "f");
  EXPECT_EQ(generated.node_ids, (std::vector<std::int64_t>{1, 2, 3, 70, 40}));
}

TEST(ReadExodus, BoxBlocksSetsAndSides) {
  const Mesh m = read_exodus(data("box_2x2x2.exo"));
  expect_box(m);
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_EQ(m.blocks[0].name, "lower");    // named in the file
  EXPECT_EQ(m.blocks[1].name, "block_20"); // unnamed: block_<id>
  // The file's element order and node order (1-based positions, not the id map).
  EXPECT_EQ(m.blocks[0].elements[0], (Hex{0, 1, 4, 3, 9, 10, 13, 12}));
  EXPECT_EQ(m.blocks[1].elements[3], (Hex{13, 14, 17, 16, 22, 23, 26, 25}));
  // The file's element ids (elem_num_map), for messages.
  EXPECT_EQ(m.blocks[0].ids, (std::vector<std::int64_t>{500, 499, 498, 497}));
  EXPECT_EQ(m.blocks[1].ids, (std::vector<std::int64_t>{496, 495, 494, 493}));

  ASSERT_EQ(m.node_sets.size(), 2u);
  EXPECT_EQ(m.node_sets.at("bottom"), nodes_where(m, [](const Vec3& x) { return near(x[2], 0); }));
  EXPECT_EQ(m.node_sets.at("nodeset_7"), (std::vector<std::int64_t>{18, 26}));

  ASSERT_EQ(m.side_sets.size(), 2u);
  const auto& top = m.side_sets.at("top");
  ASSERT_EQ(top.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(top[i].element, static_cast<std::int64_t>(4 + i));
    EXPECT_EQ(top[i].face, 5);
    // Side 6 of the upper elements is on z = 3 with its normal along +z.
    for (int a : hex_faces[5]) EXPECT_TRUE(near(m.nodes[element(m, 4 + i)[a]][2], 3.0));
    const Vec3 n = face_normal(m, top[i]);
    EXPECT_GT(n[2], 0);
    EXPECT_NEAR(n[0], 0, 1e-12);
  }
  const auto& misc = m.side_sets.at("sideset_4");
  ASSERT_EQ(misc.size(), 2u);
  EXPECT_EQ(misc[0].element, 0);
  EXPECT_EQ(misc[0].face, 0); // side 1: y = 0, normal -y
  EXPECT_LT(face_normal(m, misc[0])[1], 0);
  EXPECT_EQ(misc[1].element, 2);
  EXPECT_EQ(misc[1].face, 3); // side 4: x = 0, normal -x
  EXPECT_LT(face_normal(m, misc[1])[0], 0);
}

TEST(ReadExodus, ClassicAndNetcdf4FilesReadTheSame) {
  const Mesh ref = read_exodus(data("box_2x2x2.exo"));
  for (const char* f : {"box_2x2x2_cdf1.exo", "box_2x2x2_nc4.exo"}) {
    SCOPED_TRACE(f);
    const Mesh m = read_exodus(data(f));
    expect_box(m);
    ASSERT_EQ(m.blocks.size(), ref.blocks.size());
    for (std::size_t b = 0; b < m.blocks.size(); ++b) {
      EXPECT_EQ(m.blocks[b].name, ref.blocks[b].name);
      EXPECT_EQ(m.blocks[b].elements, ref.blocks[b].elements);
      EXPECT_EQ(m.blocks[b].ids, ref.blocks[b].ids);
    }
    EXPECT_EQ(m.node_sets, ref.node_sets);
    EXPECT_EQ(m.side_sets.size(), ref.side_sets.size());
  }
}

TEST(ReadExodus, Hex20ByItsCorners) {
  const Mesh m = read_exodus(data("hex20.exo"));
  EXPECT_EQ(m.num_nodes(), 20); // mid-edge nodes stay, unused
  ASSERT_EQ(m.num_elements(), 1);
  EXPECT_EQ(m.blocks[0].elements[0], (Hex{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_NEAR(hex_volume(corners(m, m.blocks[0].elements[0])), 1.0, 1e-14);
  // Names beyond Exodus's default length of 32 come back whole.
  EXPECT_EQ(m.node_sets.at("bottom_face_of_the_cube_with_a_long_set_name"),
            (std::vector<std::int64_t>{0, 1, 2, 3, 8, 9, 10, 11}));
}

// Expects read_exodus(path) to throw an InputError whose message has every fragment.
void expect_exodus_error(const std::string& path, const std::vector<std::string>& fragments) {
  try {
    read_exodus(path);
    ADD_FAILURE() << path << ": no error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.where().file, path);
    for (const auto& f : fragments)
      EXPECT_NE(msg.find(f), std::string::npos) << msg << "\n  lacks: " << f;
  }
}

TEST(ReadExodus, BadContentNamesWhatIsWrong) {
  expect_exodus_error(data("bad_tet_block.exo"), {"block_20", "id 20", "TETRA", "hexahedra only"});
  expect_exodus_error(data("bad_node_range.exo"), {"block_20", "element 5", "node 28", "1 to 27"});
  expect_exodus_error(data("bad_nodeset_range.exo"), {"node set 'bottom'", "node 0"});
  expect_exodus_error(data("bad_side_range.exo"), {"side set 'top'", "side 7", "sides 1 to 6"});
  expect_exodus_error(data("bad_elem_range.exo"), {"side set 'top'", "element 9", "1 to 8"});
  expect_exodus_error(data("bad_2d.exo"), {"2-dimensional"});
  // A repeated node is refused as in .k and .msh files, naming the element's id.
  expect_exodus_error(data("bad_degenerate_hex.exo"),
                      {"element block 'lower'", "element 500 uses node 13 twice (N7 and N8)",
                       "degenerate hexahedra"});
}

// Defects the Exodus library does not survive by itself (it writes past fixed-size
// buffers, or past anvil's: found by fuzz/fuzz_exodus and by reading the library's use of
// netCDF): caught before it reads.
TEST(ReadExodus, CorruptShapesAndAttributesAreInputErrors) {
  expect_exodus_error(data("bad_set_shape.exo"),
                      {"side set 'top'", "elem_ss1 holds 4 values", "counts give 2"});
  expect_exodus_error(data("bad_attr_array.exo"), {"maximum_name_length has 100 values"});
  expect_exodus_error(data("bad_int64_status.exo"), {"int64_status has 200 values"});
  expect_exodus_error(data("bad_elem_type.exo"), {"element type of connect1", "3000 characters"});
}

// netCDF-4 files are read by the HDF5 library, which frees uninitialised pointers in
// corrupt files (bad_hdf5.exo, found by fuzz/fuzz_exodus): read_exodus reads them in a
// child process, so that whatever the library does is an input error for anvil.
TEST(ReadExodus, CorruptHdf5IsAnInputError) {
  expect_exodus_error(data("bad_hdf5.exo"), {"bad_hdf5.exo"});
  const Mesh m = read_exodus(data("box_2x2x2_nc4.exo")); // and a good one reads in the child
  EXPECT_EQ(m.num_elements(), 8);
  EXPECT_EQ(m.node_sets.size(), 2u);
  EXPECT_EQ(m.side_sets.size(), 2u);
}

TEST(ReadExodus, UnreadableFilesAreInputErrors) {
  TempDir dir;
  const std::string good = slurp(data("box_2x2x2.exo"));
  ASSERT_GT(good.size(), 1000u);
  expect_exodus_error(dir.file("missing.exo"), {"cannot open"});
  write(dir.path / "empty.exo", "");
  expect_exodus_error(dir.file("empty.exo"), {});
  std::mt19937 rng(7);
  std::string garbage(4096, '\0');
  for (auto& c : garbage) c = static_cast<char>(rng());
  write(dir.path / "garbage.exo", garbage);
  expect_exodus_error(dir.file("garbage.exo"), {});
  // A Gmsh file under an Exodus name.
  write(dir.path / "text.exo", slurp(data("box_2x2x2.msh")));
  expect_exodus_error(dir.file("text.exo"), {"cannot open"});
  for (std::size_t len : {std::size_t{4}, std::size_t{100}, good.size() / 2, good.size() - 8}) {
    SCOPED_TRACE(len);
    write(dir.path / "truncated.exo", good.substr(0, len));
    expect_exodus_error(dir.file("truncated.exo"), {});
  }
}

// A directory named like a mesh file (some tools write `model.exo` directories for
// decomposed sets): an input error naming it, not a hang on its nonsense size (QA round 13).
TEST(ReadExodus, DirectoryIsAnInputError) {
  TempDir dir;
  for (const char* name : {"model.exo", "model.e"}) {
    fs::create_directories(dir.path / name);
    expect_exodus_error(dir.file(name), {"is a directory, not a mesh file"});
  }
}

// One unit-cube hexahedron as an Exodus II file with the given id maps.
void write_one_hex(const std::string& path, const std::vector<std::int64_t>& node_map,
                   const std::vector<std::int64_t>& elem_map) {
  int cws = 8, iows = 8;
  const int id = ex_create(path.c_str(), EX_CLOBBER | EX_ALL_INT64_API, &cws, &iows);
  ASSERT_GE(id, 0);
  ASSERT_EQ(ex_put_init(id, "one hex", 3, 8, 1, 1, 0, 0), 0);
  const std::vector<double> x{0, 1, 1, 0, 0, 1, 1, 0}, y{0, 0, 1, 1, 0, 0, 1, 1},
      z{0, 0, 0, 0, 1, 1, 1, 1};
  ASSERT_EQ(ex_put_coord(id, x.data(), y.data(), z.data()), 0);
  ASSERT_EQ(ex_put_block(id, EX_ELEM_BLOCK, 1, "HEX8", 1, 8, 0, 0, 0), 0);
  const std::int64_t conn[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  ASSERT_EQ(ex_put_conn(id, EX_ELEM_BLOCK, 1, conn, nullptr, nullptr), 0);
  ASSERT_EQ(ex_put_id_map(id, EX_NODE_MAP, node_map.data()), 0);
  ASSERT_EQ(ex_put_id_map(id, EX_ELEM_MAP, elem_map.data()), 0);
  ex_close(id);
}

// Exodus ids are positive, and the outputs carry them: an id <= 0 in an id map is refused
// as keyword and Gmsh input refuse it, naming the map, the entity and the id.
TEST(ReadExodus, NonPositiveMapIdsAreRefused) {
  TempDir dir;
  const std::vector<std::int64_t> nodes{11, 12, 13, 14, 15, 16, 17, 18};
  write_one_hex(dir.file("good.exo"), nodes, {7});
  const Mesh m = read_exodus(dir.file("good.exo"));
  EXPECT_EQ(m.node_ids, nodes);
  EXPECT_EQ(m.blocks.at(0).ids, (std::vector<std::int64_t>{7}));
  write_one_hex(dir.file("neg_node.exo"), {11, -5, 13, 14, 15, 16, 17, 18}, {7});
  expect_exodus_error(dir.file("neg_node.exo"),
                      {"node_num_map", "node 2", "id -5", "ids must be positive"});
  write_one_hex(dir.file("zero_node.exo"), {11, 12, 13, 14, 15, 16, 17, 0}, {7});
  expect_exodus_error(dir.file("zero_node.exo"), {"node_num_map", "node 8", "id 0"});
  write_one_hex(dir.file("neg_elem.exo"), nodes, {-7});
  expect_exodus_error(dir.file("neg_elem.exo"),
                      {"elem_num_map", "element 1", "id -7", "ids must be positive"});
}

// Corrupt bytes anywhere in an Exodus file: an InputError or a mesh, never a crash or
// the gigabyte allocations that netCDF makes from a corrupt header.
TEST(ReadExodus, MutatedFilesParseOrThrowInputError) {
  TempDir dir;
  for (const char* source : {"box_2x2x2.exo", "box_2x2x2_cdf1.exo"}) {
    const std::string good = slurp(data(source));
    std::mt19937 rng(20240601);
    int parsed = 0, rejected = 0;
    for (int v = 0; v < 150; ++v) {
      std::string s = good;
      const int flips = 1 + v % 4;
      for (int k = 0; k < flips; ++k) s[rng() % s.size()] = static_cast<char>(rng());
      write(dir.path / "mutated.exo", s);
      try {
        const Mesh m = read_exodus(dir.file("mutated.exo"));
        for (const auto& b : m.blocks)
          for (const auto& h : b.elements)
            for (auto n : h) ASSERT_TRUE(n >= 0 && n < m.num_nodes());
        ++parsed;
      } catch (const InputError&) {
        ++rejected;
      } catch (const std::exception& e) {
        ADD_FAILURE() << source << " variant " << v << ": " << e.what();
      }
    }
    EXPECT_GT(parsed, 0) << source;
    EXPECT_GT(rejected, 0) << source;
  }
}

// ---------------------------------------------------------------------------------------
// Gmsh

void expect_gmsh_box_sets(const Mesh& m) {
  auto set = [&](const std::function<bool(const Vec3&)>& p) { return nodes_where(m, p); };
  EXPECT_EQ(m.node_sets.at("bottom"), set([](const Vec3& x) { return near(x[2], 0); }));
  EXPECT_EQ(m.node_sets.at("top"), set([](const Vec3& x) { return near(x[2], 3); }));
  EXPECT_EQ(m.node_sets.at("edge"),
            set([](const Vec3& x) { return near(x[1], 0) && near(x[2], 0); }));
  EXPECT_EQ(m.node_sets.at("origin"),
            set([](const Vec3& x) { return near(x[0], 0) && near(x[1], 0) && near(x[2], 0); }));
  EXPECT_EQ(m.node_sets.at("lower"), set([](const Vec3& x) { return x[2] < 1.5 + 1e-9; }));
  EXPECT_EQ(m.node_sets.at("upper"), set([](const Vec3& x) { return x[2] > 1.5 - 1e-9; }));
  EXPECT_EQ(m.node_sets.size(), 6u);
  EXPECT_EQ(m.node_sets.at("origin").size(), 1u);
  EXPECT_EQ(m.node_sets.at("edge").size(), 3u);
  EXPECT_EQ(m.node_sets.at("top").size(), 9u);
  EXPECT_TRUE(m.side_sets.empty());
}

TEST(ReadGmsh, Box41BlocksPerVolumeGroupAndNodeSets) {
  const Mesh m = read_gmsh(data("box_2x2x2.msh"));
  expect_box(m);
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_EQ(m.blocks[0].name, "lower");
  EXPECT_EQ(m.blocks[1].name, "upper");
  EXPECT_EQ(m.blocks[0].elements.size(), 4u);
  for (const auto& h : m.blocks[0].elements)
    for (auto n : h) EXPECT_LE(m.nodes[n][2], 1.5 + 1e-9);
  // Gmsh tags are 1-based and in file order here: element 12 is nodes 1 13 25 16 5 17 26 20.
  EXPECT_EQ(m.blocks[0].elements[0], (Hex{0, 12, 24, 15, 4, 16, 25, 19}));
  expect_gmsh_box_sets(m);
}

// A UTF-8 byte-order mark (some Windows editors write one) is skipped, as in keyword files.
TEST(ReadGmsh, ByteOrderMarkIsSkipped) {
  const Mesh ref = parse_gmsh(slurp(data("box_2x2x2.msh")), "box.msh");
  const Mesh m = parse_gmsh("\xEF\xBB\xBF" + slurp(data("box_2x2x2.msh")), "box.msh");
  expect_box(m);
  EXPECT_EQ(m.node_ids, ref.node_ids);
  EXPECT_EQ(m.node_sets, ref.node_sets);
  // Only at the start of the file.
  try {
    parse_gmsh("\n\xEF\xBB\xBF" + slurp(data("box_2x2x2.msh")), "box.msh");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("box.msh:2"), std::string::npos) << e.what();
  }
}

// A directory named like a mesh file is named as one, not as an empty file.
TEST(ReadGmsh, DirectoryIsAnInputError) {
  TempDir dir;
  fs::create_directories(dir.path / "model.msh");
  try {
    read_gmsh(dir.file("model.msh"));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, dir.file("model.msh"));
    EXPECT_NE(std::string(e.what()).find("is a directory, not a mesh file"), std::string::npos)
        << e.what();
  }
}

TEST(ReadGmsh, Box22ReadsLike41) {
  const Mesh a = read_gmsh(data("box_2x2x2.msh"));
  const Mesh b = read_gmsh(data("box_2x2x2_v22.msh"));
  expect_box(b);
  ASSERT_EQ(b.blocks.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(b.blocks[i].name, a.blocks[i].name);
    EXPECT_EQ(b.blocks[i].elements, a.blocks[i].elements);
  }
  expect_gmsh_box_sets(b);
  EXPECT_EQ(a.node_sets, b.node_sets);
}

// Gmsh's hexahedron is Exodus's: every face of hex_faces has its normal pointing out of
// the element (away from its centre).
TEST(ReadGmsh, HexNodeOrderMatchesHexFaces) {
  const Mesh m = read_gmsh(data("box_2x2x2.msh"));
  for (std::int64_t e = 0; e < m.num_elements(); ++e) {
    const auto x = corners(m, element(m, e));
    Vec3 c{};
    for (const auto& p : x) c += p * 0.125;
    for (int f = 0; f < 6; ++f) {
      Vec3 fc{};
      for (int a : hex_faces[f]) fc += x[a] * 0.25;
      EXPECT_GT(dot(face_normal(m, {e, f}), fc - c), 0) << "element " << e << " face " << f;
    }
  }
}

// A minimal MSH 4.1 file: one volume entity with the given physical tags (space
// separated, may be empty) holding one unit hexahedron; `names` is the $PhysicalNames
// body (without the count line), `count` its line count.
std::string one_hex_41(const std::string& phys, int nphys, const std::string& names = "",
                       int count = 0) {
  std::string s = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  if (count > 0) s += fmt::format("$PhysicalNames\n{}\n{}$EndPhysicalNames\n", count, names);
  s += fmt::format("$Entities\n0 0 0 1\n7 0 0 0 1 1 1 {} {} 0\n$EndEntities\n", nphys, phys);
  s += "$Nodes\n1 8 1 8\n3 7 0 8\n1\n2\n3\n4\n5\n6\n7\n8\n"
       "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n$EndNodes\n";
  s += "$Elements\n1 1 1 1\n3 7 5 1\n1 1 2 3 4 5 6 7 8\n$EndElements\n";
  return s;
}

TEST(ReadGmsh, UnnamedGroupsAndNoGroup) {
  {
    const Mesh m = parse_gmsh(one_hex_41("", 0), "none.msh");
    ASSERT_EQ(m.blocks.size(), 1u);
    EXPECT_EQ(m.blocks[0].ids, std::vector<std::int64_t>{1}); // the element's tag
    EXPECT_EQ(m.blocks[0].name, "mesh");
    EXPECT_TRUE(m.node_sets.empty());
  }
  {
    const Mesh m = parse_gmsh(one_hex_41("9", 1), "unnamed.msh");
    ASSERT_EQ(m.blocks.size(), 1u);
    EXPECT_EQ(m.blocks[0].name, "volume_9");
    EXPECT_EQ(m.node_sets.at("volume_9").size(), 8u);
  }
  {
    // Two 3-D groups on one volume: the element once, in the lowest tag's block.
    const Mesh m =
        parse_gmsh(one_hex_41("4 2", 2, "3 2 \"steel part\"\n3 4 \"all\"\n", 2), "two.msh");
    ASSERT_EQ(m.num_elements(), 1);
    EXPECT_EQ(m.blocks[0].name, "steel part");
    EXPECT_EQ(m.node_sets.at("all").size(), 8u);
    EXPECT_EQ(m.node_sets.at("steel part").size(), 8u);
  }
}

// MSH 2 writes an element once per physical group: the copies are one element.
TEST(ReadGmsh, Msh22DuplicatesAreOneElement) {
  const std::string text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                           "$PhysicalNames\n2\n3 1 \"a\"\n3 2 \"b\"\n$EndPhysicalNames\n"
                           "$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
                           "5 0 0 1\n6 1 0 1\n7 1 1 1\n8 0 1 1\n$EndNodes\n"
                           "$Elements\n3\n1 5 2 1 1 1 2 3 4 5 6 7 8\n"
                           "2 5 2 2 1 1 2 3 4 5 6 7 8\n3 15 2 0 1 1\n$EndElements\n";
  const Mesh m = parse_gmsh(text, "dup.msh");
  ASSERT_EQ(m.num_elements(), 1);
  EXPECT_EQ(m.blocks[0].name, "a");
  EXPECT_EQ(m.node_sets.at("a").size(), 8u);
  EXPECT_EQ(m.node_sets.at("b").size(), 8u);
}

struct Case {
  const char* what;
  std::string text;
  std::vector<std::string> fragments; // all must appear in the message
};

// Variants of the valid 4.1 box, each wrong in one way.
std::vector<Case> malformed_gmsh() {
  const std::string good = slurp(data("box_2x2x2.msh"));
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    if (pos != std::string::npos) s.replace(pos, from.size(), to);
    return s;
  };
  const auto nodes_at = good.find("$Nodes");
  const auto elements_at = good.find("$Elements");
  // The text up to the end of the line that holds byte `at`.
  auto cut = [&](std::size_t at) { return good.substr(0, good.find('\n', at) + 1); };
  std::string garbage(2000, '\0');
  std::mt19937 rng(3);
  for (auto& c : garbage) c = static_cast<char>(rng());
  return {
      {"empty file", "", {"m.msh", "empty"}},
      {"blank file", "\n  \n\n", {"empty"}},
      {"binary garbage", garbage, {"m.msh:"}},
      {"no $MeshFormat", good.substr(good.find("$PhysicalNames")), {"m.msh:1:", "$MeshFormat"}},
      {"binary MSH", replace("4.1 0 8", "4.1 1 8"), {"m.msh:2:", "binary"}},
      {"version 4.0", replace("4.1 0 8", "4.0 0 8"), {"m.msh:2:", "version 4.0"}},
      {"truncated in $Nodes", cut(nodes_at + 200), {"$Nodes", "ends early"}},
      {"truncated in $Elements", cut(elements_at + 60), {"$Elements", "ends early"}},
      {"truncated before $EndElements",
       good.substr(0, good.find("$EndElements")),
       {"ends early", "$EndElements"}},
      {"missing $Elements", good.substr(0, elements_at), {"no $Elements"}},
      {"missing $Nodes",
       good.substr(0, nodes_at) + good.substr(elements_at),
       {"$Elements must come after $Nodes"}},
      {"missing $Entities",
       good.substr(0, good.find("$Entities")) + good.substr(nodes_at),
       {"$Entities must come before $Nodes"}},
      {"node count too large",
       replace("$Nodes\n29 27 1 27", "$Nodes\n29 28 1 28"),
       {"m.msh:", "28 nodes are declared"}},
      {"node count too small",
       replace("$Nodes\n29 27 1 27", "$Nodes\n29 26 1 27"),
       {"more than the 26 nodes"}},
      {"element count wrong",
       replace("$Elements\n6 19 1 19", "$Elements\n6 20 1 20"),
       {"20 elements are declared"}},
      {"too many entity blocks",
       replace("$Elements\n6 19 1 19", "$Elements\n7 19 1 19"),
       {"m.msh:", "$Elements"}},
      {"bad coordinate",
       replace("0.9999999999973842 0 0", "0.99999x9999973842 0 0"),
       {"m.msh:", "$Nodes", "x must be a finite number", "0.99999x"}},
      {"non-finite coordinate", replace("0.9999999999973842 0 0", "nan 0 0"), {"finite"}},
      {"missing coordinate",
       replace("0.9999999999973842 0 0", "0.9999999999973842 0"),
       {"expected node coordinates (3 values), found 2"}},
      {"bad integer",
       replace("3 1 5 4\n12 ", "3 1 5 4\n1x2 "),
       {"$Elements", "element tag must be an integer"}},
      {"unknown element type", replace("3 1 5 4", "3 1 99 4"), {"unknown element type 99"}},
      {"tetrahedra in a volume",
       replace("3 2 5 4\n16 5 17 26 20 9 21 27 24", "3 2 4 4\n16 5 17 26 20"),
       {"m.msh:169:", "volume 2 (physical volume 'upper')", "4-node tetrahedron", "type 4"}},
      {"hexahedron in a surface", replace("2 1 3 4", "2 1 5 4"), {"type 5) in surface 1"}},
      {"degenerate hexahedron",
       replace("12 1 13 25 16 5 17 26 20", "12 1 13 25 16 5 17 26 26"),
       {"m.msh:", "$Elements", "element 12 uses node 26 twice (N7 and N8)", "degenerate"}},
      {"undefined node",
       replace("12 1 13 25 16 5 17 26 20", "12 1 13 25 16 5 17 26 99"),
       {"node 99 is not defined"}},
      {"node count per element",
       replace("12 1 13 25 16 5 17 26 20", "12 1 13 25 16 5 17 26"),
       {"expected an element: tag and node tags (9 values), found 8"}},
      {"duplicate node tag", replace("\n13\n0.99", "\n12\n0.99"), {"node 12 is defined twice"}},
      {"duplicate element",
       replace("13 16 25 15 4 20 26 19 8", "12 16 25 15 4 20 26 19 8"),
       {"element 12 is defined twice"}},
      {"undefined entity", replace("3 2 5 4", "3 9 5 4"), {"volume 9 is not defined in $Entities"}},
      {"negative count", replace("$Nodes\n29 27 1 27", "$Nodes\n-29 27 1 27"), {"negative"}},
      {"huge count",
       replace("$Nodes\n29 27 1 27", "$Nodes\n29 9000000000000000000 1 27"),
       {"more than the file can hold"}},
      {"unquoted name", replace("\"origin\"", "origin"), {"double quotes"}},
      {"duplicate physical name",
       replace("\"upper\"", "\"lower\""),
       {"m.msh:11:", "both named 'lower'"}},
      {"unclosed section", good + "$Comments\nhello\n", {"$Comments is not closed"}},
      {"stray text",
       replace("$EndPhysicalNames\n", "$EndPhysicalNames\nhello\n"),
       {"m.msh:13:", "section header"}},
      {"records after the count", replace("$EndNodes", "1\n$EndNodes"), {"expected $EndNodes"}},
      {"partitioned",
       replace("$Nodes\n", "$PartitionedEntities\n$EndPartitionedEntities\n$Nodes\n"),
       {"partitioned"}},
      {"entity record short", replace("1 0 0 0 1 6 \n", "1 0 0 0 2 6 \n"), {"physical tags"}},
  };
}

TEST(ReadGmsh, MalformedInputNamesFileLineAndProblem) {
  for (const auto& c : malformed_gmsh()) {
    SCOPED_TRACE(c.what);
    try {
      parse_gmsh(c.text, "m.msh");
      ADD_FAILURE() << c.what << ": no error";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(e.where().file, "m.msh");
      for (const auto& f : c.fragments)
        EXPECT_NE(msg.find(f), std::string::npos) << msg << "\n  lacks: " << f;
    }
  }
}

TEST(ReadGmsh, NoHexahedraIsAnError) {
  std::string text = one_hex_41("", 0);
  text.replace(text.find("3 7 5 1\n1 1 2 3 4 5 6 7 8"), 25, "3 7 5 0");
  text.replace(text.find("$Elements\n1 1 1 1"), 17, "$Elements\n1 0 0 0");
  try {
    parse_gmsh(text, "flat.msh");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no hexahedra"), std::string::npos) << e.what();
  }
}

// Fuzz-style: deterministic random damage to the valid text (byte flips, digit changes,
// truncations, deleted and repeated lines). Every variant parses or throws InputError.
TEST(ReadGmsh, MutatedTextParsesOrThrowsInputError) {
  for (const char* source : {"box_2x2x2.msh", "box_2x2x2_v22.msh"}) {
    const std::string good = slurp(data(source));
    std::mt19937 rng(12345);
    int parsed = 0, rejected = 0;
    for (int v = 0; v < 400; ++v) {
      std::string s = good;
      switch (v % 5) {
      case 0: // random bytes
        for (int k = 0, n = 1 + static_cast<int>(rng() % 6); k < n; ++k)
          s[rng() % s.size()] = static_cast<char>(rng());
        break;
      case 1: // a digit becomes another digit or a sign: counts, tags and ids go wrong
        for (int k = 0; k < 3; ++k) {
          const auto p = rng() % s.size();
          if (std::isdigit(static_cast<unsigned char>(s[p]))) s[p] = "0123456789-"[rng() % 11];
        }
        break;
      case 2: // truncation
        s.resize(rng() % s.size());
        break;
      case 3: { // a line deleted
        const auto p = s.find('\n', rng() % s.size());
        if (p != std::string::npos) {
          const auto q = s.find('\n', p + 1);
          s.erase(p, q == std::string::npos ? std::string::npos : q - p);
        }
        break;
      }
      case 4: { // a line repeated
        const auto p = s.find('\n', rng() % s.size());
        if (p != std::string::npos) {
          const auto q = s.find('\n', p + 1);
          if (q != std::string::npos) s.insert(p, s.substr(p, q - p));
        }
        break;
      }
      }
      try {
        const Mesh m = parse_gmsh(s, "fuzz.msh");
        for (const auto& b : m.blocks)
          for (const auto& h : b.elements)
            for (auto n : h) ASSERT_TRUE(n >= 0 && n < m.num_nodes());
        for (const auto& [name, ids] : m.node_sets)
          for (auto n : ids) ASSERT_TRUE(n >= 0 && n < m.num_nodes());
        ++parsed;
      } catch (const InputError& e) {
        ASSERT_EQ(e.where().file, "fuzz.msh");
        ++rejected;
      } catch (const std::exception& e) {
        ADD_FAILURE() << source << " variant " << v << ": not an InputError: " << e.what();
      }
    }
    EXPECT_GT(parsed, 0) << source;
    EXPECT_GT(rejected, 100) << source;
  }
}

// ---------------------------------------------------------------------------------------
// Through the deck: `anvil check` reads the files, prints the counts, exits 2 on bad ones.

struct CheckRun {
  int status;
  std::string output; // stdout and stderr
};

CheckRun anvil_check(const std::string& deck) {
  const std::string cmd = fmt::format("'{}' check '{}' 2>&1", test::anvil_binary(), deck);
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return {-1, "popen failed"};
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int raw = ::pclose(p);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw), out};
}

std::string deck_for(const std::string& mesh_file, const std::string& set) {
  return fmt::format(R"(title: reader check
termination: {{cycles: 1}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  box:
    mesh: {{file: {}}}
    material: steel
boundary_conditions:
  - {{set: {}, fix: all}}
)",
                     mesh_file, set);
}

TEST(ReadersDeck, CheckReadsExodusAndGmsh) {
  TempDir dir;
  for (const char* f : {"box_2x2x2.exo", "box_2x2x2.msh", "box_2x2x2_v22.msh"}) {
    SCOPED_TRACE(f);
    // A relative path resolves against the deck's directory.
    fs::copy_file(data(f), dir.path / f);
    const std::string set = std::string(f).ends_with(".exo") ? "box.nodeset_7" : "box.top";
    write(dir.path / "deck.yaml", deck_for(f, set));
    const CheckRun r = anvil_check(dir.file("deck.yaml"));
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("nodes       27\n"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("elements    8\n"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("mass 47100 kg"), std::string::npos) << r.output; // 7850 * 6 m^3
    EXPECT_NE(r.output.find("deck and mesh are valid"), std::string::npos) << r.output;
  }
}

// A set a file part does not have: the error lists the sets its file gave it (QA round
// 16: it listed none, where a generated part's error lists its own).
TEST(ReadersDeck, UnknownSetOfAFilePartListsItsSets) {
  TempDir dir;
  fs::copy_file(data("box_2x2x2.msh"), dir.path / "box_2x2x2.msh");
  write(dir.path / "deck.yaml", deck_for("box_2x2x2.msh", "box.nope"));
  const CheckRun r = anvil_check(dir.file("deck.yaml"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("node set 'box.nope' is not defined: part 'box' has box."),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("box.top"), std::string::npos) << r.output;
}

// Ids that repeat across a model's mesh files fall back to 1..N in the outputs, and the
// setup says so (QA round 13: silently).
TEST(ReadersDeck, RepeatedFileIdsAreWarnedOf) {
  TempDir dir;
  fs::copy_file(data("box_2x2x2.msh"), dir.path / "box_2x2x2.msh");
  write(dir.path / "deck.yaml", R"(termination: {cycles: 1}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  a: {mesh: {file: box_2x2x2.msh}, material: steel}
  b: {mesh: {file: box_2x2x2.msh}, material: steel}
)");
  const CheckRun r = anvil_check(dir.file("deck.yaml"));
  EXPECT_EQ(r.status, 0) << r.output;
  for (const char* what : {"node", "element"})
    EXPECT_NE(r.output.find(fmt::format("the mesh files' {} ids repeat in the model", what)),
              std::string::npos)
        << r.output;
  write(dir.path / "deck.yaml", deck_for("box_2x2x2.msh", "box.top"));
  const CheckRun one = anvil_check(dir.file("deck.yaml"));
  EXPECT_EQ(one.output.find("ids repeat"), std::string::npos) << one.output;
}

// A tangled element: its exact volume is positive (0.276) but its Jacobian at the centre,
// which the one-point element integrates with, is not (-0.030; QA round 21). The setup
// refuses it as it refuses an inverted one, naming it (`anvil check`, exit 2).
TEST(ReadersDeck, TangledElementIsRefused) {
  TempDir dir;
  write(dir.path / "tangled.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n"
        "1 0.3 0.01 -0.69\n2 1.88 0.56 1.05\n3 0.46 1.95 1.0\n4 -1.0 2.28 -1.01\n"
        "5 0.63 -0.09 0.79\n6 1.63 -0.51 1.86\n7 1.47 -0.22 -0.48\n8 0.67 0.66 0.44\n"
        "$EndNodes\n$Elements\n1\n7 5 2 0 1 1 2 3 4 5 6 7 8\n$EndElements\n");
  write(dir.path / "deck.yaml", R"(termination: {cycles: 1}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  t: {mesh: {file: tangled.msh}, material: steel}
)");
  const CheckRun r = anvil_check(dir.file("deck.yaml"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("deck.yaml:5: parts.t.mesh"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("element 7 of part t is tangled: its volume is positive (0.276"),
            std::string::npos)
      << r.output;
}

TEST(ReadersDeck, BadMeshFilesExitWithStatusTwo) {
  TempDir dir;
  const std::string good = slurp(data("box_2x2x2.msh"));
  struct BadFile {
    std::string name, bytes, fragment;
  };
  std::string garbage(3000, '\0');
  std::mt19937 rng(11);
  for (auto& c : garbage) c = static_cast<char>(rng());
  const std::vector<BadFile> files = {
      {"tet.exo", slurp(data("bad_tet_block.exo")), "TETRA"},
      {"nodes.exo", slurp(data("bad_node_range.exo")), "node 28"},
      {"truncated.exo", slurp(data("box_2x2x2.exo")).substr(0, 1500), "truncated.exo"},
      {"garbage.exo", garbage, "garbage.exo"},
      {"empty.msh", "", "empty"},
      {"garbage.msh", garbage, "garbage.msh:"},
      {"truncated.msh", good.substr(0, good.size() / 2), "truncated?"},
      {"tet.msh", good.substr(0, good.find("3 1 5 4")) + "3 1 4 1\n12 1 13 25 16\n$EndElements\n",
       "tetrahedron"},
      {"model.k", "*KEYWORD\n*NODE\n1 x\n", "model.k:3: *NODE.NID"},
      {"model.inp", "*HEADING\n", "unknown format"},
  };
  for (const auto& f : files) {
    SCOPED_TRACE(f.name);
    write(dir.path / f.name, f.bytes);
    write(dir.path / "deck.yaml", deck_for(f.name, "box.top"));
    const CheckRun r = anvil_check(dir.file("deck.yaml"));
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("deck.yaml:7: parts.box.mesh"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(f.fragment), std::string::npos) << r.output;
  }
  // Directories named like mesh files (an Exodus one used to hang the reader).
  for (const char* name : {"dir.exo", "dir.msh", "dir.k"}) {
    SCOPED_TRACE(name);
    fs::create_directories(dir.path / name);
    write(dir.path / "deck.yaml", deck_for(name, "box.top"));
    const CheckRun r = anvil_check(dir.file("deck.yaml"));
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(
                  fmt::format("deck.yaml:7: parts.box.mesh: {}: is a directory", dir.file(name))),
              std::string::npos)
        << r.output;
  }
  // A set that the file does not define.
  fs::copy_file(data("box_2x2x2.msh"), dir.path / "box.msh");
  write(dir.path / "deck.yaml", deck_for("box.msh", "box.nosuchset"));
  const CheckRun r = anvil_check(dir.file("deck.yaml"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("box.nosuchset"), std::string::npos) << r.output;
}

} // namespace
