#include "anvil/solver/model.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <new>
#include <stdexcept>

#include <fmt/format.h>

#include "anvil/contact/surface.hpp"
#include "anvil/fe/hex_block.hpp"
#include "anvil/io/keyword.hpp"
#include "anvil/mesh/generators.hpp"
#include "anvil/mesh/read_exodus.hpp"
#include "anvil/mesh/read_gmsh.hpp"
#include "anvil/parallel/graph_partition.hpp"
#include "anvil/parallel/rcb.hpp"

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
  if (is_keyword_file(path)) return &read_keyword_mesh;
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
    case MeshConfig::Kind::embedded:
      break;
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(p.mesh.where, e.what());
  } catch (const std::bad_alloc&) {
    throw InputError(p.mesh.where, "the generated mesh does not fit in memory");
  } catch (const std::length_error&) {
    throw InputError(p.mesh.where, "the generated mesh does not fit in memory");
  }
  const auto reader = mesh_reader(p.mesh.file);
  if (!reader)
    throw InputError(p.mesh.where,
                     fmt::format("cannot read mesh file '{}': unknown format (expected "
                                 ".exo, .e, .g, .gen or .ex2 for Exodus II, .msh for Gmsh, "
                                 ".k, .key or .dyn for an LS-DYNA keyword file)",
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
  // Parts of one embedded mesh (a keyword deck) share its nodes: the nodes and node sets
  // are appended once, with the first such part, and each part takes its own block.
  std::vector<std::pair<const Mesh*, std::int64_t>> embedded_offset;
  for (const auto& p : config.parts) {
    if (p.mesh.kind == MeshConfig::Kind::embedded) {
      const Mesh* src = p.mesh.embedded.get();
      if (!src || p.mesh.embedded_block >= src->blocks.size())
        throw InputError(p.mesh.where, "the part's embedded mesh is missing");
      auto it = std::find_if(embedded_offset.begin(), embedded_offset.end(),
                             [&](const auto& e) { return e.first == src; });
      if (it == embedded_offset.end()) {
        const std::int64_t shift = mesh.append_nodes(*src, "");
        embedded_offset.emplace_back(src, shift);
        it = std::prev(embedded_offset.end());
      }
      const ElementBlock& sb = src->blocks[p.mesh.embedded_block];
      ElementBlock b{p.name, sb.elements, sb.ids};
      for (auto& h : b.elements)
        for (auto& n : h) n += it->second;
      if (b.elements.empty()) throw InputError(p.mesh.where, "the part's mesh has no elements");
      mesh.blocks.push_back(std::move(b));
      continue;
    }
    Mesh m = part_mesh(p);
    // A part is one block named after the part, whatever the source called it.
    if (m.blocks.size() != 1) {
      ElementBlock merged{p.name, {}, {}};
      const bool file_ids = std::any_of(m.blocks.begin(), m.blocks.end(),
                                        [](const auto& b) { return !b.ids.empty(); });
      for (auto& b : m.blocks) {
        merged.elements.insert(merged.elements.end(), b.elements.begin(), b.elements.end());
        for (std::size_t e = 0; file_ids && e < b.elements.size(); ++e)
          merged.ids.push_back(b.id(e));
      }
      m.blocks = {std::move(merged)};
    }
    m.blocks[0].name = p.name;
    if (m.blocks[0].elements.empty())
      throw InputError(p.mesh.where, "the part's mesh has no elements");
    mesh.append(m, p.name);
  }
  // The embedded meshes' side sets (a keyword deck's loaded segments), renumbered from
  // their blocks to the parts that took them.
  const auto offsets = mesh.block_offsets();
  for (const auto& embedded : embedded_offset) {
    const Mesh* src = embedded.first;
    const auto src_offsets = src->block_offsets();
    for (const auto& [name, sides] : src->side_sets) {
      auto& dst = mesh.side_sets[name];
      for (const SideEntry& s : sides) {
        const auto sb = static_cast<std::size_t>(
            std::upper_bound(src_offsets.begin(), src_offsets.end(), s.element) -
            src_offsets.begin() - 1);
        for (std::size_t b = 0; b < config.parts.size(); ++b)
          if (config.parts[b].mesh.embedded.get() == src &&
              config.parts[b].mesh.embedded_block == sb)
            dst.push_back({offsets[b] + (s.element - src_offsets[sb]), s.face});
      }
    }
  }
  for (std::size_t b = 0; b < config.parts.size(); ++b) {
    if (!config.parts[b].thick_shell.enabled()) continue;
    const auto& elements = mesh.blocks[b].elements;
    for (std::size_t e = 0; e < elements.size(); ++e)
      if (const Shape shape = shape_of(elements[e]); shape != Shape::hexahedron)
        throw InputError(config.parts[b].where,
                         fmt::format("part {} is a thick shell, and its element {} is a {}: "
                                     "thick shells are hexahedra",
                                     config.parts[b].name, mesh.blocks[b].id(e),
                                     shape_name(shape)));
    orient_thickness_zeta(mesh, b);
  }
  return mesh;
}

std::vector<std::int64_t> elements_holding(const Mesh& mesh, std::span<const std::size_t> blocks,
                                           std::span<const Vec3> points,
                                           std::span<const std::int64_t> node) {
  std::vector<std::int64_t> holder(points.size(), -1);
  auto corners = [&](const Hex& e) {
    std::array<Vec3, 8> x;
    for (int k = 0; k < 8; ++k) x[k] = mesh.nodes[static_cast<std::size_t>(e[k])];
    return x;
  };
  auto bounds = [](const std::array<Vec3, 8>& x) {
    Box3 b{x[0], x[0]};
    for (const Vec3& q : x)
      for (int i = 0; i < 3; ++i) {
        b.lo[i] = std::min(b.lo[i], q[i]);
        b.hi[i] = std::max(b.hi[i], q[i]);
      }
    return b;
  };
  double extent = 0;
  std::int64_t elements = 0;
  for (std::size_t b : blocks)
    for (const Hex& e : mesh.blocks[b].elements) {
      const Box3 bb = bounds(corners(e));
      extent += std::max({bb.hi.x - bb.lo.x, bb.hi.y - bb.lo.y, bb.hi.z - bb.lo.z});
      ++elements;
    }
  if (elements == 0 || !(extent > 0) || points.empty()) return holder;
  // The faces of these blocks that bound them (one element's, not two): a point on such a
  // face touches the body; a point on a face between two elements is inside it.
  std::vector<FaceKey> faces;
  for (std::size_t b : blocks)
    for (const Hex& e : mesh.blocks[b].elements)
      for (int f = 0; f < 6; ++f) faces.push_back(face_key(e, f));
  std::sort(faces.begin(), faces.end());
  auto bounding = [&](const FaceKey& k) {
    const auto [lo, hi] = std::equal_range(faces.begin(), faces.end(), k);
    return hi - lo == 1;
  };
  const double cell = extent / static_cast<double>(elements);
  auto key = [cell](double a) { return static_cast<std::int64_t>(std::floor(a / cell)); };
  std::map<std::array<std::int64_t, 3>, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < points.size(); ++i)
    grid[{key(points[i].x), key(points[i].y), key(points[i].z)}].push_back(i);
  std::int64_t gid = 0; // the global id of the element (blocks in order)
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const bool listed = std::find(blocks.begin(), blocks.end(), b) != blocks.end();
    if (!listed) {
      gid += static_cast<std::int64_t>(mesh.blocks[b].elements.size());
      continue;
    }
    for (const Hex& e : mesh.blocks[b].elements) {
      const std::int64_t id = gid++;
      const auto x = corners(e);
      const Box3 bb = bounds(x);
      const double tol = 1e-6 * std::max({bb.hi.x - bb.lo.x, bb.hi.y - bb.lo.y, bb.hi.z - bb.lo.z});
      Vec3 centre[6], normal[6];
      double margin[6]; // behind a bounding face by more than tol, an inner one by -tol
      for (int f = 0; f < 6; ++f) {
        const auto& q = hex_faces[static_cast<std::size_t>(f)];
        centre[f] = 0.25 * (x[q[0]] + x[q[1]] + x[q[2]] + x[q[3]]);
        const Vec3 n = cross(x[q[2]] - x[q[0]], x[q[3]] - x[q[1]]);
        const double len = norm(n);
        normal[f] = len > 0 ? n * (1 / len) : n;
        const FaceKey k = face_key(e, f); // (a collapsed face of a wedge, ...: no plane)
        margin[f] = !is_face(k)   ? std::numeric_limits<double>::infinity()
                    : bounding(k) ? -tol
                                  : tol;
      }
      const std::int64_t l[3] = {key(bb.lo.x), key(bb.lo.y), key(bb.lo.z)};
      const std::int64_t h[3] = {key(bb.hi.x), key(bb.hi.y), key(bb.hi.z)};
      auto test = [&](const std::vector<std::size_t>& cell_points) {
        for (std::size_t i : cell_points) {
          if (holder[i] >= 0) continue; // (the first, the smallest id)
          if (!node.empty() && std::find(e.begin(), e.end(), node[i]) != e.end()) continue;
          bool in = true;
          for (int f = 0; f < 6 && in; ++f) in = dot(points[i] - centre[f], normal[f]) < margin[f];
          if (in) holder[i] = id;
        }
      };
      // An element much larger than the mean spans more cells than the grid has points'
      // cells (a 1 m block beside 0.3 mm elements: 10^8 cells, QA round 35 found `anvil
      // check` taking minutes): then the occupied cells inside its box are visited instead.
      const double span = static_cast<double>(h[0] - l[0] + 1) *
                          static_cast<double>(h[1] - l[1] + 1) *
                          static_cast<double>(h[2] - l[2] + 1);
      if (span > static_cast<double>(grid.size())) {
        for (const auto& [k, cell_points] : grid)
          if (k[0] >= l[0] && k[0] <= h[0] && k[1] >= l[1] && k[1] <= h[1] && k[2] >= l[2] &&
              k[2] <= h[2])
            test(cell_points);
        continue;
      }
      for (std::int64_t a = l[0]; a <= h[0]; ++a)
        for (std::int64_t c = l[1]; c <= h[1]; ++c)
          for (std::int64_t d = l[2]; d <= h[2]; ++d)
            if (const auto it = grid.find({a, c, d}); it != grid.end()) test(it->second);
    }
  }
  // A point on a bounding face of the part that holds it touches that part, whichever
  // element's test it passed: the elements of wedges and tetrahedra that reach the surface
  // at a corner or an edge only have no bounding face there, and a point on that corner or
  // edge lies on their inner faces (QA round 36: touching meshes of tetrahedra reported 32
  // nodes inside). (The faces of the point's own part, which it lies on, are not looked at.)
  std::vector<std::int64_t> first_gid(mesh.blocks.size() + 1, 0);
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b)
    first_gid[b + 1] = first_gid[b] + static_cast<std::int64_t>(mesh.blocks[b].elements.size());
  std::map<std::array<std::int64_t, 3>, std::vector<std::size_t>> held; // the held points
  for (std::size_t i = 0; i < points.size(); ++i)
    if (holder[i] >= 0) held[{key(points[i].x), key(points[i].y), key(points[i].z)}].push_back(i);
  if (held.empty()) return holder;
  for (std::size_t b : blocks)
    for (const Hex& e : mesh.blocks[b].elements)
      for (int f = 0; f < 6; ++f) {
        const FaceKey k = face_key(e, f);
        if (!is_face(k) || !bounding(k)) continue;
        auto in_this_part = [&](std::size_t i) {
          return holder[i] >= first_gid[b] && holder[i] < first_gid[b + 1] &&
                 (node.empty() || std::find(k.begin(), k.end(), node[i]) == k.end());
        };
        const auto& q = hex_faces[static_cast<std::size_t>(f)];
        const std::array<Vec3, 4> v = {mesh.nodes[static_cast<std::size_t>(e[q[0]])],
                                       mesh.nodes[static_cast<std::size_t>(e[q[1]])],
                                       mesh.nodes[static_cast<std::size_t>(e[q[2]])],
                                       mesh.nodes[static_cast<std::size_t>(e[q[3]])]};
        Box3 fb{v[0], v[0]};
        for (const Vec3& w : v)
          for (int i = 0; i < 3; ++i) {
            fb.lo[i] = std::min(fb.lo[i], w[i]);
            fb.hi[i] = std::max(fb.hi[i], w[i]);
          }
        const double tol =
            1e-6 * std::max({fb.hi.x - fb.lo.x, fb.hi.y - fb.lo.y, fb.hi.z - fb.lo.z});
        // On the face: within tol of one of its triangles (0 1 2, 0 2 3; a triangle's
        // repeated corner makes the second one empty).
        auto on_face = [&](const Vec3& x) {
          for (int t = 0; t < 2; ++t) {
            const Vec3 &a = v[0], &b1 = v[1 + t], &c1 = v[2 + t];
            const Vec3 n = cross(b1 - a, c1 - a);
            const double n2 = dot(n, n);
            if (!(n2 > 0)) continue;
            const double len = std::sqrt(n2);
            if (std::abs(dot(x - a, n)) > tol * len) continue;
            // Barycentric: each edge's side, within tol of the edge.
            const bool inside = dot(cross(b1 - a, x - a), n) >= -tol * len * norm(b1 - a) &&
                                dot(cross(c1 - b1, x - b1), n) >= -tol * len * norm(c1 - b1) &&
                                dot(cross(a - c1, x - c1), n) >= -tol * len * norm(a - c1);
            if (inside) return true;
          }
          return false;
        };
        auto visit = [&](const std::vector<std::size_t>& cell_points) {
          for (std::size_t i : cell_points)
            if (holder[i] >= 0 && in_this_part(i) && on_face(points[i])) holder[i] = -1;
        };
        const std::int64_t l[3] = {key(fb.lo.x - tol), key(fb.lo.y - tol), key(fb.lo.z - tol)};
        const std::int64_t h[3] = {key(fb.hi.x + tol), key(fb.hi.y + tol), key(fb.hi.z + tol)};
        const double span = static_cast<double>(h[0] - l[0] + 1) *
                            static_cast<double>(h[1] - l[1] + 1) *
                            static_cast<double>(h[2] - l[2] + 1);
        if (span > static_cast<double>(held.size())) {
          for (const auto& [c, cell_points] : held)
            if (c[0] >= l[0] && c[0] <= h[0] && c[1] >= l[1] && c[1] <= h[1] && c[2] >= l[2] &&
                c[2] <= h[2])
              visit(cell_points);
          continue;
        }
        for (std::int64_t a = l[0]; a <= h[0]; ++a)
          for (std::int64_t c = l[1]; c <= h[1]; ++c)
            for (std::int64_t d = l[2]; d <= h[2]; ++d)
              if (const auto it = held.find({a, c, d}); it != held.end()) visit(it->second);
      }
  return holder;
}

std::vector<std::int64_t> resolve_selection(const Mesh& mesh, const Config& config,
                                            const Selection& sel) {
  std::vector<std::int64_t> ids;
  if (!sel.name.empty()) {
    if (auto it = config.node_sets.find(sel.name); it != config.node_sets.end()) {
      ids = resolve_selection(mesh, config, it->second);
    } else if (auto m = mesh.node_sets.find(sel.name); m != mesh.node_sets.end()) {
      ids = m->second;
    } else if (mesh.side_sets.count(sel.name)) {
      throw InputError(sel.where, fmt::format("'{}' is a side set (faces), not a node set: a "
                                              "pressure takes it as its surface",
                                              sel.name));
    } else {
      // A name PART.SET of a part read from a file: the sets its file has (the deck's
      // reader lists a generated part's own).
      std::string known;
      if (const auto dot = sel.name.find('.'); dot != std::string::npos) {
        const std::string prefix = sel.name.substr(0, dot + 1);
        for (const auto& [name, nodes] : mesh.node_sets)
          if (name.compare(0, prefix.size(), prefix) == 0)
            known += (known.empty() ? "" : ", ") + name;
        if (part_index(config, sel.name.substr(0, dot)) < config.parts.size())
          known = known.empty()
                      ? fmt::format(": part '{}' has no node sets", sel.name.substr(0, dot))
                      : fmt::format(": part '{}' has {}", sel.name.substr(0, dot), known);
        else
          known.clear();
      }
      throw InputError(sel.where, fmt::format("node set '{}' is not defined{}", sel.name, known));
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

std::vector<SideEntry> resolve_surface(const Mesh& mesh, const Config& config,
                                       const Selection& sel) {
  if (!sel.name.empty()) {
    if (const auto it = mesh.side_sets.find(sel.name); it != mesh.side_sets.end()) {
      std::vector<SideEntry> faces = it->second;
      std::sort(faces.begin(), faces.end(), [](const SideEntry& a, const SideEntry& b) {
        return a.element != b.element ? a.element < b.element : a.face < b.face;
      });
      faces.erase(std::unique(faces.begin(), faces.end(),
                              [](const SideEntry& a, const SideEntry& b) {
                                return a.element == b.element && a.face == b.face;
                              }),
                  faces.end());
      if (faces.empty())
        throw InputError(sel.where, fmt::format("side set '{}' is empty", sel.name));
      return faces;
    }
    // A deck set: its own selection (its part restricts the faces too), found here.
    if (const auto it = config.node_sets.find(sel.name); it != config.node_sets.end()) {
      Selection named = it->second;
      named.where = sel.where;
      return resolve_surface(mesh, config, named);
    }
    // Neither: the part's side sets and node sets, both of which a surface takes.
    if (!mesh.node_sets.count(sel.name)) {
      std::string known;
      if (const auto dot = sel.name.find('.'); dot != std::string::npos) {
        const std::string prefix = sel.name.substr(0, dot + 1);
        for (const auto& [name, faces] : mesh.side_sets)
          if (name.compare(0, prefix.size(), prefix) == 0)
            known += (known.empty() ? "" : ", ") + name;
        for (const auto& [name, nodes] : mesh.node_sets)
          if (name.compare(0, prefix.size(), prefix) == 0)
            known += (known.empty() ? "" : ", ") + name;
      }
      throw InputError(
          sel.where,
          fmt::format("'{}' is neither a side set nor a node set{}", sel.name,
                      known.empty() ? std::string() : fmt::format(" (the part has {})", known)));
    }
  }
  if (sel.part && part_index(config, *sel.part) == config.parts.size() &&
      config.particle_set(*sel.part) >= 0)
    throw InputError(sel.where, fmt::format("'{}' is a particle set: a pressure acts on the "
                                            "faces of the mesh",
                                            *sel.part));
  const std::vector<std::int64_t> nodes = resolve_selection(mesh, config, sel);
  std::vector<bool> blocks(mesh.blocks.size(), !sel.part);
  if (sel.part) blocks[part_index(config, *sel.part)] = true;
  const ExteriorFaces ext = exterior_faces(mesh, blocks);
  std::vector<SideEntry> faces;
  for (std::size_t f = 0; f < ext.size(); ++f)
    if (std::all_of(ext.nodes[f].begin(), ext.nodes[f].end(), [&](std::int64_t n) {
          return std::binary_search(nodes.begin(), nodes.end(), n);
        }))
      faces.push_back({ext.element[f], ext.side[f]});
  if (faces.empty())
    throw InputError(sel.where, fmt::format("the selection holds no face of the model's surface "
                                            "(of its {} nodes, no four are the corners of an "
                                            "exterior face)",
                                            nodes.size()));
  return faces;
}

std::vector<std::array<std::int64_t, 2>> contact_body_links(const Mesh& mesh,
                                                            const Config& config) {
  if (config.contact.empty()) return {};
  return links_between_bodies(mesh,
                              exterior_faces(mesh, blocks_named(mesh, config.contact[0].parts)));
}

std::vector<int> partition_model(const Mesh& mesh, const Config& config, const Comm& comm) {
  std::vector<int> weight;
  weight.reserve(config.parts.size());
  for (const auto& part : config.parts)
    weight.push_back(element_cost(part.hourglass, part.thick_shell));
  std::vector<int> owner;
  if (config.decomposition.fe == DecompositionConfig::Fe::metis) {
    // Bodies in contact that start within a face's size of each other are linked in the
    // graph: the elements of an interface then tend to share a rank in both the FE and the
    // contact decomposition (docs/cycle.md, "The static FE decomposition").
    if (comm.rank() == 0)
      owner = partition_elements(mesh, comm.size(), weight,
                                 comm.size() > 1 ? contact_body_links(mesh, config)
                                                 : std::vector<std::array<std::int64_t, 2>>{});
    comm.broadcast(owner, 0);
    return owner;
  }
  // RCB: rank r brings the elements [r ne / P, (r + 1) ne / P) in global order, each at
  // its centre (the mean of its corners) with its global id and its block's weight. The
  // partition depends only on the whole set, not on who brings what.
  const std::int64_t ne = mesh.num_elements(), ranks = comm.size(), r = comm.rank();
  const std::int64_t first = ne * r / ranks, last = ne * (r + 1) / ranks;
  const auto n = static_cast<std::size_t>(last - first);
  std::vector<double> x(n), y(n), z(n), w(n);
  std::vector<std::int64_t> gid(n);
  std::int64_t e = 0;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b)
    for (const auto& h : mesh.blocks[b].elements) {
      if (e >= first && e < last) {
        Vec3 c{0, 0, 0};
        for (const auto node : h) c = c + mesh.nodes[static_cast<std::size_t>(node)];
        const auto k = static_cast<std::size_t>(e - first);
        x[k] = 0.125 * c.x;
        y[k] = 0.125 * c.y;
        z[k] = 0.125 * c.z;
        gid[k] = e;
        w[k] = weight[b];
      }
      ++e;
    }
  Rcb rcb(comm, config.decomposition.scale);
  rcb.partition({x, y, z, gid, w});
  // Every rank learns every owner: its own range filled, the others' -1, a maximum.
  std::vector<std::int64_t> all(static_cast<std::size_t>(ne), -1);
  const auto dest = rcb.destinations();
  for (std::size_t k = 0; k < n; ++k) all[static_cast<std::size_t>(first) + k] = dest[k];
  comm.max(std::span<std::int64_t>(all));
  owner.assign(all.begin(), all.end());
  return owner;
}

} // namespace anvil
