#include "anvil/mesh/read_gmsh.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <new>
#include <optional>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "anvil/core/error.hpp"
#include "anvil/io/files.hpp"

namespace anvil {

namespace {

struct ElementType {
  int dim;
  int nodes;
  const char* name;
};

// The Gmsh element types up to the orders a mesh generator writes (Gmsh reference
// manual, "MSH file format"). The node count is needed to parse every element, also
// those only used for node sets.
std::optional<ElementType> element_type(std::int64_t type) {
  switch (type) {
  case 1:
    return ElementType{1, 2, "2-node line"};
  case 2:
    return ElementType{2, 3, "3-node triangle"};
  case 3:
    return ElementType{2, 4, "4-node quadrangle"};
  case 4:
    return ElementType{3, 4, "4-node tetrahedron"};
  case 5:
    return ElementType{3, 8, "8-node hexahedron"};
  case 6:
    return ElementType{3, 6, "6-node prism"};
  case 7:
    return ElementType{3, 5, "5-node pyramid"};
  case 8:
    return ElementType{1, 3, "3-node line"};
  case 9:
    return ElementType{2, 6, "6-node triangle"};
  case 10:
    return ElementType{2, 9, "9-node quadrangle"};
  case 11:
    return ElementType{3, 10, "10-node tetrahedron"};
  case 12:
    return ElementType{3, 27, "27-node hexahedron"};
  case 13:
    return ElementType{3, 18, "18-node prism"};
  case 14:
    return ElementType{3, 14, "14-node pyramid"};
  case 15:
    return ElementType{0, 1, "point"};
  case 16:
    return ElementType{2, 8, "8-node quadrangle"};
  case 17:
    return ElementType{3, 20, "20-node hexahedron"};
  case 18:
    return ElementType{3, 15, "15-node prism"};
  case 19:
    return ElementType{3, 13, "13-node pyramid"};
  case 20:
    return ElementType{2, 9, "9-node triangle"};
  case 21:
    return ElementType{2, 10, "10-node triangle"};
  case 22:
    return ElementType{2, 12, "12-node triangle"};
  case 23:
    return ElementType{2, 15, "15-node triangle"};
  case 24:
    return ElementType{2, 15, "15-node incomplete triangle"};
  case 25:
    return ElementType{2, 21, "21-node triangle"};
  case 26:
    return ElementType{1, 4, "4-node line"};
  case 27:
    return ElementType{1, 5, "5-node line"};
  case 28:
    return ElementType{1, 6, "6-node line"};
  case 29:
    return ElementType{3, 20, "20-node tetrahedron"};
  case 30:
    return ElementType{3, 35, "35-node tetrahedron"};
  case 31:
    return ElementType{3, 56, "56-node tetrahedron"};
  case 92:
    return ElementType{3, 64, "64-node hexahedron"};
  case 93:
    return ElementType{3, 125, "125-node hexahedron"};
  default:
    return std::nullopt;
  }
}

// The solids anvil reads, by their corners: Gmsh numbers an element's vertices first, in
// the order of its first-order type, whatever its order (Gmsh reference manual, "Node
// ordering"), so every order of a solid is read as its first-order form.
std::optional<Shape> solid_of(std::int64_t type) {
  switch (type) {
  case 5:  // 8-node hexahedron
  case 17: // 20-node
  case 12: // 27-node
  case 92: // 64-node
  case 93: // 125-node
    return Shape::hexahedron;
  case 4:  // 4-node tetrahedron
  case 11: // 10-node
  case 29: // 20-node
  case 30: // 35-node
  case 31: // 56-node
    return Shape::tetrahedron;
  case 6:  // 6-node prism
  case 18: // 15-node
  case 13: // 18-node
    return Shape::wedge;
  case 7:  // 5-node pyramid
  case 19: // 13-node
  case 14: // 14-node
    return Shape::pyramid;
  default:
    return std::nullopt;
  }
}

// Gmsh's reference elements are anvil's forms as they stand (solid_hex): tetrahedron
// (0,0,0) (1,0,0) (0,1,0) (0,0,1), the first three counter-clockwise seen from the
// fourth; prism (0,0,-1) (1,0,-1) (0,1,-1) and the same at z = 1 (edges 0-3, 1-4, 2-5),
// the bottom triangle counter-clockwise seen from the top one; pyramid base (-1,-1,0)
// (1,-1,0) (1,1,0) (-1,1,0), counter-clockwise seen from the apex (0,0,1).

// Every 3-D type of element_type() is a solid today; the message stays for any type
// added there that is not.
constexpr const char* solids_read =
    "anvil reads hexahedra (type 5; 17, 12, 92, 93 by their corners), tetrahedra (type 4; "
    "11, 29, 30, 31 by their corners), prisms (type 6; 18, 13 by their corners) and pyramids "
    "(type 7; 19, 14 by their corners)";

const char* dim_word(int dim) {
  static constexpr const char* words[4] = {"point", "curve", "surface", "volume"};
  return words[dim];
}

using EntityKey = std::pair<int, std::int64_t>; // (dimension, tag)

struct HexRecord {
  Hex nodes;          // 0-based node positions, the canonical hexahedron of any solid
  std::int64_t group; // 3-D physical tag of its block, 0 for none
  std::int64_t tag;   // the element's tag
};

// A line-oriented parser over the whole text. Gmsh writes one record per line, so the
// parser insists on that: every error can then name the line it found wrong.
class Parser {
public:
  Parser(std::string_view text, const std::string& name) : text_(text), name_(name) {}

  Mesh parse() {
    if (!next_nonblank()) fail_at(0, "the file is empty; expected $MeshFormat");
    if (tokens_.size() != 1 || tokens_[0] != "$MeshFormat")
      fail(fmt::format("expected $MeshFormat on the first line, found '{}'", shown(line_)));
    parse_format();
    while (next_nonblank()) {
      if (tokens_.size() != 1 || tokens_[0][0] != '$')
        fail(fmt::format("expected a section header ($Nodes, $Elements, ...), found '{}'",
                         shown(line_)));
      const std::string_view head = tokens_[0];
      section_ = std::string(head);
      if (head == "$MeshFormat") fail("a second $MeshFormat section");
      if (head.rfind("$End", 0) == 0) fail(fmt::format("'{}' without its section", shown(head)));
      if (head == "$PhysicalNames")
        parse_physical_names();
      else if (head == "$Entities")
        parse_entities();
      else if (head == "$Nodes")
        version_ == 4 ? parse_nodes_41() : parse_nodes_22();
      else if (head == "$Elements")
        version_ == 4 ? parse_elements_41() : parse_elements_22();
      else if (head == "$PartitionedEntities")
        fail("partitioned MSH files are not supported: save the mesh without partitions");
      else
        skip_section(); // $Periodic, $NodeData, $Comments, ...: nothing anvil uses
      section_.clear();
    }
    const int end_line = line_no_;
    if (version_ == 4 && !seen_entities_)
      fail_at(end_line, "the file has no $Entities section (required in MSH 4.1)");
    if (!seen_nodes_) fail_at(end_line, "the file has no $Nodes section");
    if (!seen_elements_) fail_at(end_line, "the file has no $Elements section");
    return build(end_line);
  }

private:
  // ---- lines and tokens -------------------------------------------------------------

  // Advances to the next line (without its end of line); false at the end of the text.
  bool next_line() {
    if (pos_ >= text_.size()) return false;
    const auto end = text_.find('\n', pos_);
    const auto stop = end == std::string_view::npos ? text_.size() : end;
    line_ = text_.substr(pos_, stop - pos_);
    if (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);
    pos_ = stop + 1;
    ++line_no_;
    split();
    return true;
  }

  bool next_nonblank() {
    while (next_line())
      if (!tokens_.empty()) return true;
    return false;
  }

  // The next line, which must exist and hold `count` tokens (-1: any number).
  void expect_line(const char* what, long count = -1) {
    if (!next_line()) fail_at(line_no_, fmt::format("the file ends early: expected {}", what));
    if (count >= 0 && static_cast<long>(tokens_.size()) != count)
      fail(fmt::format("expected {} ({} values), found {} values", what, count, tokens_.size()));
  }

  void split() {
    tokens_.clear();
    std::size_t i = 0;
    auto blank = [](char c) {
      return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
    };
    while (i < line_.size()) {
      while (i < line_.size() && blank(line_[i])) ++i;
      const std::size_t start = i;
      while (i < line_.size() && !blank(line_[i])) ++i;
      if (i > start) tokens_.push_back(line_.substr(start, i - start));
    }
  }

  // The line after the records of a section must close it: a wrong count shows up here.
  void expect_end(const char* end_tag) {
    if (!next_line()) fail_at(line_no_, fmt::format("the file ends early: expected {}", end_tag));
    if (tokens_.size() != 1 || tokens_[0] != end_tag)
      fail(fmt::format("expected {}, found '{}' (do the counts match the records?)", end_tag,
                       shown(line_)));
  }

  // ---- numbers ----------------------------------------------------------------------

  std::int64_t integer(std::string_view tok, const char* what) const {
    std::int64_t v = 0;
    const auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || p != tok.data() + tok.size())
      fail(fmt::format("{} must be an integer, found '{}'", what, shown(tok)));
    return v;
  }

  // A count of records that follow: non-negative and no more than the text can hold (so
  // that sums of counts cannot overflow and no reservation exceeds the file).
  std::int64_t count(std::string_view tok, const char* what) const {
    const std::int64_t v = integer(tok, what);
    if (v < 0) fail(fmt::format("{} must not be negative, found {}", what, v));
    if (static_cast<std::uint64_t>(v) > text_.size())
      fail(fmt::format("{} is {}, more than the file can hold", what, v));
    return v;
  }

  std::int64_t tag(std::string_view tok, const char* what) const {
    const std::int64_t v = integer(tok, what);
    if (v <= 0) fail(fmt::format("{} must be positive, found {}", what, v));
    return v;
  }

  int dimension(std::string_view tok) const {
    const std::int64_t v = integer(tok, "the entity dimension");
    if (v < 0 || v > 3) fail(fmt::format("the entity dimension must be 0 to 3, found {}", v));
    return static_cast<int>(v);
  }

  double real(std::string_view tok, const char* what) const {
    if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
    double v = 0;
    const auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || p != tok.data() + tok.size() || !std::isfinite(v))
      fail(fmt::format("{} must be a finite number, found '{}'", what, shown(tok)));
    return v;
  }

  // ---- errors -----------------------------------------------------------------------

  [[noreturn]] void fail(const std::string& message) const { fail_at(line_no_, message); }
  [[noreturn]] void fail_at(int line, const std::string& message) const {
    // A last line without its end of line is the usual sign of a cut-off file.
    const bool cut = line == line_no_ && line > 1 && pos_ > text_.size() && !line_.empty();
    throw InputError(SourceLocation{name_, line, section_},
                     cut ? message + " (the file ends within this line: truncated?)" : message);
  }

  // Text from the file for a message: short, and printable whatever the file holds.
  static std::string shown(std::string_view s) {
    std::string out;
    for (char c : s.substr(0, 60)) {
      const auto u = static_cast<unsigned char>(c);
      out += (u >= 0x20 && u < 0x7f) ? std::string(1, c) : fmt::format("\\x{:02x}", u);
    }
    if (s.size() > 60) out += "...";
    return out;
  }

  // ---- sections ---------------------------------------------------------------------

  void parse_format() {
    section_ = "$MeshFormat";
    expect_line("version, file type and data size", 3);
    const std::string_view v = tokens_[0];
    const std::int64_t file_type = integer(tokens_[1], "the file type");
    if (v == "4.1")
      version_ = 4;
    else if (v == "2.2" || v == "2.1" || v == "2" || v == "2.0")
      version_ = 2;
    else
      fail(fmt::format("MSH version {} is not supported: save as version 4.1 or 2.2 (ASCII)",
                       shown(v)));
    if (file_type != 0)
      fail("binary MSH files are not supported: save as ASCII (gmsh option -format msh41, "
           "without -bin)");
    if (integer(tokens_[2], "the data size") <= 0) fail("the data size must be positive");
    expect_end("$EndMeshFormat");
    section_.clear();
  }

  void parse_physical_names() {
    if (seen_names_) fail("a second $PhysicalNames section");
    seen_names_ = true;
    expect_line("the number of physical names", 1);
    const std::int64_t n = count(tokens_[0], "the number of physical names");
    for (std::int64_t i = 0; i < n; ++i) {
      expect_line("a physical name: dimension, tag and \"name\"");
      if (tokens_.size() < 3) fail("expected dimension, tag and \"name\"");
      const int dim = dimension(tokens_[0]);
      const std::int64_t t = tag(tokens_[1], "the physical tag");
      // The name is the rest of the line in double quotes; it may contain blanks.
      std::string_view rest =
          line_.substr(static_cast<std::size_t>(tokens_[2].data() - line_.data()));
      while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\t')) rest.remove_suffix(1);
      if (rest.size() < 2 || rest.front() != '"' || rest.back() != '"')
        fail(fmt::format("the physical name must be in double quotes, found '{}'", shown(rest)));
      const std::string_view name = rest.substr(1, rest.size() - 2);
      for (char c : name)
        if (c == '"' || static_cast<unsigned char>(c) < 0x20)
          fail(fmt::format("the physical name '{}' contains a quote or a control character",
                           shown(name)));
      if (!names_.emplace(EntityKey{dim, t}, std::make_pair(std::string(name), line_no_)).second)
        fail(fmt::format("physical {} {} is named twice", dim_word(dim), t));
    }
    expect_end("$EndPhysicalNames");
  }

  void parse_entities() {
    if (version_ != 4) fail("$Entities in an MSH 2 file");
    if (seen_entities_) fail("a second $Entities section");
    if (seen_nodes_) fail("$Entities must come before $Nodes");
    seen_entities_ = true;
    expect_line("the numbers of points, curves, surfaces and volumes", 4);
    std::int64_t n[4];
    for (int d = 0; d < 4; ++d) n[d] = count(tokens_[d], "the number of entities");
    for (int d = 0; d < 4; ++d)
      for (std::int64_t i = 0; i < n[d]; ++i) {
        expect_line("an entity record");
        // point: tag x y z nphys phys...; others: tag box(6) nphys phys... nbound bound...
        const std::size_t first_phys = d == 0 ? 5 : 8;
        if (tokens_.size() < first_phys)
          fail(fmt::format("a {} record needs at least {} values, found {}", dim_word(d),
                           first_phys, tokens_.size()));
        const std::int64_t t = tag(tokens_[0], "the entity tag");
        for (std::size_t k = 1; k + 1 < first_phys; ++k) real(tokens_[k], "a coordinate");
        const std::int64_t np = count(tokens_[first_phys - 1], "the number of physical tags");
        std::size_t expected = first_phys + static_cast<std::size_t>(np);
        if (tokens_.size() < expected + (d == 0 ? 0 : 1))
          fail(fmt::format("the {} record ends before its {} physical tags", dim_word(d), np));
        std::vector<std::int64_t> phys;
        for (std::int64_t k = 0; k < np; ++k)
          phys.push_back(tag(tokens_[first_phys + k], "a physical tag"));
        if (d > 0) {
          const std::int64_t nb = count(tokens_[expected], "the number of bounding entities");
          expected += 1 + static_cast<std::size_t>(nb);
          for (std::size_t k = first_phys + np + 1; k < tokens_.size() && k < expected; ++k)
            integer(tokens_[k], "a bounding entity tag"); // signed: orientation
        }
        if (tokens_.size() != expected)
          fail(fmt::format("the {} record has {} values, its counts say {}", dim_word(d),
                           tokens_.size(), expected));
        std::sort(phys.begin(), phys.end());
        phys.erase(std::unique(phys.begin(), phys.end()), phys.end());
        if (!entities_.emplace(EntityKey{d, t}, std::move(phys)).second)
          fail(fmt::format("{} {} is defined twice", dim_word(d), t));
      }
    expect_end("$EndEntities");
  }

  // Physical tags of an entity that an element or node block refers to.
  const std::vector<std::int64_t>& entity(int dim, std::int64_t t) const {
    const auto it = entities_.find({dim, t});
    if (it == entities_.end())
      fail(fmt::format("{} {} is not defined in $Entities", dim_word(dim), t));
    return it->second;
  }

  void add_node(std::int64_t t, const Vec3& x) {
    if (!node_index_.emplace(t, static_cast<std::int64_t>(nodes_.size())).second)
      fail(fmt::format("node {} is defined twice", t));
    nodes_.push_back(x);
    node_tags_.push_back(t);
  }

  // Reserve for `n` records, but never more than the remaining text could hold.
  std::size_t capped(std::int64_t n) const {
    return std::min<std::size_t>(static_cast<std::size_t>(n),
                                 (text_.size() - std::min(pos_, text_.size())) / 2 + 1);
  }

  void parse_nodes_41() {
    if (seen_nodes_) fail("a second $Nodes section");
    if (!seen_entities_) fail("$Entities must come before $Nodes (MSH 4.1)");
    seen_nodes_ = true;
    expect_line("numEntityBlocks numNodes minNodeTag maxNodeTag", 4);
    const std::int64_t blocks = count(tokens_[0], "the number of node blocks");
    const std::int64_t total = count(tokens_[1], "the number of nodes");
    const std::int64_t min_tag = integer(tokens_[2], "the smallest node tag");
    const std::int64_t max_tag = integer(tokens_[3], "the largest node tag");
    nodes_.reserve(capped(total));
    node_index_.reserve(capped(total));
    std::int64_t seen = 0;
    std::vector<std::int64_t> tags;
    for (std::int64_t b = 0; b < blocks; ++b) {
      expect_line("entityDim entityTag parametric numNodesInBlock", 4);
      const int dim = dimension(tokens_[0]);
      entity(dim, tag(tokens_[1], "the entity tag"));
      const std::int64_t parametric = integer(tokens_[2], "the parametric flag");
      if (parametric != 0 && parametric != 1) fail("the parametric flag must be 0 or 1");
      const std::int64_t n = count(tokens_[3], "the number of nodes in the block");
      seen += n;
      if (seen > total)
        fail(fmt::format("the node blocks hold more than the {} nodes declared", total));
      tags.clear();
      tags.reserve(capped(n));
      for (std::int64_t i = 0; i < n; ++i) {
        expect_line("a node tag", 1);
        const std::int64_t t = tag(tokens_[0], "the node tag");
        if (t < min_tag || t > max_tag)
          fail(fmt::format("node tag {} is outside the declared range {} to {}", t, min_tag,
                           max_tag));
        tags.push_back(t);
      }
      const long values = 3 + (parametric ? dim : 0);
      for (std::int64_t i = 0; i < n; ++i) {
        expect_line("node coordinates", values);
        add_node(tags[i],
                 Vec3{real(tokens_[0], "x"), real(tokens_[1], "y"), real(tokens_[2], "z")});
        for (long k = 3; k < values; ++k) real(tokens_[k], "a parametric coordinate");
      }
    }
    if (seen != total)
      fail_at(line_no_, fmt::format("{} nodes are declared but the blocks hold {}", total, seen));
    expect_end("$EndNodes");
  }

  void parse_nodes_22() {
    if (seen_nodes_) fail("a second $Nodes section");
    seen_nodes_ = true;
    expect_line("the number of nodes", 1);
    const std::int64_t n = count(tokens_[0], "the number of nodes");
    nodes_.reserve(capped(n));
    node_index_.reserve(capped(n));
    for (std::int64_t i = 0; i < n; ++i) {
      expect_line("a node: tag x y z", 4);
      add_node(tag(tokens_[0], "the node tag"),
               Vec3{real(tokens_[1], "x"), real(tokens_[2], "y"), real(tokens_[3], "z")});
    }
    expect_end("$EndNodes");
  }

  std::int64_t node(std::string_view tok) const {
    const std::int64_t t = integer(tok, "a node tag");
    const auto it = node_index_.find(t);
    if (it == node_index_.end()) fail(fmt::format("node {} is not defined in $Nodes", t));
    return it->second;
  }

  // One element whose node tags are tokens_[first..]; `phys` are the physical tags of its
  // entity (sorted), `dim` the entity's dimension.
  void add_element(std::int64_t etag, std::int64_t type, const ElementType& info, int dim,
                   std::size_t first, const std::vector<std::int64_t>& phys, bool dedupe) {
    if (!element_tags_.insert(etag).second) fail(fmt::format("element {} is defined twice", etag));
    if (info.dim != dim)
      fail(fmt::format("element {} is a {} (type {}) but its entity is a {}", etag, info.name, type,
                       dim_word(dim)));
    node_ids_.clear();
    for (int a = 0; a < info.nodes; ++a) node_ids_.push_back(node(tokens_[first + a]));
    const std::optional<Shape> solid = solid_of(type);
    if (dim == 3 && !solid) {
      std::string where;
      if (!phys.empty()) where = fmt::format(" in physical volume '{}'", group_name(3, phys[0]));
      fail(fmt::format("element {}{} is a {} (type {}); {}", etag, where, info.name, type,
                       solids_read));
    }
    for (const auto p : phys) {
      auto& set = set_nodes_[{dim, p}];
      set.insert(set.end(), node_ids_.begin(), node_ids_.end());
    }
    if (dim != 3) return;
    HexRecord h{{}, phys.empty() ? 0 : phys[0], etag};
    if (solid == Shape::hexahedron) {
      Hex tags;
      for (int a = 0; a < 8; ++a) tags[a] = integer(tokens_[first + a], "a node tag");
      if (const std::string why = canonical_hex(tags, etag); !why.empty()) fail(why);
      std::copy_n(node_ids_.begin(), 8, h.nodes.begin());
      canonical_hex(h.nodes, etag); // the same repeats as the tags': the same rewrite
    } else {
      // A tetrahedron, prism or pyramid names each of its corners once.
      const int n = corner_count(*solid);
      for (int a = 1; a < n; ++a)
        for (int b = 0; b < a; ++b)
          if (node_ids_[a] == node_ids_[b])
            fail(fmt::format("element {} ({}, type {}) uses node {} twice (corners {} and {})",
                             etag, info.name, type, tokens_[first + a], b + 1, a + 1));
      h.nodes = solid_hex(*solid, node_ids_.data());
    }
    // MSH 2 writes an element once per physical group it belongs to: the copies add set
    // membership (done above), not elements.
    if (dedupe && !hex_seen_.emplace(h.nodes, hexes_.size()).second) return;
    hexes_.push_back(h);
  }

  void parse_elements_41() {
    if (seen_elements_) fail("a second $Elements section");
    if (!seen_nodes_) fail("$Elements must come after $Nodes");
    seen_elements_ = true;
    expect_line("numEntityBlocks numElements minElementTag maxElementTag", 4);
    const std::int64_t blocks = count(tokens_[0], "the number of element blocks");
    const std::int64_t total = count(tokens_[1], "the number of elements");
    const std::int64_t min_tag = integer(tokens_[2], "the smallest element tag");
    const std::int64_t max_tag = integer(tokens_[3], "the largest element tag");
    element_tags_.reserve(capped(total));
    std::int64_t seen = 0;
    for (std::int64_t b = 0; b < blocks; ++b) {
      expect_line("entityDim entityTag elementType numElementsInBlock", 4);
      const int dim = dimension(tokens_[0]);
      const std::int64_t etag = tag(tokens_[1], "the entity tag");
      const auto& phys = entity(dim, etag);
      const std::int64_t type = integer(tokens_[2], "the element type");
      const auto info = element_type(type);
      if (!info) fail(fmt::format("unknown element type {}", type));
      if (info->dim != dim)
        fail(fmt::format("a block of {} elements (type {}) in {} {}: the element type's "
                         "dimension must be the entity's",
                         info->name, type, dim_word(dim), etag));
      if (dim == 3 && !solid_of(type))
        fail(fmt::format(
            "a block of {} elements (type {}) in volume {}{}; {}", info->name, type, etag,
            phys.empty() ? std::string()
                         : fmt::format(" (physical volume '{}')", group_name(3, phys[0])),
            solids_read));
      const std::int64_t n = count(tokens_[3], "the number of elements in the block");
      seen += n;
      if (seen > total)
        fail(fmt::format("the element blocks hold more than the {} elements declared", total));
      for (std::int64_t i = 0; i < n; ++i) {
        expect_line("an element: tag and node tags", 1 + info->nodes);
        const std::int64_t t = tag(tokens_[0], "the element tag");
        if (t < min_tag || t > max_tag)
          fail(fmt::format("element tag {} is outside the declared range {} to {}", t, min_tag,
                           max_tag));
        add_element(t, type, *info, dim, 1, phys, false);
      }
    }
    if (seen != total)
      fail(fmt::format("{} elements are declared but the blocks hold {}", total, seen));
    expect_end("$EndElements");
  }

  void parse_elements_22() {
    if (seen_elements_) fail("a second $Elements section");
    if (!seen_nodes_) fail("$Elements must come after $Nodes");
    seen_elements_ = true;
    expect_line("the number of elements", 1);
    const std::int64_t n = count(tokens_[0], "the number of elements");
    element_tags_.reserve(capped(n));
    std::vector<std::int64_t> phys;
    for (std::int64_t i = 0; i < n; ++i) {
      expect_line("an element: tag type numTags tags... nodes...");
      if (tokens_.size() < 3) fail("expected element tag, type and number of tags");
      const std::int64_t t = tag(tokens_[0], "the element tag");
      const std::int64_t type = integer(tokens_[1], "the element type");
      const auto info = element_type(type);
      if (!info) fail(fmt::format("unknown element type {}", type));
      const std::int64_t ntags = count(tokens_[2], "the number of tags");
      const std::size_t expected = 3 + static_cast<std::size_t>(ntags) + info->nodes;
      if (tokens_.size() != expected)
        fail(fmt::format("element {} ({}, {} tags) needs {} values, found {}", t, info->name, ntags,
                         expected, tokens_.size()));
      // tags: physical, elementary entity, then partitions; physical 0 means none.
      phys.clear();
      if (ntags >= 1) {
        const std::int64_t p = integer(tokens_[3], "the physical tag");
        if (p < 0) fail(fmt::format("the physical tag must not be negative, found {}", p));
        if (p > 0) phys.push_back(p);
      }
      for (std::int64_t k = 1; k < ntags; ++k) integer(tokens_[3 + k], "an element tag");
      add_element(t, type, *info, info->dim, 3 + static_cast<std::size_t>(ntags), phys, true);
    }
    expect_end("$EndElements");
  }

  void skip_section() {
    const std::string end = "$End" + section_.substr(1);
    const int start = line_no_;
    while (next_line())
      if (tokens_.size() == 1 && tokens_[0] == end) return;
    fail_at(start, fmt::format("section {} is not closed by {}", section_, end));
  }

  // ---- the mesh ---------------------------------------------------------------------

  std::string group_name(int dim, std::int64_t t) const {
    const auto it = names_.find({dim, t});
    if (it != names_.end() && !it->second.first.empty()) return it->second.first;
    return fmt::format("{}_{}", dim_word(dim), t);
  }

  Mesh build(int end_line) {
    if (hexes_.empty())
      fail_at(end_line, "the file has no solid elements (no hexahedra, tetrahedra, prisms or "
                        "pyramids): mesh the volumes and save them (Physical Volume or "
                        "Mesh.SaveAll)");
    Mesh mesh;
    mesh.nodes = std::move(nodes_);
    mesh.node_ids = std::move(node_tags_);
    // Blocks by ascending physical tag, "mesh" (no group) last; file order within.
    std::set<std::int64_t> groups;
    for (const auto& h : hexes_) groups.insert(h.group);
    std::vector<std::int64_t> order(groups.begin(), groups.end());
    if (!order.empty() && order.front() == 0)
      std::rotate(order.begin(), order.begin() + 1, order.end());
    for (const auto g : order) {
      ElementBlock b{g == 0 ? std::string("mesh") : group_name(3, g), {}, {}};
      for (const auto& h : hexes_)
        if (h.group == g) {
          b.elements.push_back(h.nodes);
          b.ids.push_back(h.tag);
        }
      mesh.blocks.push_back(std::move(b));
    }
    // Node sets; two groups may not share a name (their sets would silently merge).
    std::map<std::string, EntityKey> owner;
    for (auto& [key, ids] : set_nodes_) {
      const std::string name = group_name(key.first, key.second);
      if (const auto [it, fresh] = owner.emplace(name, key); !fresh) {
        const auto named = names_.find(key);
        fail_at(named != names_.end() ? named->second.second : end_line,
                fmt::format("physical {} {} and physical {} {} are both named '{}'",
                            dim_word(it->second.first), it->second.second, dim_word(key.first),
                            key.second, name));
      }
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      mesh.node_sets[name] = std::move(ids);
    }
    return mesh;
  }

  std::string_view text_;
  const std::string& name_;
  std::size_t pos_ = 0;
  int line_no_ = 0;
  std::string_view line_;
  std::vector<std::string_view> tokens_;
  std::string section_; // for error messages: the section being read

  int version_ = 4;
  bool seen_names_ = false, seen_entities_ = false, seen_nodes_ = false, seen_elements_ = false;
  std::map<EntityKey, std::pair<std::string, int>> names_;  // physical -> (name, line)
  std::map<EntityKey, std::vector<std::int64_t>> entities_; // entity -> physical tags
  std::vector<Vec3> nodes_;
  std::unordered_map<std::int64_t, std::int64_t> node_index_; // Gmsh tag -> position
  std::vector<std::int64_t> node_tags_;                       // position -> Gmsh tag
  std::unordered_set<std::int64_t> element_tags_;
  std::vector<HexRecord> hexes_;
  std::map<Hex, std::size_t> hex_seen_;                      // MSH 2 duplicates
  std::map<EntityKey, std::vector<std::int64_t>> set_nodes_; // physical -> node positions
  std::vector<std::int64_t> node_ids_;                       // scratch
};

} // namespace

Mesh parse_gmsh(std::string_view text, const std::string& name) {
  // A UTF-8 byte-order mark, as some Windows editors write it, is no part of the mesh
  // (skipped as in keyword files).
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  try {
    return Parser(text, name).parse();
  } catch (const std::bad_alloc&) {
    throw InputError(SourceLocation{name, 0, ""}, "the mesh does not fit in memory");
  } catch (const std::length_error&) {
    throw InputError(SourceLocation{name, 0, ""}, "the mesh does not fit in memory");
  }
}

Mesh read_gmsh(const std::string& path) {
  std::string text;
  try {
    text = read_input_file(path, std::numeric_limits<std::uintmax_t>::max(), "mesh file");
  } catch (const std::bad_alloc&) {
    throw InputError(SourceLocation{path, 0, ""}, "the file does not fit in memory");
  } catch (const std::length_error&) {
    throw InputError(SourceLocation{path, 0, ""}, "the file does not fit in memory");
  }
  return parse_gmsh(text, path);
}

} // namespace anvil
