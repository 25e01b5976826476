#include "anvil/io/checkpoint.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "anvil/core/error.hpp"
#include "anvil/core/hash.hpp"
#include "anvil/io/files.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil {

namespace {

// The format's version is the magic's last character. Version 5 put the payload's length
// and its FNV-1a checksum after the magic and the mesh's fingerprint in the header;
// version 6 the particles' fingerprint. Older files are refused: rerun to write a new one.
constexpr char magic[8] = {'A', 'N', 'V', 'I', 'L', 'C', 'K', '6'};
constexpr std::size_t magic_version = 7;
constexpr std::size_t payload_start = sizeof magic + 2 * sizeof(std::uint64_t); // length, sum
static_assert(Checkpoint::point_values == 8 * ThickShell::max_points);

// Records travel to rank 0, and files are read, in pieces of at most this many bytes: an
// MPI message counts its bytes in an int, and a piece bounds the buffers either side.
constexpr std::size_t piece_bytes = std::size_t{8} << 20;

// Sends `n` values to rank 0 in pieces; recv_pieces receives them (the same pieces).
template <class T>
void send_pieces(const Comm& comm, const T* v, std::size_t n, int tag) {
  constexpr std::size_t piece = piece_bytes / sizeof(T);
  for (std::size_t i = 0; i < n; i += piece)
    comm.send_bytes(v + i, std::min(piece, n - i) * sizeof(T), 0, tag);
}
template <class T>
void recv_pieces(const Comm& comm, T* v, std::size_t n, int source, int tag) {
  constexpr std::size_t piece = piece_bytes / sizeof(T);
  for (std::size_t i = 0; i < n; i += piece)
    comm.recv_bytes(v + i, std::min(piece, n - i) * sizeof(T), source, tag);
}

// One section of the checkpoint, gathered on rank 0 in ascending global id: every rank's
// records, each with its global id `gid[i]`, one integer `extra[i]` and the Width values
// that fill(i, out) writes for this rank's record i. Rank 0 gathers the ids and sorts
// them first, then puts each record's values straight at their place in the section
// (its own as fill writes them, the others' as they arrive, a piece at a time): it holds
// the section once, with the ids' order, and no rank builds its values whole.
template <int Width, class Fill>
void gather_sorted(const Comm& comm, const std::vector<std::int64_t>& gid,
                   const std::vector<std::int64_t>& extra, const Fill& fill,
                   std::vector<std::int64_t>& out_gid, std::vector<double>& out_data,
                   std::vector<std::int64_t>& out_extra) {
  constexpr std::size_t piece = std::max<std::size_t>(1, piece_bytes / (Width * sizeof(double)));
  const std::size_t mine = gid.size();
  const auto counts = comm.allgather(static_cast<std::int64_t>(mine));
  if (comm.rank() != 0) {
    send_pieces(comm, gid.data(), mine, 21);
    send_pieces(comm, extra.data(), mine, 23);
    std::vector<double> buffer(std::min(piece, mine) * Width);
    for (std::size_t i0 = 0; i0 < mine; i0 += piece) {
      const std::size_t n = std::min(piece, mine - i0);
      for (std::size_t i = 0; i < n; ++i) fill(i0 + i, &buffer[i * Width]);
      comm.send_bytes(buffer.data(), n * Width * sizeof(double), 0, 22);
    }
    return;
  }
  // Every rank's ids and extras in rank order, then their order by id.
  std::vector<std::size_t> first(counts.size() + 1, 0); // each rank's first record
  for (std::size_t r = 0; r < counts.size(); ++r)
    first[r + 1] = first[r] + static_cast<std::size_t>(counts[r]);
  const std::size_t total = first.back();
  std::vector<std::int64_t> all_gid(total), all_extra(total);
  std::copy(gid.begin(), gid.end(), all_gid.begin());
  std::copy(extra.begin(), extra.end(), all_extra.begin());
  for (int r = 1; r < comm.size(); ++r) {
    const std::size_t at = first[static_cast<std::size_t>(r)];
    const std::size_t n = first[static_cast<std::size_t>(r) + 1] - at;
    recv_pieces(comm, all_gid.data() + at, n, r, 21);
    recv_pieces(comm, all_extra.data() + at, n, r, 23);
  }
  std::vector<std::size_t> order(total);
  for (std::size_t i = 0; i < total; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return all_gid[a] < all_gid[b]; });
  out_gid.resize(total);
  out_extra.resize(total);
  for (std::size_t k = 0; k < total; ++k) {
    out_gid[k] = all_gid[order[k]];
    out_extra[k] = all_extra[order[k]];
  }
  all_extra = {};
  // Where each record goes: all_gid's room, its ids being in out_gid now.
  std::vector<std::int64_t>& place = all_gid;
  for (std::size_t k = 0; k < total; ++k) place[order[k]] = static_cast<std::int64_t>(k);
  order = {};
  out_data.resize(total * Width);
  auto at = [&](std::size_t i) { return &out_data[static_cast<std::size_t>(place[i]) * Width]; };
  for (std::size_t i = 0; i < mine; ++i) fill(i, at(i));
  std::vector<double> buffer;
  for (int r = 1; r < comm.size(); ++r) {
    const std::size_t r0 = first[static_cast<std::size_t>(r)];
    const std::size_t n = first[static_cast<std::size_t>(r) + 1] - r0;
    buffer.resize(std::min(piece, n) * Width);
    for (std::size_t i0 = 0; i0 < n; i0 += piece) {
      const std::size_t m = std::min(piece, n - i0);
      comm.recv_bytes(buffer.data(), m * Width * sizeof(double), r, 22);
      for (std::size_t i = 0; i < m; ++i)
        std::memcpy(at(r0 + i0 + i), &buffer[i * Width], Width * sizeof(double));
    }
  }
}

// Reads a checkpoint's payload section by section, straight into the vectors that keep
// it, and its FNV-1a checksum over the bytes as they come: no copy of the file is held.
class PayloadReader {
public:
  PayloadReader(std::ifstream& in, std::uint64_t size, std::uint64_t sum, const std::string& path)
      : in_(in), size_(size), sum_(sum), path_(path) {}

  // The next section: its number of items, then the items.
  template <class T>
  void get(std::vector<T>& v) {
    std::uint64_t n = 0;
    if (size_ - pos_ < sizeof n) truncated();
    read(&n, sizeof n);
    if (n > (size_ - pos_) / sizeof(T)) truncated();
    v.resize(n);
    read(v.data(), n * sizeof(T));
  }

  // Reads what is left (nothing, in a checkpoint as written) and checks the checksum:
  // InputError unless it matches. Returns whether bytes were left.
  bool finish() {
    const bool left = pos_ < size_;
    std::vector<char> rest(
        static_cast<std::size_t>(std::min<std::uint64_t>(size_ - pos_, piece_bytes)));
    while (pos_ < size_)
      read(rest.data(),
           static_cast<std::size_t>(std::min<std::uint64_t>(size_ - pos_, rest.size())));
    if (hash_.value() != sum_)
      throw InputError(fmt::format("checkpoint '{}' is corrupt: its checksum does not match its "
                                   "contents",
                                   path_));
    return left;
  }

private:
  // A section that runs past the file's end: a damaged file (the checksum says so), else
  // truncated.
  [[noreturn]] void truncated() {
    finish();
    throw InputError("checkpoint '" + path_ + "' is truncated");
  }

  void read(void* data, std::size_t bytes) {
    auto* p = static_cast<char*>(data);
    for (std::size_t done = 0; done < bytes;) {
      const std::size_t n = std::min(piece_bytes, bytes - done);
      in_.read(p + done, static_cast<std::streamsize>(n));
      if (static_cast<std::size_t>(in_.gcount()) != n)
        throw InputError("cannot read checkpoint '" + path_ + "'");
      hash_.bytes(p + done, n); // (while the piece is in the cache)
      done += n;
    }
    pos_ += bytes;
  }

  std::ifstream& in_;
  std::uint64_t size_, sum_, pos_ = payload_start;
  const std::string& path_;
  Fnv1a hash_;
};

} // namespace

Checkpoint capture(const Simulation& sim, const OutputState& outputs) {
  const Comm& comm = sim.comm();
  Checkpoint c;
  c.deck = sim.config().deck_file;
  const Clock& clk = sim.clock();
  c.time = clk.time;
  c.cycle = clk.cycle;
  c.dt = clk.dt;
  c.dt_prev = clk.dt_prev;
  c.dt_initial = clk.dt_initial;
  c.outputs = outputs;
  c.model_nodes = sim.global_nodes();
  c.model_elements = sim.global_elements();
  c.mesh_fingerprint = sim.mesh_fingerprint();
  c.particle_fingerprint = sim.particle_fingerprint();
  c.mass_scaling_target = sim.mass_scaling_target();
  double diag[2] = {sim.external_work_local(), sim.contact_energy_local()};
  comm.sum(std::span<double>(diag, 2));
  c.external_work = diag[0];
  c.contact_energy = diag[1];

  // Each section: this rank's records' ids and extras, where their values are, and how
  // to write a record's values (gather_sorted asks for them a piece at a time).
  std::vector<std::int64_t> gid, extra;
  const auto& nd = sim.nodes();
  const ContactPhase* cp = sim.contact();
  {
    std::vector<std::size_t> node; // this rank's owned nodes
    node.reserve(nd.size());
    gid.reserve(nd.size());
    extra.reserve(nd.size());
    for (std::size_t n = 0; n < nd.size(); ++n) {
      if (!sim.fe().node_owned[n]) continue;
      node.push_back(n);
      gid.push_back(sim.fe().node_gid[n]);
      extra.push_back(cp ? cp->last_face()[n] : -1);
    }
    auto fill = [&](std::size_t i, double* d) {
      const std::size_t n = node[i];
      for (int k = 0; k < 3; ++k) d[k] = nd.x[k][n];
      for (int k = 0; k < 3; ++k) d[3 + k] = nd.v[k][n];
      d[6] = cp ? cp->allowance()[n] : 0.0;
    };
    gather_sorted<Checkpoint::node_values>(comm, gid, extra, fill, c.node_gid, c.node_data,
                                           c.node_face);
  }
  // This rank's elements (of every block, or of the thick-shell blocks): block, element.
  std::vector<std::array<int, 2>> element;
  auto list_elements = [&](bool thick_shells_only) {
    std::size_t n = 0;
    for (const auto& b : sim.blocks())
      if (!thick_shells_only || b.thick_shell.enabled()) n += static_cast<std::size_t>(b.size());
    gid.clear();
    extra.clear();
    element.clear();
    gid.reserve(n);
    extra.reserve(n);
    element.reserve(n);
    const auto& blocks = sim.blocks();
    for (std::size_t ib = 0; ib < blocks.size(); ++ib) {
      const auto& b = blocks[ib];
      if (thick_shells_only && !b.thick_shell.enabled()) continue;
      for (int e = 0; e < b.size(); ++e) {
        gid.push_back(b.gid[e]);
        extra.push_back(thick_shells_only ? b.thick_shell.points : b.alive[e] == 0.0 ? 1 : 0);
        element.push_back({static_cast<int>(ib), e});
      }
    }
  };
  list_elements(false);
  auto fill_element = [&](std::size_t i, double* d) {
    const auto& b = sim.blocks()[static_cast<std::size_t>(element[i][0])];
    const int e = element[i][1];
    for (int k = 0; k < 6; ++k) d[k] = b.stress[k][e];
    d[6] = b.plastic_strain.empty() ? 0.0 : b.plastic_strain[e];
    d[7] = b.temperature.empty() ? 0.0 : b.temperature[e];
    d[8] = b.internal_energy[e];
    d[9] = b.hourglass_energy[e];
    for (int k = 0; k < 12; ++k)
      d[10 + k] = b.hourglass_force[k].empty() ? 0.0 : b.hourglass_force[k][e];
  };
  gather_sorted<Checkpoint::element_values>(comm, gid, extra, fill_element, c.element_gid,
                                            c.element_data, c.element_eroded);
  list_elements(true);
  auto fill_points = [&](std::size_t i, double* d) {
    const auto& b = sim.blocks()[static_cast<std::size_t>(element[i][0])];
    const int e = element[i][1];
    for (int p = 0; p < ThickShell::max_points; ++p, d += 8) {
      const bool in = p < b.thick_shell.points;
      for (int k = 0; k < 6; ++k) d[k] = in ? b.point_stress[p][k][e] : 0.0;
      d[6] = in && !b.point_plastic_strain.empty() ? b.point_plastic_strain[p][e] : 0.0;
      d[7] = in && !b.point_temperature.empty() ? b.point_temperature[p][e] : 0.0;
    }
  };
  gather_sorted<Checkpoint::point_values>(comm, gid, extra, fill_points, c.point_gid, c.point_data,
                                          c.point_count);
  element = {};
  if (const sph::SphPhase* sph = sim.sph()) {
    c.model_particles = sph->global_count();
    const sph::Particles& pt = sph->particles();
    gid.assign(pt.gid.begin(), pt.gid.begin() + static_cast<std::ptrdiff_t>(pt.size()));
    extra.assign(pt.last_face.begin(),
                 pt.last_face.begin() + static_cast<std::ptrdiff_t>(pt.size()));
    auto fill = [&](std::size_t i, double* d) {
      for (int k = 0; k < 3; ++k) d[k] = pt.x[k][i];
      for (int k = 0; k < 3; ++k) d[3 + k] = pt.v[k][i];
      d[6] = pt.rho[i];
      d[7] = pt.h[i];
      for (int k = 0; k < 6; ++k) d[8 + k] = pt.stress[k][i];
      d[14] = pt.energy[i];
      d[15] = pt.plastic_strain[i];
      d[16] = pt.temperature[i];
      d[17] = pt.wave_speed[i];
    };
    gather_sorted<Checkpoint::particle_values>(comm, gid, extra, fill, c.particle_gid,
                                               c.particle_data, c.particle_face);
  }
  return c;
}

void write_checkpoint(const std::string& path, const Checkpoint& c) {
  nlohmann::json h;
  h["deck"] = c.deck;
  h["time"] = c.time;
  h["cycle"] = c.cycle;
  h["dt"] = c.dt;
  h["dt_prev"] = c.dt_prev;
  h["dt_initial"] = c.dt_initial;
  h["external_work"] = c.external_work;
  h["contact_energy"] = c.contact_energy;
  h["model_nodes"] = c.model_nodes;
  h["model_elements"] = c.model_elements;
  h["model_particles"] = c.model_particles;
  h["mesh_fingerprint"] = c.mesh_fingerprint;
  h["particle_fingerprint"] = c.particle_fingerprint;
  h["mass_scaling_target"] = c.mass_scaling_target;
  h["next_fields"] = c.outputs.next_fields;
  h["next_history"] = c.outputs.next_history;
  h["next_checkpoint"] = c.outputs.next_checkpoint;
  h["field_count"] = c.outputs.field_count;
  h["pvd"] = c.outputs.pvd;
  h["particle_pvd"] = c.outputs.particle_pvd;
  h["history_rows"] = c.outputs.history_rows;
  h["history_last"] = c.outputs.history_last;
  // Doubles as raw bits in the binary part: the header's decimal text is for people.
  const double exact[8] = {c.time,
                           c.dt,
                           c.dt_prev,
                           c.dt_initial,
                           c.external_work,
                           c.contact_energy,
                           c.outputs.next_fields,
                           c.outputs.next_history};
  const std::string header = json_text(h);
  // The file is the magic, the payload's length and checksum, then the payload: sections,
  // each its number of items and the items. It is written from where the sections lie,
  // piece by piece, with no copy of it in memory.
  constexpr std::size_t sections = 15;
  std::array<std::uint64_t, sections> items{};
  std::uint64_t trailer[2] = {}; // the payload's length and checksum
  std::vector<std::string_view> pieces;
  pieces.reserve(2 + 2 * sections);
  pieces.emplace_back(magic, sizeof magic);
  pieces.emplace_back(reinterpret_cast<const char*>(trailer), sizeof trailer);
  std::size_t section = 0;
  auto put = [&]<class T>(const T* v, std::size_t n) {
    items[section] = n;
    pieces.emplace_back(reinterpret_cast<const char*>(&items[section]), sizeof(std::uint64_t));
    ++section;
    if (n) pieces.emplace_back(reinterpret_cast<const char*>(v), n * sizeof(T));
  };
  auto put_vector = [&](const auto& v) { put(v.data(), v.size()); };
  put(header.data(), header.size());
  put(exact, 8);
  put(&c.outputs.next_checkpoint, 1);
  put_vector(c.node_gid);
  put_vector(c.node_data);
  put_vector(c.node_face);
  put_vector(c.element_gid);
  put_vector(c.element_data);
  put_vector(c.particle_gid);
  put_vector(c.particle_data);
  put_vector(c.particle_face);
  put_vector(c.element_eroded);
  put_vector(c.point_gid);
  put_vector(c.point_data);
  put_vector(c.point_count);
  Fnv1a sum;
  for (std::size_t k = 2; k < pieces.size(); ++k) {
    trailer[0] += pieces[k].size();
    sum.bytes(pieces[k]);
  }
  trailer[1] = sum.value();
  write_file_atomic(path, pieces);
}

namespace {

// Throws unless `gid` is strictly ascending and within [0, limit).
void check_ids(const std::vector<std::int64_t>& gid, std::int64_t limit, const char* what,
               const std::string& path) {
  for (std::size_t k = 0; k < gid.size(); ++k)
    if (gid[k] < 0 || gid[k] >= limit || (k > 0 && gid[k] <= gid[k - 1]))
      throw InputError(fmt::format("checkpoint '{}' is inconsistent: its {} ids are not "
                                   "ascending ids of the model",
                                   path, what));
}

// Throws unless every value of the section is finite.
void check_finite(const std::vector<double>& data, int width, const char* what,
                  const std::vector<std::int64_t>& gid, const std::string& path) {
  for (std::size_t k = 0; k < data.size(); ++k)
    if (!std::isfinite(data[k]))
      throw InputError(fmt::format("checkpoint '{}' holds a non-finite value for {} {}", path, what,
                                   gid[k / static_cast<std::size_t>(width)] + 1));
}

} // namespace

Checkpoint read_checkpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open checkpoint '" + path + "'");
  char start[payload_start] = {};
  in.read(start, sizeof start);
  const auto got = static_cast<std::size_t>(in.gcount());
  if (got < sizeof magic || std::memcmp(start, magic, magic_version) != 0)
    throw InputError("'" + path + "' is not an anvil checkpoint");
  const char version = start[magic_version];
  if (version >= '1' && version < magic[magic_version])
    throw InputError(fmt::format("checkpoint '{}' was written by an older anvil (format version "
                                 "{}); this anvil reads version {} only: run the deck again to "
                                 "write a new checkpoint",
                                 path, version, magic[magic_version]));
  if (version != magic[magic_version])
    throw InputError(
        fmt::format("checkpoint '{}' has format version {}; this anvil reads version {}", path,
                    version, magic[magic_version]));
  if (got < payload_start) throw InputError("checkpoint '" + path + "' is truncated");
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  in.seekg(static_cast<std::streamoff>(payload_start));
  if (end < static_cast<std::streamoff>(payload_start) || !in)
    throw InputError("cannot read checkpoint '" + path + "'");
  const auto size = static_cast<std::uint64_t>(end);
  std::uint64_t trailer[2] = {};
  std::memcpy(trailer, start + sizeof magic, sizeof trailer);
  const std::uint64_t payload = size - payload_start;
  if (payload < trailer[0])
    throw InputError(fmt::format("checkpoint '{}' is truncated: {} of its {} bytes", path, size,
                                 trailer[0] + payload_start));
  if (payload > trailer[0])
    throw InputError(fmt::format("checkpoint '{}' is corrupt: {} bytes follow its end", path,
                                 payload - trailer[0]));
  Checkpoint c;
  c.file = path;
  std::vector<char> header;
  std::vector<double> exact, next_checkpoint;
  PayloadReader r(in, size, trailer[1], path);
  r.get(header);
  r.get(exact);
  r.get(next_checkpoint);
  r.get(c.node_gid);
  r.get(c.node_data);
  r.get(c.node_face);
  r.get(c.element_gid);
  r.get(c.element_data);
  r.get(c.particle_gid);
  r.get(c.particle_data);
  r.get(c.particle_face);
  r.get(c.element_eroded);
  r.get(c.point_gid);
  r.get(c.point_data);
  r.get(c.point_count);
  const bool bytes_left = r.finish(); // (the checksum: before anything is believed)
  try {
    const auto h = nlohmann::json::parse(std::string(header.begin(), header.end()));
    c.deck = h.at("deck").get<std::string>();
    c.cycle = h.at("cycle").get<std::int64_t>();
    c.model_nodes = h.at("model_nodes").get<std::int64_t>();
    c.model_elements = h.at("model_elements").get<std::int64_t>();
    c.model_particles = h.at("model_particles").get<std::int64_t>();
    c.mesh_fingerprint = h.at("mesh_fingerprint").get<std::uint64_t>();
    c.particle_fingerprint = h.at("particle_fingerprint").get<std::uint64_t>();
    if (h.contains("mass_scaling_target")) // (since mass scaling; same format version)
      c.mass_scaling_target = h.at("mass_scaling_target").get<double>();
    c.outputs.field_count = h.at("field_count").get<int>();
    c.outputs.pvd = h.at("pvd").get<std::vector<std::pair<double, std::string>>>();
    c.outputs.particle_pvd =
        h.at("particle_pvd").get<std::vector<std::pair<double, std::string>>>();
    if (h.contains("history_rows")) { // (since 2026-11-23; same format version)
      c.outputs.history_rows = h.at("history_rows").get<std::int64_t>();
      c.outputs.history_last = h.at("history_last").get<std::string>();
    }
  } catch (const std::exception& e) {
    throw InputError("checkpoint '" + path + "' has a damaged header: " + e.what());
  }
  if (bytes_left || exact.size() != 8 || next_checkpoint.size() != 1 ||
      c.node_data.size() != c.node_gid.size() * Checkpoint::node_values ||
      c.node_face.size() != c.node_gid.size() ||
      c.element_data.size() != c.element_gid.size() * Checkpoint::element_values ||
      c.element_eroded.size() != c.element_gid.size() ||
      c.particle_data.size() != c.particle_gid.size() * Checkpoint::particle_values ||
      c.particle_face.size() != c.particle_gid.size() ||
      c.point_data.size() != c.point_gid.size() * Checkpoint::point_values ||
      c.point_count.size() != c.point_gid.size() ||
      c.model_nodes != static_cast<std::int64_t>(c.node_gid.size()) ||
      c.model_elements != static_cast<std::int64_t>(c.element_gid.size()) ||
      c.model_particles != static_cast<std::int64_t>(c.particle_gid.size()) ||
      std::any_of(c.point_count.begin(), c.point_count.end(),
                  [](std::int64_t n) { return n < 1 || n > ThickShell::max_points; }))
    throw InputError("checkpoint '" + path + "' is inconsistent");
  constexpr std::int64_t any = std::numeric_limits<std::int64_t>::max();
  check_ids(c.node_gid, any, "node", path);
  check_ids(c.element_gid, c.model_elements, "element", path);
  check_ids(c.point_gid, c.model_elements, "thick-shell element", path);
  check_ids(c.particle_gid, any, "particle", path);
  check_finite(c.node_data, Checkpoint::node_values, "node", c.node_gid, path);
  check_finite(c.element_data, Checkpoint::element_values, "element", c.element_gid, path);
  check_finite(c.particle_data, Checkpoint::particle_values, "particle", c.particle_gid, path);
  check_finite(c.point_data, Checkpoint::point_values, "thick-shell element", c.point_gid, path);
  c.time = exact[0];
  c.dt = exact[1];
  c.dt_prev = exact[2];
  c.dt_initial = exact[3];
  c.external_work = exact[4];
  c.contact_energy = exact[5];
  c.outputs.next_fields = exact[6];
  c.outputs.next_history = exact[7];
  c.outputs.next_checkpoint = next_checkpoint[0];
  return c;
}

} // namespace anvil
