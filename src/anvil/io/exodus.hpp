// Exodus II field output (`output: {format: exodus | both}`): one file per rank in the
// Nemesis naming that ParaView and SEACAS (epu) read as one decomposed model,
// `results.exo.P.R` (R zero-padded to the digits of P), or `results.exo` on one rank.
//
// Each file holds this rank's nodes (reference coordinates, shared nodes in every file
// that uses them) and elements, one element block per part named after it, the global
// node and element ids as the id maps, and per field output one time step: nodal
// displacement_x/y/z and velocity_x/y/z (ParaView applies `displacement` to the
// coordinates), element stress_xx ... stress_zx, von_mises, pressure, plastic_strain,
// temperature (when a part has it), fe_rank (and contact_rank with contact). The file is
// netCDF classic (64-bit offset) and flushed after every step, so a run killed mid-way
// leaves a file that reads up to its last complete step. A model with an id above
// 2^31 - 1 (a mesh file's) is written as netCDF-4 with 64-bit integers instead, the only
// way the Exodus library stores such ids; HDF5 makes no promise about killed runs.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "anvil/io/vtu.hpp"

namespace anvil {

class Simulation;

// The file of `rank` among `ranks` in `dir`: STEM.exo, or STEM.exo.P.R on P ranks (the
// SEACAS naming that ParaView and epu read).
std::string exodus_path(const std::string& dir, int ranks, int rank,
                        const std::string& stem = "results");

// Longest name (part, variable) the files hold, in bytes.
inline constexpr std::size_t max_name_bytes = 80;

// `names` as the file stores them: a name of at most `max_bytes` bytes as it is, a longer
// one cut on a UTF-8 character boundary, and a cut that repeats a name already taken
// ending in ~2, ~3, ... instead, so that the names stay distinct.
std::vector<std::string> exodus_names(const std::vector<std::string>& names, std::size_t max_bytes);

class ExodusWriter {
public:
  // Creates the file at `path` (replacing one that exists) with this rank's mesh and the
  // variables of `layout` (a piece from fe_piece: its arrays name the variables). Not
  // collective. Throws InputError when the file cannot be written.
  ExodusWriter(const std::string& path, const Simulation& sim, const VtuPiece& layout);
  ~ExodusWriter();
  ExodusWriter(const ExodusWriter&) = delete;
  ExodusWriter& operator=(const ExodusWriter&) = delete;

  // Appends a time step with the values of `piece` (same layout as at creation) and
  // flushes the file. Throws InputError when the write fails.
  void write_step(double time, const VtuPiece& piece);

  int steps() const { return step_; }

private:
  struct Variable {
    std::size_t array; // index into the piece's point_data or cell_data
    int component;     // of that array
  };
  [[noreturn]] void fail(const std::string& what) const;
  void check(int rc, const char* what) const {
    if (rc < 0) fail(what);
  }

  std::string path_;
  int id_ = -1;
  int step_ = 0;
  std::vector<Variable> nodal_, element_;
  std::vector<std::int64_t> block_sizes_; // elements of each block on this rank
};

} // namespace anvil
