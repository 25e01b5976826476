// Writes anvil's generated cylinder (the mesh of examples/taylor_bar.yaml) as an LS-DYNA
// keyword include file: *NODE (ids 1..N in anvil's order, E16 coordinates with 10
// significant digits), *ELEMENT_SOLID (part 1, ids 1..M in anvil's order, one line per
// element) and *SET_NODE_LIST 1 with the nodes of the bottom face. Also prints the node
// ids nearest to the Taylor bar's probe points. Built with the tests:
//   build/tests/export_cylinder tests/data/decks/taylor_bar_mesh.k
#include <cmath>
#include <cstdio>
#include <limits>

#include "anvil/mesh/generators.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: export_cylinder OUT.k\n");
    return 2;
  }
  anvil::CylinderSpec spec;
  spec.radius = 3.2e-3;
  spec.length = 32.4e-3;
  spec.axis = 2;
  spec.divisions = {8, 40};
  const anvil::Mesh mesh = anvil::generate_cylinder(spec);
  std::FILE* f = std::fopen(argv[1], "w");
  if (!f) {
    std::fprintf(stderr, "export_cylinder: cannot write %s\n", argv[1]);
    return 1;
  }
  std::fprintf(f, "$ anvil's cylinder: radius 3.2e-3 m, length 32.4e-3 m, axis z, divisions "
                  "[8, 40]\n$ written by tests/data/decks/export_cylinder.cpp; do not edit\n");
  std::fprintf(f, "*NODE\n$#   nid               x               y               z      tc      "
                  "rc\n");
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    const auto& x = mesh.nodes[n];
    // -0 would print as "-0.000000000E+00", which reads back the same; keep it tidy.
    auto c = [](double v) { return v == 0 ? 0.0 : v; };
    std::fprintf(f, "%8zu%16.9E%16.9E%16.9E%8d%8d\n", n + 1, c(x.x), c(x.y), c(x.z), 0, 0);
  }
  std::fprintf(f, "*ELEMENT_SOLID\n$#   eid     pid      n1      n2      n3      n4      n5      "
                  "n6      n7      n8\n");
  std::size_t eid = 0;
  for (const auto& b : mesh.blocks)
    for (const auto& h : b.elements) {
      std::fprintf(f, "%8zu%8d", ++eid, 1);
      for (auto n : h) std::fprintf(f, "%8lld", static_cast<long long>(n + 1));
      std::fprintf(f, "\n");
    }
  std::fprintf(f, "*SET_NODE_LIST_TITLE\nimpact face (z = 0)\n$#     sid\n         1\n");
  const auto& bottom = mesh.node_sets.at("bottom");
  for (std::size_t i = 0; i < bottom.size(); ++i)
    std::fprintf(f, "%10lld%s", static_cast<long long>(bottom[i] + 1),
                 (i % 8 == 7 || i + 1 == bottom.size()) ? "\n" : "");
  std::fclose(f);

  for (const auto& [name, at] : {std::pair<const char*, anvil::Vec3>{"tip", {0, 0, 32.4e-3}},
                                 std::pair<const char*, anvil::Vec3>{"rim", {3.2e-3, 0, 0}}}) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t id = 0;
    for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
      const double d = anvil::norm(mesh.nodes[n] - at);
      if (d < best) best = d, id = n + 1;
    }
    std::printf("%s: node %zu\n", name, id);
  }
  return 0;
}
