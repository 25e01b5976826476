#include "anvil/io/checkpoint.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
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

// Sends this rank's records to rank 0, which keeps them in ascending global id.
template <int Width>
void gather_sorted(const Comm& comm, const std::vector<std::int64_t>& gid,
                   const std::vector<double>& data, const std::vector<std::int64_t>& extra,
                   std::vector<std::int64_t>& out_gid, std::vector<double>& out_data,
                   std::vector<std::int64_t>& out_extra) {
  const auto counts = comm.allgather(static_cast<std::int64_t>(gid.size()));
  if (comm.rank() != 0) {
    if (!gid.empty()) {
      comm.send_bytes(gid.data(), gid.size() * sizeof(std::int64_t), 0, 21);
      comm.send_bytes(data.data(), data.size() * sizeof(double), 0, 22);
      comm.send_bytes(extra.data(), extra.size() * sizeof(std::int64_t), 0, 23);
    }
    return;
  }
  std::vector<std::int64_t> all_gid(gid), all_extra(extra);
  std::vector<double> all_data(data);
  for (int r = 1; r < comm.size(); ++r) {
    const auto n = static_cast<std::size_t>(counts[static_cast<std::size_t>(r)]);
    if (n == 0) continue;
    const std::size_t g0 = all_gid.size(), d0 = all_data.size();
    all_gid.resize(g0 + n);
    all_extra.resize(g0 + n);
    all_data.resize(d0 + n * Width);
    comm.recv_bytes(all_gid.data() + g0, n * sizeof(std::int64_t), r, 21);
    comm.recv_bytes(all_data.data() + d0, n * Width * sizeof(double), r, 22);
    comm.recv_bytes(all_extra.data() + g0, n * sizeof(std::int64_t), r, 23);
  }
  std::vector<std::size_t> order(all_gid.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return all_gid[a] < all_gid[b]; });
  out_gid.resize(order.size());
  out_extra.resize(order.size());
  out_data.resize(order.size() * Width);
  for (std::size_t k = 0; k < order.size(); ++k) {
    out_gid[k] = all_gid[order[k]];
    out_extra[k] = all_extra[order[k]];
    std::memcpy(&out_data[k * Width], &all_data[order[k] * Width], Width * sizeof(double));
  }
}

template <class T>
void put(std::string& s, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  s.append(reinterpret_cast<const char*>(&n), sizeof n);
  if (n) s.append(reinterpret_cast<const char*>(v.data()), n * sizeof(T));
}

template <class T>
void get(const std::string& s, std::size_t& pos, std::vector<T>& v, const std::string& path) {
  std::uint64_t n = 0;
  if (pos + sizeof n > s.size()) throw InputError("checkpoint '" + path + "' is truncated");
  std::memcpy(&n, s.data() + pos, sizeof n);
  pos += sizeof n;
  if (n > (s.size() - pos) / sizeof(T)) throw InputError("checkpoint '" + path + "' is truncated");
  v.resize(n);
  if (n) std::memcpy(v.data(), s.data() + pos, n * sizeof(T));
  pos += n * sizeof(T);
}

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
  double diag[2] = {sim.external_work_local(), sim.contact_energy_local()};
  comm.sum(std::span<double>(diag, 2));
  c.external_work = diag[0];
  c.contact_energy = diag[1];

  std::vector<std::int64_t> gid, face;
  std::vector<double> data;
  const auto& nd = sim.nodes();
  const ContactPhase* cp = sim.contact();
  for (std::size_t n = 0; n < nd.size(); ++n) {
    if (!sim.fe().node_owned[n]) continue;
    gid.push_back(sim.fe().node_gid[n]);
    for (int i = 0; i < 3; ++i) data.push_back(nd.x[i][n]);
    for (int i = 0; i < 3; ++i) data.push_back(nd.v[i][n]);
    data.push_back(cp ? cp->allowance()[n] : 0.0);
    face.push_back(cp ? cp->last_face()[n] : -1);
  }
  gather_sorted<Checkpoint::node_values>(comm, gid, data, face, c.node_gid, c.node_data,
                                         c.node_face);
  gid.clear();
  data.clear();
  face.clear();
  for (const auto& b : sim.blocks())
    for (int e = 0; e < b.size(); ++e) {
      gid.push_back(b.gid[e]);
      for (int k = 0; k < 6; ++k) data.push_back(b.stress[k][e]);
      data.push_back(b.plastic_strain.empty() ? 0.0 : b.plastic_strain[e]);
      data.push_back(b.temperature.empty() ? 0.0 : b.temperature[e]);
      data.push_back(b.internal_energy[e]);
      data.push_back(b.hourglass_energy[e]);
      for (int k = 0; k < 12; ++k)
        data.push_back(b.hourglass_force[k].empty() ? 0.0 : b.hourglass_force[k][e]);
      face.push_back(b.alive[e] == 0.0 ? 1 : 0);
    }
  gather_sorted<Checkpoint::element_values>(comm, gid, data, face, c.element_gid, c.element_data,
                                            c.element_eroded);
  gid.clear();
  data.clear();
  face.clear();
  for (const auto& b : sim.blocks())
    for (int e = 0; b.thick_shell.enabled() && e < b.size(); ++e) {
      gid.push_back(b.gid[e]);
      for (int p = 0; p < ThickShell::max_points; ++p) {
        const bool in = p < b.thick_shell.points;
        for (int k = 0; k < 6; ++k) data.push_back(in ? b.point_stress[p][k][e] : 0.0);
        data.push_back(in && !b.point_plastic_strain.empty() ? b.point_plastic_strain[p][e] : 0.0);
        data.push_back(in && !b.point_temperature.empty() ? b.point_temperature[p][e] : 0.0);
      }
      face.push_back(b.thick_shell.points);
    }
  gather_sorted<Checkpoint::point_values>(comm, gid, data, face, c.point_gid, c.point_data,
                                          c.point_count);
  if (const sph::SphPhase* sph = sim.sph()) {
    c.model_particles = sph->global_count();
    gid.clear();
    data.clear();
    face.clear();
    const sph::Particles& pt = sph->particles();
    for (std::size_t i = 0; i < pt.size(); ++i) {
      gid.push_back(pt.gid[i]);
      for (int k = 0; k < 3; ++k) data.push_back(pt.x[k][i]);
      for (int k = 0; k < 3; ++k) data.push_back(pt.v[k][i]);
      data.push_back(pt.rho[i]);
      data.push_back(pt.h[i]);
      for (int k = 0; k < 6; ++k) data.push_back(pt.stress[k][i]);
      data.push_back(pt.energy[i]);
      data.push_back(pt.plastic_strain[i]);
      data.push_back(pt.temperature[i]);
      data.push_back(pt.wave_speed[i]);
      face.push_back(pt.last_face[i]);
    }
    gather_sorted<Checkpoint::particle_values>(comm, gid, data, face, c.particle_gid,
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
  std::string s(payload_start, '\0');
  std::memcpy(s.data(), magic, sizeof magic);
  const std::string header = json_text(h);
  put(s, std::vector<char>(header.begin(), header.end()));
  put(s, std::vector<double>(exact, exact + 8));
  put(s, std::vector<double>{c.outputs.next_checkpoint});
  put(s, c.node_gid);
  put(s, c.node_data);
  put(s, c.node_face);
  put(s, c.element_gid);
  put(s, c.element_data);
  put(s, c.particle_gid);
  put(s, c.particle_data);
  put(s, c.particle_face);
  put(s, c.element_eroded);
  put(s, c.point_gid);
  put(s, c.point_data);
  put(s, c.point_count);
  const std::string_view payload = std::string_view(s).substr(payload_start);
  const std::uint64_t trailer[2] = {payload.size(), Fnv1a().bytes(payload).value()};
  std::memcpy(s.data() + sizeof magic, trailer, sizeof trailer);
  write_file_atomic(path, s);
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
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string s = ss.str();
  if (s.size() < sizeof magic || std::memcmp(s.data(), magic, magic_version) != 0)
    throw InputError("'" + path + "' is not an anvil checkpoint");
  const char version = s[magic_version];
  if (version >= '1' && version < magic[magic_version])
    throw InputError(fmt::format("checkpoint '{}' was written by an older anvil (format version "
                                 "{}); this anvil reads version {} only: run the deck again to "
                                 "write a new checkpoint",
                                 path, version, magic[magic_version]));
  if (version != magic[magic_version])
    throw InputError(
        fmt::format("checkpoint '{}' has format version {}; this anvil reads version {}", path,
                    version, magic[magic_version]));
  if (s.size() < payload_start) throw InputError("checkpoint '" + path + "' is truncated");
  std::uint64_t trailer[2] = {};
  std::memcpy(trailer, s.data() + sizeof magic, sizeof trailer);
  const std::string_view payload = std::string_view(s).substr(payload_start);
  if (payload.size() < trailer[0])
    throw InputError(fmt::format("checkpoint '{}' is truncated: {} of its {} bytes", path, s.size(),
                                 trailer[0] + payload_start));
  if (payload.size() > trailer[0])
    throw InputError(fmt::format("checkpoint '{}' is corrupt: {} bytes follow its end", path,
                                 payload.size() - trailer[0]));
  if (Fnv1a().bytes(payload).value() != trailer[1])
    throw InputError(fmt::format("checkpoint '{}' is corrupt: its checksum does not match its "
                                 "contents",
                                 path));
  std::size_t pos = payload_start;
  Checkpoint c;
  c.file = path;
  std::vector<char> header;
  std::vector<double> exact, next_checkpoint;
  get(s, pos, header, path);
  get(s, pos, exact, path);
  get(s, pos, next_checkpoint, path);
  get(s, pos, c.node_gid, path);
  get(s, pos, c.node_data, path);
  get(s, pos, c.node_face, path);
  get(s, pos, c.element_gid, path);
  get(s, pos, c.element_data, path);
  get(s, pos, c.particle_gid, path);
  get(s, pos, c.particle_data, path);
  get(s, pos, c.particle_face, path);
  get(s, pos, c.element_eroded, path);
  get(s, pos, c.point_gid, path);
  get(s, pos, c.point_data, path);
  get(s, pos, c.point_count, path);
  try {
    const auto h = nlohmann::json::parse(std::string(header.begin(), header.end()));
    c.deck = h.at("deck").get<std::string>();
    c.cycle = h.at("cycle").get<std::int64_t>();
    c.model_nodes = h.at("model_nodes").get<std::int64_t>();
    c.model_elements = h.at("model_elements").get<std::int64_t>();
    c.model_particles = h.at("model_particles").get<std::int64_t>();
    c.mesh_fingerprint = h.at("mesh_fingerprint").get<std::uint64_t>();
    c.particle_fingerprint = h.at("particle_fingerprint").get<std::uint64_t>();
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
  if (pos != s.size() || exact.size() != 8 || next_checkpoint.size() != 1 ||
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
