// `anvil decompose`: the decompositions of a model at t = 0, as pictures and numbers.
#pragma once

#include <string>

#include "anvil/io/config.hpp"
#include "anvil/parallel/comm.hpp"

namespace anvil {

// Writes OUTDIR/decomposition.pvtu (+ per-rank .vtu pieces, results.pvd) with the cell
// fields fe_rank and contact_rank (the RCB rank of each element's first exterior face);
// with particles, OUTDIR/particles_decomposition.pvtu (+ pieces, particles.pvd) with the
// point field sph_rank; and OUTDIR/decomposition.json: per decomposition the counts per
// rank, the imbalance and, for the FE partition, the edge cut; for the contact and SPH
// RCBs their cuts and boxes. Collective.
void write_decomposition(const Config& config, const std::string& outdir, const Comm& comm);

} // namespace anvil
