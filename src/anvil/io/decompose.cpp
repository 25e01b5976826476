#include "anvil/io/decompose.hpp"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "anvil/fe/hex_block.hpp"
#include "anvil/io/files.hpp"
#include "anvil/io/outputs.hpp"
#include "anvil/parallel/graph_partition.hpp"
#include "anvil/parallel/rcb_statistics.hpp"
#include "anvil/solver/model.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil {

namespace {

// Per-rank values gathered on every rank, with max / mean.
nlohmann::json per_rank(const Comm& comm, double local) {
  const auto all = comm.allgather(local);
  double sum = 0, mx = 0;
  for (double v : all) {
    sum += v;
    mx = std::max(mx, v);
  }
  const double mean = sum / static_cast<double>(all.size());
  return {{"per_rank", all}, {"total", sum}, {"imbalance", mean > 0 ? mx / mean : 1.0}};
}

// A series of one step, at t = 0: a .vtu piece per rank, the .pvtu joining them and a
// .pvd naming it, as a run writes results.pvd and particles.pvd. Collective.
void write_series(const Comm& comm, const std::string& outdir, const std::string& stem,
                  const std::string& pvd, const VtuPiece& piece) {
  collective_write(comm, [&] {
    write_vtu(outdir + "/" + stem + "_r" + std::to_string(comm.rank()) + ".vtu", piece);
  });
  collective_write(comm, [&] {
    if (comm.rank() != 0) return;
    std::vector<std::string> pieces;
    for (int r = 0; r < comm.size(); ++r)
      pieces.push_back(stem + "_r" + std::to_string(r) + ".vtu");
    write_pvtu(outdir + "/" + stem + ".pvtu", pieces, piece);
    write_pvd(outdir + "/" + pvd, {{0.0, stem + ".pvtu"}});
  });
}

} // namespace

void write_decomposition(const Config& config, const std::string& outdir, const Comm& comm) {
  Simulation sim(config, comm);
  sim.decompose_now();
  // Rank 0 creates the directory; a failure stops every rank (none waits for the others).
  collective_write(comm, [&] {
    if (comm.rank() == 0) make_directories(outdir);
  });

  // The elements (a deck of particles only has none) and the particles, each with the
  // rank of its decomposition.
  const bool elements = sim.global_elements() > 0;
  if (elements) write_series(comm, outdir, "decomposition", "results.pvd", fe_piece(sim));
  if (sim.sph())
    write_series(comm, outdir, "particles_decomposition", "particles.pvd", particle_piece(sim));

  nlohmann::json j;
  j["ranks"] = comm.size();
  j["elements"] = sim.global_elements();
  j["nodes"] = sim.global_nodes();
  j["particles"] = sim.sph() ? sim.sph()->global_count() : 0;
  // The deck's `decomposition` key, as used: the RCBs' stretch (and the FE method below).
  const DecompositionConfig& dc = config.decomposition;
  j["rcb_scale"] = {dc.scale.x, dc.scale.y, dc.scale.z};
  if (elements) {
    nlohmann::json fe;
    fe["method"] = dc.fe == DecompositionConfig::Fe::metis ? "metis" : "rcb";
    fe["elements"] = per_rank(comm, static_cast<double>(sim.fe().num_elements()));
    // The work the partition balances: each element weighted by its formulation's cost.
    double cost = 0;
    for (std::size_t b = 0; b < sim.fe().blocks.size(); ++b)
      cost += static_cast<double>(sim.fe().blocks[b].gid.size()) *
              element_cost(config.parts[b].hourglass, config.parts[b].thick_shell);
    fe["cost"] = per_rank(comm, cost);
    fe["owned_nodes"] = per_rank(comm, static_cast<double>(sim.fe().num_owned_nodes()));
    fe["held_nodes"] = per_rank(comm, static_cast<double>(sim.fe().node_gid.size()));
    double shared = 0;
    for (const auto& nb : sim.fe().neighbors) shared += static_cast<double>(nb.shared.size());
    fe["shared_node_copies"] = per_rank(comm, shared);
    fe["neighbours"] = per_rank(comm, static_cast<double>(sim.fe().neighbors.size()));
    const Mesh mesh = build_mesh(config);
    const std::vector<int> owner = partition_model(mesh, config, comm); // collective
    if (comm.rank() == 0) {
      fe["edge_cut"] = partition_cut(mesh, owner);
      // Pairs of elements of bodies about to meet that the graph links (METIS only).
      if (dc.fe == DecompositionConfig::Fe::metis)
        fe["body_links"] = contact_body_links(mesh, config).size();
    }
    j["fe"] = fe;
  }
  if (const ContactPhase* cp = sim.contact()) {
    nlohmann::json c = rcb_statistics(cp->rcb());
    c["nodes_held"] = per_rank(comm, static_cast<double>(cp->nodes_held()));
    c["faces_held"] = per_rank(comm, static_cast<double>(cp->faces_held()));
    j["contact"] = c;
  }
  if (const auto* sph = sim.sph()) {
    nlohmann::json p = rcb_statistics(sph->rcb());
    p["particles"] = per_rank(comm, static_cast<double>(sph->particles().size()));
    j["sph"] = p;
  }
  collective_write(comm, [&] {
    if (comm.rank() == 0) write_file_atomic(outdir + "/decomposition.json", json_text(j, 2) + "\n");
  });
}

} // namespace anvil
