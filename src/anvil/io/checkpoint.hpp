// Checkpoints: the complete state of a run, independent of the number of ranks (nodes,
// elements and SPH particles keyed by global id), written atomically (temporary file,
// fsync, rename; the previous checkpoint stays until the new one is complete). `anvil run
// DECK --restart CHECKPOINT` continues from one, on the same or another number of ranks,
// and reproduces the uninterrupted run bit for bit. The file carries its length and an
// FNV-1a checksum of its contents (a damaged, truncated or extended file is refused) and
// a fingerprint of the mesh it was written for (a restart with another mesh is refused).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace anvil {

class Simulation;

// Where the output series stood (so a restarted run continues it).
struct OutputState {
  double next_fields = 0, next_history = 0, next_checkpoint = 0;
  int field_count = 0;
  std::vector<std::pair<double, std::string>> pvd;          // results.pvd (rank 0)
  std::vector<std::pair<double, std::string>> particle_pvd; // particles.pvd (rank 0)
  // history.csv as written so far (rank 0): its rows and the last of them, for a restart
  // to tell this run's history from a later run's in the same directory (-1: unknown, a
  // checkpoint from before they were recorded).
  std::int64_t history_rows = -1;
  std::string history_last;
};

struct Checkpoint {
  static constexpr int node_values = 7;     // x, y, z, vx, vy, vz, contact allowance
  static constexpr int element_values = 22; // stress (6), plastic strain, temperature,
                                            // internal and hourglass energy, Q (12)
  // Per particle: x (3), v (3), density, smoothing length, stress (6), specific energy,
  // plastic strain, temperature, wave speed. What the deck fixes (set, mass, reference
  // position, constraints) is not stored: the restarted run rebuilds it from the deck.
  static constexpr int particle_values = 18;
  // Per thick-shell element: stress (6), plastic strain and temperature at
  // each of up to five points through the thickness (zero past the element's points).
  static constexpr int point_values = 8 * 5; // 5: ThickShell::max_points
  std::string deck;                          // the deck the run came from (for messages)
  std::string file; // the file it was read from (for messages; empty when captured)
  double time = 0, dt = 0, dt_prev = 0, dt_initial = 0;
  std::int64_t cycle = 0;
  double external_work = 0, contact_energy = 0; // global diagnostics
  // Mass scaling's element step (time_step.mass_scaling step / scale; 0: none): the
  // masses of the run, which a restart must keep.
  double mass_scaling_target = 0;
  OutputState outputs;
  std::vector<std::int64_t> node_gid;               // ascending
  std::vector<double> node_data;                    // node_values per node
  std::vector<std::int64_t> node_face;              // contact history: last face per node
  std::vector<std::int64_t> element_gid;            // ascending
  std::vector<double> element_data;                 // element_values per element
  std::vector<std::int64_t> element_eroded;         // 1 for an eroded element
  std::vector<std::int64_t> particle_gid;           // ascending (empty without particles)
  std::vector<double> particle_data;                // particle_values per particle
  std::vector<std::int64_t> particle_face;          // contact history: last face per particle
  std::vector<std::int64_t> point_gid;              // thick-shell elements, ascending
  std::vector<double> point_data;                   // point_values per thick-shell element
  std::vector<std::int64_t> point_count;            // points through each one's thickness
  std::int64_t model_nodes = 0, model_elements = 0; // sizes of the model, for validation
  std::int64_t model_particles = 0;
  std::uint64_t mesh_fingerprint = 0;     // mesh_fingerprint() of the model's initial mesh
  std::uint64_t particle_fingerprint = 0; // Simulation::particle_fingerprint()
};

// Gathers the state of `sim` on rank 0 (collective); other ranks get an empty checkpoint.
Checkpoint capture(const Simulation& sim, const OutputState& outputs);

// Writes `c` to `path` atomically (rank 0's job).
void write_checkpoint(const std::string& path, const Checkpoint& c);

// Reads a checkpoint of this format; InputError (with the file name) when it is missing,
// of an older format, truncated, damaged (checksum) or inconsistent. Every rank reads the
// same bytes, so every rank throws the same error.
Checkpoint read_checkpoint(const std::string& path);

} // namespace anvil
