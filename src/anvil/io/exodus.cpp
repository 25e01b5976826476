#include "anvil/io/exodus.hpp"

#include <algorithm>
#include <cstdint>
#include <ctime>
#include <limits>
#include <set>

#include <exodusII.h>
#include <fmt/format.h>

#include "anvil/core/error.hpp"
#include "anvil/solver/simulation.hpp"
#include "anvil/version.hpp"

namespace anvil {

namespace {

// Arrays that go into the id maps and block structure rather than into variables.
bool is_map_array(const VtuArray& a) {
  return a.name == "node_id" || a.name == "element_id" || a.name == "part";
}

// Exodus variable names of an array's components (the SEACAS suffix conventions, which
// ParaView joins back into vectors and tensors).
std::vector<std::string> component_names(const VtuArray& a) {
  static constexpr const char* vec[3] = {"_x", "_y", "_z"};
  static constexpr const char* sym[6] = {"_xx", "_yy", "_zz", "_xy", "_yz", "_zx"};
  std::vector<std::string> out;
  for (int k = 0; k < a.components; ++k) {
    if (a.components == 1)
      out.push_back(a.name);
    else if (a.components == 3)
      out.push_back(a.name + vec[k]);
    else if (a.components == 6)
      out.push_back(a.name + sym[k]);
    else
      out.push_back(fmt::format("{}_{}", a.name, k));
  }
  return out;
}

// Component `k` of the first `count` tuples of an array from `first`, as doubles.
void gather(const VtuArray& a, int k, std::size_t first, std::size_t count,
            std::vector<double>& out) {
  out.resize(count);
  const auto c = static_cast<std::size_t>(a.components);
  for (std::size_t i = 0; i < count; ++i)
    out[i] =
        a.is_int ? static_cast<double>(a.i64[(first + i) * c + k]) : a.f64[(first + i) * c + k];
}

// Names as the C API wants them: an array of char pointers into `storage`.
struct NameList {
  std::vector<std::string> storage;
  std::vector<char*> ptrs;
  explicit NameList(std::vector<std::string> names) : storage(std::move(names)) {
    for (auto& s : storage) ptrs.push_back(s.data());
  }
};

// The longest prefix of `s` of at most `max_bytes` bytes that ends on a UTF-8 character
// boundary (deck strings are UTF-8; a cut inside a character leaves invalid text).
std::string utf8_prefix(const std::string& s, std::size_t max_bytes) {
  if (s.size() <= max_bytes) return s;
  std::size_t cut = max_bytes;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
  return s.substr(0, cut);
}

} // namespace

std::vector<std::string> exodus_names(const std::vector<std::string>& names,
                                      std::size_t max_bytes) {
  std::vector<std::string> out(names.size());
  std::set<std::string> used;
  // Names that fit are kept as they are; the others are cut, and a cut that repeats a
  // name already taken ends in ~2, ~3, ... instead.
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i].size() <= max_bytes && used.insert(names[i]).second) out[i] = names[i];
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!out[i].empty() || names[i].empty()) continue;
    std::string name = utf8_prefix(names[i], max_bytes);
    for (int k = 2; used.count(name) > 0; ++k) {
      const std::string suffix = fmt::format("~{}", k);
      name = utf8_prefix(names[i], max_bytes - std::min(max_bytes, suffix.size())) + suffix;
    }
    used.insert(name);
    out[i] = name;
  }
  return out;
}

std::string exodus_path(const std::string& dir, int ranks, int rank, const std::string& stem) {
  if (ranks == 1) return fmt::format("{}/{}.exo", dir, stem);
  const int digits = static_cast<int>(std::to_string(ranks).size());
  return fmt::format("{}/{}.exo.{}.{:0{}d}", dir, stem, ranks, rank, digits);
}

void ExodusWriter::fail(const std::string& what) const {
  const char* msg = nullptr;
  const char* func = nullptr;
  int code = 0;
  ex_get_err(&msg, &func, &code);
  throw InputError(fmt::format("cannot write the Exodus II file '{}': {}{}", path_, what,
                               msg && *msg ? fmt::format(" ({})", msg) : std::string()));
}

ExodusWriter::ExodusWriter(const std::string& path, const Simulation& sim, const VtuPiece& layout)
    : path_(path) {
  int cpu_word_size = sizeof(double), io_word_size = sizeof(double);
  // netCDF classic with 64-bit offsets: a killed run leaves a file whose header and
  // records up to the last ex_update are consistent (HDF5 files offer no such promise).
  // Not in netCDF's share mode, which writes the record count as soon as a step begins,
  // so that a kill mid-step would leave a step of fill values. 64-bit integers through
  // the API, 32-bit in the file (classic has no other), unless an id of the model (on any
  // rank: the pieces share one format) needs more: then the integers are 64-bit in the
  // file, which the Exodus library (6.02 as Debian ships it) stores only in netCDF-4.
  const bool wide_ids = sim.max_file_id() > std::numeric_limits<std::int32_t>::max();
  const int format = wide_ids ? EX_NETCDF4 | EX_ALL_INT64_DB : EX_LARGE_MODEL;
  id_ = ex_create(path.c_str(), EX_CLOBBER | EX_NOSHARE | format | EX_ALL_INT64_API, &cpu_word_size,
                  &io_word_size);
  if (id_ < 0) fail("cannot create the file");
  check(ex_set_max_name_length(id_, static_cast<int>(max_name_bytes)), "names");

  const auto& blocks = sim.blocks();
  const auto& parts = sim.config().parts;
  const std::size_t nn = sim.nodes().size();
  std::int64_t ne = 0;
  for (const auto& b : blocks) {
    block_sizes_.push_back(b.size());
    ne += b.size();
  }
  const std::string title =
      utf8_prefix(sim.config().title.empty() ? "anvil" : sim.config().title, MAX_LINE_LENGTH);
  check(ex_put_init(id_, title.c_str(), 3, static_cast<std::int64_t>(nn), ne,
                    static_cast<std::int64_t>(blocks.size()), 0, 0),
        "the header");

  // Reference coordinates: ParaView adds the displacement variable to them.
  const auto& x0 = sim.nodes().x0;
  if (nn > 0) check(ex_put_coord(id_, x0[0].data(), x0[1].data(), x0[2].data()), "coordinates");
  {
    NameList names({"x", "y", "z"});
    check(ex_put_coord_names(id_, names.ptrs.data()), "coordinate names");
  }

  const VtuArray* node_ids = nullptr;
  const VtuArray* element_ids = nullptr;
  for (const auto& a : layout.point_data)
    if (a.name == "node_id") node_ids = &a;
  for (const auto& a : layout.cell_data)
    if (a.name == "element_id") element_ids = &a;
  if (node_ids && nn > 0) check(ex_put_id_map(id_, EX_NODE_MAP, node_ids->i64.data()), "node ids");

  // One block per part, in part order; local connectivity is 1-based.
  std::size_t cell = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const auto count = block_sizes_[b];
    const auto bid = static_cast<ex_entity_id>(b + 1);
    check(ex_put_block(id_, EX_ELEM_BLOCK, bid, "HEX8", count, 8, 0, 0, 0), "an element block");
    if (count > 0) {
      std::vector<std::int64_t> conn(layout.connectivity.begin() + 8 * cell,
                                     layout.connectivity.begin() + 8 * (cell + count));
      for (auto& n : conn) ++n;
      check(ex_put_conn(id_, EX_ELEM_BLOCK, bid, conn.data(), nullptr, nullptr),
            "the connectivity");
    }
    cell += static_cast<std::size_t>(count);
  }
  if (!blocks.empty()) {
    std::vector<std::string> names;
    for (std::size_t b = 0; b < blocks.size(); ++b)
      names.push_back(b < parts.size() ? parts[b].name : fmt::format("block_{}", b + 1));
    // Cut to the file's name length here, distinct and on a character boundary, rather
    // than by the library (which cuts bytes and warns on stderr in its own format).
    NameList list(exodus_names(names, max_name_bytes));
    check(ex_put_names(id_, EX_ELEM_BLOCK, list.ptrs.data()), "block names");
  }
  if (element_ids && ne > 0)
    check(ex_put_id_map(id_, EX_ELEM_MAP, element_ids->i64.data()), "element ids");

  // Nemesis: which piece of how many this file is, and the global counts.
  const int ranks = sim.comm().size();
  if (ranks > 1) {
    char type[] = "p";
    check(ex_put_init_info(id_, ranks, 1, type), "the parallel information");
    check(ex_put_init_global(id_, sim.global_nodes(), sim.global_elements(),
                             static_cast<std::int64_t>(blocks.size()), 0, 0),
          "the global counts");
  }

  // Variables: every component of every array but the id arrays.
  std::vector<std::string> nodal_names, element_names;
  for (std::size_t i = 0; i < layout.point_data.size(); ++i) {
    if (is_map_array(layout.point_data[i])) continue;
    const auto names = component_names(layout.point_data[i]);
    for (int k = 0; k < static_cast<int>(names.size()); ++k) {
      nodal_.push_back({i, k});
      nodal_names.push_back(names[k]);
    }
  }
  for (std::size_t i = 0; i < layout.cell_data.size(); ++i) {
    if (is_map_array(layout.cell_data[i])) continue;
    const auto names = component_names(layout.cell_data[i]);
    for (int k = 0; k < static_cast<int>(names.size()); ++k) {
      element_.push_back({i, k});
      element_names.push_back(names[k]);
    }
  }
  // A rank that holds no node (fewer elements than ranks) has no nodal variables to
  // declare: Exodus defines them over the nodes.
  if (nn == 0) nodal_.clear();
  if (!nodal_.empty()) {
    check(ex_put_variable_param(id_, EX_NODAL, static_cast<int>(nodal_.size())), "nodal variables");
    NameList list(nodal_names);
    check(ex_put_variable_names(id_, EX_NODAL, static_cast<int>(nodal_.size()), list.ptrs.data()),
          "nodal variable names");
  }
  if (!element_.empty() && !blocks.empty()) {
    check(ex_put_variable_param(id_, EX_ELEM_BLOCK, static_cast<int>(element_.size())),
          "element variables");
    NameList list(element_names);
    check(ex_put_variable_names(id_, EX_ELEM_BLOCK, static_cast<int>(element_.size()),
                                list.ptrs.data()),
          "element variable names");
    // Blocks without elements on this rank store no values (Exodus's NULL blocks).
    std::vector<int> table;
    for (std::size_t b = 0; b < blocks.size(); ++b)
      for (std::size_t v = 0; v < element_.size(); ++v) table.push_back(block_sizes_[b] > 0);
    check(ex_put_truth_table(id_, EX_ELEM_BLOCK, static_cast<int>(blocks.size()),
                             static_cast<int>(element_.size()), table.data()),
          "the variable truth table");
  }

  // Provenance: the code and the wall-clock time of writing.
  {
    const std::time_t now = std::time(nullptr);
    char date[32] = "", clock[32] = "";
    std::tm tm{};
    if (localtime_r(&now, &tm)) {
      std::strftime(date, sizeof date, "%Y/%m/%d", &tm);
      std::strftime(clock, sizeof clock, "%H:%M:%S", &tm);
    }
    std::string code = "anvil", ver(version);
    char* qa[1][4] = {{code.data(), ver.data(), date, clock}};
    check(ex_put_qa(id_, 1, qa), "the QA record");
  }
  check(ex_update(id_), "the header (flush)");
}

ExodusWriter::~ExodusWriter() {
  if (id_ >= 0) ex_close(id_);
}

void ExodusWriter::write_step(double time, const VtuPiece& piece) {
  const int step = step_ + 1;
  check(ex_put_time(id_, step, &time), "a time value");
  std::vector<double> values;
  const std::size_t nn = piece.points.size() / 3;
  if (nn > 0)
    for (std::size_t v = 0; v < nodal_.size(); ++v) {
      gather(piece.point_data[nodal_[v].array], nodal_[v].component, 0, nn, values);
      check(ex_put_var(id_, step, EX_NODAL, static_cast<int>(v) + 1, 1,
                       static_cast<std::int64_t>(nn), values.data()),
            "a nodal variable");
    }
  std::size_t first = 0;
  for (std::size_t b = 0; b < block_sizes_.size(); ++b) {
    const auto count = static_cast<std::size_t>(block_sizes_[b]);
    if (count > 0)
      for (std::size_t v = 0; v < element_.size(); ++v) {
        gather(piece.cell_data[element_[v].array], element_[v].component, first, count, values);
        check(ex_put_var(id_, step, EX_ELEM_BLOCK, static_cast<int>(v) + 1,
                         static_cast<ex_entity_id>(b + 1), static_cast<std::int64_t>(count),
                         values.data()),
              "an element variable");
      }
    first += count;
  }
  // On disk now: a run killed after this reads up to this step.
  check(ex_update(id_), "a time step (flush)");
  step_ = step;
}

} // namespace anvil
