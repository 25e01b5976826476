// Writes the small Exodus II files that tests/unit/test_readers.cpp reads. Built by hand,
// not by CMake, because the files are checked in (see README.md in this folder):
//   g++ -std=c++20 -O1 make_exodus.cpp -o /tmp/make_exodus -lexoIIv2c && /tmp/make_exodus .
// Each file exercises one feature of the reader or one kind of bad input.
#include <exodusII.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

// Any failing Exodus call ends the generator: the test data must be exactly as described.
void check(int rc, const char* what) {
  if (rc < 0) {
    std::fprintf(stderr, "make_exodus: %s failed (%d)\n", what, rc);
    std::exit(1);
  }
}

struct Box {
  std::vector<double> x, y, z;           // 27 nodes, index i + 3 j + 9 k
  std::vector<std::array<int, 8>> hexes; // 8 elements, 1-based node indices, k-major
};

// The 2x2x2 box [0,2] x [0,1] x [0,3]: 27 nodes, 8 hexes in Exodus node order.
Box make_box() {
  Box b;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        b.x.push_back(1.0 * i);
        b.y.push_back(0.5 * j);
        b.z.push_back(1.5 * k);
      }
  auto n = [](int i, int j, int k) { return 1 + i + 3 * j + 9 * k; };
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        b.hexes.push_back({n(i, j, k), n(i + 1, j, k), n(i + 1, j + 1, k), n(i, j + 1, k),
                           n(i, j, k + 1), n(i + 1, j, k + 1), n(i + 1, j + 1, k + 1),
                           n(i, j + 1, k + 1)});
  return b;
}

// `format`: 0 for the library's default (netCDF classic, 64-bit offsets),
// EX_NORMAL_MODEL for the original classic format, EX_NETCDF4 for HDF5-based netCDF-4.
int create(const std::string& path, int format = 0) {
  int cws = 8, iows = 8;
  const int id = ex_create(path.c_str(), EX_CLOBBER | format, &cws, &iows);
  check(id, "ex_create");
  return id;
}

// Variants of the box file; `fault` selects the deliberate defect (empty: a valid file).
void write_box(const std::string& path, const std::string& fault, int format = 0) {
  const Box b = make_box();
  const int dim = fault == "dim2" ? 2 : 3;
  const int id = create(path, format);
  check(ex_put_init(id, "anvil reader test: 2x2x2 box", dim, 27, 8, 2, 2, 2), "ex_put_init");
  check(ex_put_coord(id, b.x.data(), b.y.data(), dim == 3 ? b.z.data() : nullptr), "ex_put_coord");
  // Non-contiguous file ids: the reader must use positions, not these numbers.
  std::vector<int> node_map(27), elem_map(8);
  for (int i = 0; i < 27; ++i) node_map[i] = 1000 + 3 * i;
  for (int e = 0; e < 8; ++e) elem_map[e] = 500 - e;
  check(ex_put_id_map(id, EX_NODE_MAP, node_map.data()), "node map");
  check(ex_put_id_map(id, EX_ELEM_MAP, elem_map.data()), "elem map");

  // Block 10 "lower" (z < 1.5), block 20 unnamed (z > 1.5), element order kept.
  const char* type = fault == "tet" ? "TETRA" : "HEX8";
  const int npe = fault == "tet" ? 4 : 8;
  for (int blk = 0; blk < 2; ++blk) {
    const int blk_id = 10 * (blk + 1);
    check(ex_put_block(id, EX_ELEM_BLOCK, blk_id, blk == 1 ? type : "HEX8", 4, blk == 1 ? npe : 8,
                       0, 0, 0),
          "ex_put_block");
    std::vector<int> conn;
    for (int e = 0; e < 4; ++e)
      for (int a = 0; a < (blk == 1 ? npe : 8); ++a) conn.push_back(b.hexes[4 * blk + e][a]);
    if (fault == "node_range" && blk == 1) conn[5] = 28;
    check(ex_put_conn(id, EX_ELEM_BLOCK, blk_id, conn.data(), nullptr, nullptr), "conn");
  }
  check(ex_put_name(id, EX_ELEM_BLOCK, 10, "lower"), "block name");

  // Node set 1 "bottom" (z = 0, 9 nodes, listed unsorted), node set 7 unnamed (2 nodes).
  std::vector<int> bottom = {9, 8, 7, 6, 5, 4, 3, 2, 1};
  if (fault == "nodeset_range") bottom[0] = 0;
  check(ex_put_set_param(id, EX_NODE_SET, 1, 9, 0), "ns param");
  check(ex_put_set(id, EX_NODE_SET, 1, bottom.data(), nullptr), "ns");
  check(ex_put_name(id, EX_NODE_SET, 1, "bottom"), "ns name");
  std::vector<int> corner = {27, 19};
  check(ex_put_set_param(id, EX_NODE_SET, 7, 2, 0), "ns param");
  check(ex_put_set(id, EX_NODE_SET, 7, corner.data(), nullptr), "ns");

  // Side set 3 "top": the top faces (side 6) of elements 5-8; side set 4 unnamed:
  // side 1 (y = 0) of element 1 and side 4 (x = 0) of element 3.
  std::vector<int> top_e = {5, 6, 7, 8}, top_s = {6, 6, 6, 6};
  if (fault == "side_range") top_s[2] = 7;
  if (fault == "elem_range") top_e[1] = 9;
  check(ex_put_set_param(id, EX_SIDE_SET, 3, 4, 0), "ss param");
  check(ex_put_set(id, EX_SIDE_SET, 3, top_e.data(), top_s.data()), "ss");
  check(ex_put_name(id, EX_SIDE_SET, 3, "top"), "ss name");
  std::vector<int> misc_e = {1, 3}, misc_s = {1, 4};
  check(ex_put_set_param(id, EX_SIDE_SET, 4, 2, 0), "ss param");
  check(ex_put_set(id, EX_SIDE_SET, 4, misc_e.data(), misc_s.data()), "ss");
  check(ex_close(id), "ex_close");
}

// One 20-node hexahedron on the unit cube: the reader keeps the 8 corners. Its block
// type is in lower case and its node set has a name longer than Exodus's default of 32
// characters.
void write_hex20(const std::string& path) {
  const int id = create(path);
  check(ex_set_max_name_length(id, 64), "ex_set_max_name_length");
  check(ex_put_init(id, "anvil reader test: one HEX20", 3, 20, 1, 1, 1, 0), "ex_put_init");
  // Corners in Exodus order, then the 12 mid-edge nodes (positions only matter for volume).
  const double c[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                          {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const int edges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 5},
                            {2, 6}, {3, 7}, {4, 5}, {5, 6}, {6, 7}, {7, 4}};
  std::vector<double> x, y, z;
  for (const auto& p : c) x.push_back(p[0]), y.push_back(p[1]), z.push_back(p[2]);
  for (const auto& e : edges) {
    x.push_back(0.5 * (c[e[0]][0] + c[e[1]][0]));
    y.push_back(0.5 * (c[e[0]][1] + c[e[1]][1]));
    z.push_back(0.5 * (c[e[0]][2] + c[e[1]][2]));
  }
  check(ex_put_coord(id, x.data(), y.data(), z.data()), "ex_put_coord");
  check(ex_put_block(id, EX_ELEM_BLOCK, 1, "hex20", 1, 20, 0, 0, 0), "ex_put_block");
  std::vector<int> conn(20);
  for (int i = 0; i < 20; ++i) conn[i] = i + 1;
  check(ex_put_conn(id, EX_ELEM_BLOCK, 1, conn.data(), nullptr, nullptr), "conn");
  std::vector<int> bottom = {1, 2, 3, 4, 9, 10, 11, 12}; // corners and mid-edges at z = 0
  check(ex_put_set_param(id, EX_NODE_SET, 2, 8, 0), "ns param");
  check(ex_put_set(id, EX_NODE_SET, 2, bottom.data(), nullptr), "ns");
  check(ex_put_name(id, EX_NODE_SET, 2, "bottom_face_of_the_cube_with_a_long_set_name"), "ns name");
  check(ex_close(id), "ex_close");
}

// Solids of every shape anvil reads, in blocks of their own, sharing nodes as a mixed
// mesh does (tests/data/meshes/mixed_solids.msh is the same mesh as Gmsh writes it, less
// the last block):
//   block 1 "hex"  HEX8     the unit cube [0,1]^3 (nodes 1-8)
//   block 2        wedge    (lower case) on the cube's face x = 1: triangle (1,0) (2,0)
//                           (1,1) from z = 0 to 1, nodes 2 9 3 and 6 10 7 (volume 1/2)
//   block 3        TETRA10  on the wedge: 6 10 7 and 11 = (1,0,2) (volume 1/6), mid-edge
//                           nodes 13-18 (unused)
//   block 4        PYRAMID  on the cube: base 5 6 7 8, apex 12 = (0.5,0.5,2) (volume 1/3)
//   block 5        HEX8     a wedge written as LS-DYNA writes one (N5 = N6, N7 = N8) on
//                           [3,4] x [0,1] x [0,1]: base 19 20 21 22 at z = 0, 23 = (3,0,1)
//                           and 24 = (3,1,1) (volume 1/2)
// Element ids 10, 20, 30, 40, 50. Side set 1 "faces" names every side of the wedge, the
// tetrahedron and the pyramid, side 6 of the cube and sides 5 and 1 of the LS-DYNA wedge;
// node set 1 "apex" the pyramid's apex.
void write_mixed(const std::string& path) {
  const int id = create(path);
  check(ex_put_init(id, "anvil reader test: mixed solids", 3, 24, 5, 5, 1, 1), "ex_put_init");
  std::vector<double> x = {0, 1, 1, 0, 0, 1, 1, 0, 2, 2, 1, 0.5};
  std::vector<double> y = {0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 0, 0.5};
  std::vector<double> z = {0, 0, 0, 0, 1, 1, 1, 1, 0, 1, 2, 2};
  // TETRA10 mid-edge nodes 13-18: edges 1-2, 2-3, 1-3, 1-4, 2-4, 3-4 of the tetrahedron.
  const int tet[4] = {6, 10, 7, 11};
  const int tet_edges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (const auto& e : tet_edges) {
    const int p = tet[e[0]] - 1, q = tet[e[1]] - 1;
    x.push_back(0.5 * (x[p] + x[q]));
    y.push_back(0.5 * (y[p] + y[q]));
    z.push_back(0.5 * (z[p] + z[q]));
  }
  // The LS-DYNA wedge, nodes 19-24.
  for (const auto& p :
       {std::array<double, 3>{3, 0, 0}, {4, 0, 0}, {4, 1, 0}, {3, 1, 0}, {3, 0, 1}, {3, 1, 1}}) {
    x.push_back(p[0]);
    y.push_back(p[1]);
    z.push_back(p[2]);
  }
  check(ex_put_coord(id, x.data(), y.data(), z.data()), "ex_put_coord");

  struct Block {
    const char* type;
    int nodes;
    std::vector<int> conn;
  };
  const std::vector<Block> blocks = {
      {"HEX8", 8, {1, 2, 3, 4, 5, 6, 7, 8}},
      {"wedge", 6, {2, 9, 3, 6, 10, 7}},
      {"TETRA10", 10, {6, 10, 7, 11, 13, 14, 15, 16, 17, 18}},
      {"PYRAMID", 5, {5, 6, 7, 8, 12}},
      {"HEX8", 8, {19, 20, 21, 22, 23, 23, 24, 24}},
  };
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const int blk_id = static_cast<int>(b) + 1;
    check(ex_put_block(id, EX_ELEM_BLOCK, blk_id, blocks[b].type, 1, blocks[b].nodes, 0, 0, 0),
          "ex_put_block");
    check(ex_put_conn(id, EX_ELEM_BLOCK, blk_id, blocks[b].conn.data(), nullptr, nullptr), "conn");
  }
  check(ex_put_name(id, EX_ELEM_BLOCK, 1, "hex"), "block name");
  std::vector<int> elem_map = {10, 20, 30, 40, 50};
  check(ex_put_id_map(id, EX_ELEM_MAP, elem_map.data()), "elem map");

  std::vector<int> apex = {12};
  check(ex_put_set_param(id, EX_NODE_SET, 1, 1, 0), "ns param");
  check(ex_put_set(id, EX_NODE_SET, 1, apex.data(), nullptr), "ns");
  check(ex_put_name(id, EX_NODE_SET, 1, "apex"), "ns name");

  std::vector<int> elems = {1, 2, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 4, 5, 5};
  std::vector<int> sides = {6, 1, 2, 3, 4, 5, 1, 2, 3, 4, 1, 2, 3, 4, 5, 5, 1};
  check(ex_put_set_param(id, EX_SIDE_SET, 1, static_cast<int>(elems.size()), 0), "ss param");
  check(ex_put_set(id, EX_SIDE_SET, 1, elems.data(), sides.data()), "ss");
  check(ex_put_name(id, EX_SIDE_SET, 1, "faces"), "ss name");
  check(ex_close(id), "ex_close");
}

} // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : ".";
  write_box(dir + "/box_2x2x2.exo", "");
  write_box(dir + "/box_2x2x2_cdf1.exo", "", EX_NORMAL_MODEL);
  write_box(dir + "/box_2x2x2_nc4.exo", "", EX_NETCDF4);
  write_box(dir + "/bad_tet_block.exo", "tet");
  write_box(dir + "/bad_node_range.exo", "node_range");
  write_box(dir + "/bad_nodeset_range.exo", "nodeset_range");
  write_box(dir + "/bad_side_range.exo", "side_range");
  write_box(dir + "/bad_elem_range.exo", "elem_range");
  write_box(dir + "/bad_2d.exo", "dim2");
  write_hex20(dir + "/hex20.exo");
  write_mixed(dir + "/mixed_solids.exo");
  return 0;
}
