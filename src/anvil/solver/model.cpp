#include "anvil/solver/model.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>

#include "anvil/mesh/generators.hpp"
#include "anvil/mesh/read_exodus.hpp"
#include "anvil/mesh/read_gmsh.hpp"

namespace anvil {

namespace {

using MeshReader = Mesh (*)(const std::string& path);

// The reader for a mesh file, chosen by its extension (case-insensitive); null if none.
MeshReader mesh_reader(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".exo" || ext == ".e" || ext == ".g" || ext == ".gen" || ext == ".ex2")
    return &read_exodus;
  if (ext == ".msh") return &read_gmsh;
  return nullptr;
}

Mesh part_mesh(const PartConfig& p) {
  try {
    switch (p.mesh.kind) {
    case MeshConfig::Kind::box:
      return generate_box(p.mesh.box);
    case MeshConfig::Kind::cylinder:
      return generate_cylinder(p.mesh.cylinder);
    case MeshConfig::Kind::can:
      return generate_can(p.mesh.can);
    case MeshConfig::Kind::file:
      break;
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(p.mesh.where, e.what());
  }
  const auto reader = mesh_reader(p.mesh.file);
  if (!reader)
    throw InputError(p.mesh.where,
                     fmt::format("cannot read mesh file '{}': unknown format (expected "
                                 ".exo, .e, .g, .gen or .ex2 for Exodus II, .msh for Gmsh)",
                                 p.mesh.file));
  try {
    return reader(p.mesh.file);
  } catch (const InputError& e) {
    // The reader names the mesh file and line; the deck location says which part.
    throw InputError(p.mesh.where, e.what());
  }
}

std::size_t part_index(const Config& c, const std::string& name) {
  for (std::size_t i = 0; i < c.parts.size(); ++i)
    if (c.parts[i].name == name) return i;
  return c.parts.size();
}

} // namespace

Mesh build_mesh(const Config& config) {
  Mesh mesh;
  for (const auto& p : config.parts) {
    Mesh m = part_mesh(p);
    // A part is one block named after the part, whatever the source called it.
    if (m.blocks.size() != 1) {
      ElementBlock merged{p.name, {}};
      for (auto& b : m.blocks)
        merged.elements.insert(merged.elements.end(), b.elements.begin(), b.elements.end());
      m.blocks = {std::move(merged)};
    }
    m.blocks[0].name = p.name;
    if (m.blocks[0].elements.empty())
      throw InputError(p.mesh.where, "the part's mesh has no elements");
    mesh.append(m, p.name);
  }
  return mesh;
}

std::vector<std::int64_t> resolve_selection(const Mesh& mesh, const Config& config,
                                            const Selection& sel) {
  std::vector<std::int64_t> ids;
  if (!sel.name.empty()) {
    if (auto it = config.node_sets.find(sel.name); it != config.node_sets.end()) {
      ids = resolve_selection(mesh, config, it->second);
    } else if (auto m = mesh.node_sets.find(sel.name); m != mesh.node_sets.end()) {
      ids = m->second;
    } else {
      throw InputError(sel.where, fmt::format("node set '{}' is not defined", sel.name));
    }
  } else {
    std::vector<std::int64_t> candidates;
    if (sel.part) {
      const auto b = part_index(config, *sel.part);
      if (b == config.parts.size())
        throw InputError(sel.where, fmt::format("part '{}' is not defined", *sel.part));
      candidates = block_nodes(mesh, b);
    }
    if (sel.box) {
      ids = select_nodes(mesh, *sel.box, sel.part ? &candidates : nullptr);
      if (sel.part && candidates.empty()) ids.clear();
    } else {
      ids = std::move(candidates);
    }
  }
  if (ids.empty()) throw InputError(sel.where, "the selection contains no nodes");
  return ids;
}

} // namespace anvil
