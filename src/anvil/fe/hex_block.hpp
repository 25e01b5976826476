// A block of hexahedra on one rank (one part: one material, one hourglass control) and
// the element kernel that turns nodal positions and velocities into corner forces:
// stress update at the mid-step (Jaumann rate through the Hughes-Winget rotation),
// constitutive update through the material's batch interface, internal forces from the
// uniform-strain gradient, Flanagan-Belytschko hourglass forces, artificial bulk
// viscosity and the element stable time step. The kernel knows nothing of MPI.
#pragma once

#include <array>
#include <cstdint>
#include <new>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "anvil/material/material.hpp"

namespace anvil {

struct HourglassControl {
  enum class Model { viscous, stiffness, assumed_strain };
  Model model = Model::viscous;
  // Viscous: Q = coefficient/4 rho c V^(2/3) q (LS-DYNA's scaling of its type 1-3).
  // Stiffness: dQ/dt = coefficient (lambda + 2 mu) (B:B) / (3 V) q (Flanagan-Belytschko).
  // Assumed strain: dQ/dt = coefficient K q in the element's co-rotational frame, K the
  // physical stiffness of the hourglass modes under the assumed-strain field of
  // Belytschko and Bindeman (1993) (hex8::assumed_strain_rate, docs/element.md).
  double coefficient = 0.1; // the deck's default is 1 for assumed_strain
};

// Artificial bulk viscosity q = rho l (quadratic l |tr D| - linear c) tr D when the
// element compresses (tr D < -1e-12 c / l: not by round-off), l = V^(1/3) (von
// Neumann-Richtmyer plus Landshoff, with LS-DYNA's default coefficients).
struct BulkViscosity {
  double quadratic = 1.5;
  double linear = 0.06;
};

// Element erosion (optional, per part): an element whose plastic strain reaches a limit,
// or whose volume turns non-positive, is deleted: it stops producing force, its faces
// leave the contact surfaces, its mass stays on its nodes.
struct Erosion {
  double plastic_strain = 0; // 0: off
  bool inverted = false;     // erode instead of stopping the run
  bool enabled() const { return plastic_strain > 0 || inverted; }
};

// Thick shell (optional, per part; docs/element.md, "Thick shell"): the element's
// bending through its thinnest direction (made its zeta axis when the mesh is built,
// orient_thick_shells) is integrated at `points` Gauss points through the thickness, each
// with its own stress and material state, instead of carried by hourglass forces; the
// other hourglass modes take the assumed-strain stiffness.
struct ThickShell {
  static constexpr int max_points = 5;
  int points = 0; // 0: off; else 2..max_points
  bool enabled() const { return points > 0; }
};

// Relative cost of one element in the FE phase, for balancing the static decomposition:
// the kernel's time per element and cycle on the benchmark blocks of docs/performance.md
// (J2, 47^3, ns): viscous 127, stiffness 138, assumed strain 148; the thick shell adds
// about 22 per point through the thickness to the assumed-strain form (212 with 3).
int element_cost(const HourglassControl& hourglass, const ThickShell& thick_shell);

struct HexBlock {
  std::string name;                   // part name
  int part = 0;                       // part index in the deck
  const Material* material = nullptr; // not owned
  HourglassControl hourglass;
  BulkViscosity bulk_viscosity;
  Erosion erosion;
  ThickShell thick_shell;
  bool rigid = false; // a rigid body's elements: no stress, no forces, no step (skipped)

  std::vector<std::int64_t> gid;        // global element ids, ascending
  std::array<std::vector<int>, 8> conn; // local node index of each corner
  std::vector<double> mass;             // kg
  // Mass scaling (docs/deck.md, time_step.mass_scaling): empty, or per element the
  // factor f that the nodes' share of the element's mass and its inertia in the kernel
  // (bulk viscosity, hourglass damping, stable step) take, as from a density f times its
  // material's, and 1 / sqrt f, which scales its material's wave speed there. `mass` and
  // the density the material sees stay physical.
  std::vector<double> mass_scale, wave_scale;
  // Wedges, pyramids and tetrahedra (corners that share a node; mesh.hpp): their nodes
  // take equal shares of the element's mass (corner_share), 1 / n each of n nodes, where
  // the kernel's step bounds assume an eighth per corner; a node of k corners gets
  // 8 / (n k) times that, and the element's step is taken times the least of these,
  // step_factor = 8 / (n k_max) (2/3 for a wedge, 0.4 for a pyramid; a tetrahedron has a
  // bound of its own, below), which keeps it stable. Empty where every element is a
  // hexahedron.
  std::vector<double> step_factor;
  // 1 for a tetrahedron (a b c c d d d d), which has no hourglass modes: its step is the
  // plain one of its own four nodes (hex_block.cpp). Empty where there is none.
  std::vector<double> tetrahedron;
  std::vector<double> volume;                          // current volume, m^3
  std::vector<double> alive;                           // 1, or 0 once eroded
  std::int64_t eroded = 0;                             // elements with alive 0
  std::array<std::vector<double>, 6> stress;           // Cauchy stress, Pa
  std::vector<double> plastic_strain;                  // empty unless the material has it
  std::vector<double> temperature;                     // empty unless the material has it
  std::array<std::vector<double>, 12> hourglass_force; // Q_i,alpha (3 alpha + i), stiffness
                                                       // forms only: global components for
                                                       // `stiffness`, co-rotational ones for
                                                       // `assumed_strain`
  // Thick shell: the state at each point through the thickness (point p at zeta =
  // hex8::thick_shell_point); stress, plastic_strain and temperature above then hold
  // their thickness averages (Gauss weights).
  std::vector<std::array<std::vector<double>, 6>> point_stress;
  std::vector<std::vector<double>> point_plastic_strain; // empty unless the material has it
  std::vector<std::vector<double>> point_temperature;    // empty unless the material has it
  std::vector<double> internal_energy;                   // J, stress work plus bulk viscosity work
  std::vector<double> hourglass_energy;                  // J
  std::size_t corner_base = 0;           // corner (e, a) of this block lives at slot
                                         // corner_base + 8 e + a (element-major)
  int node_begin = 0, node_end = 0;      // the local nodes the corners refer to
                                         // lie in [node_begin, node_end)
  std::vector<std::uint8_t> corner_rows; // per vector of elements: 1 where the
                                         // kernel stores the corner slots (init:
                                         // all; see HexWorkspace::begin_nodal_forces)

  int size() const { return static_cast<int>(gid.size()); }
  // The share of element e's mass that corner a gives its node: 1/8, or 1 / (n k) for a
  // node that k of its corners share among n distinct nodes.
  double corner_share(std::size_t e, int a) const {
    if (step_factor.empty() || step_factor[e] == 1.0) return 0.125;
    const auto [n, k] = corner_multiplicity(e, a);
    return 1.0 / (n * k);
  }
  // Of element e's corners: how many distinct nodes they name (n), and how many of them
  // name corner a's node (k).
  std::pair<int, int> corner_multiplicity(std::size_t e, int a) const {
    int n = 0, k = 0;
    for (int c = 0; c < 8; ++c) {
      k += conn[c][e] == conn[a][e];
      bool first = true;
      for (int d = 0; d < c; ++d) first = first && conn[d][e] != conn[c][e];
      n += first;
    }
    return {n, k};
  }
  // Element e's mass with mass scaling's (what its nodes carry), kg.
  double scaled_mass(std::size_t e) const {
    return mass_scale.empty() ? mass[e] : mass[e] * mass_scale[e];
  }

  // Sets the elements (ascending global ids and their corners as local node indices)
  // and the corner slot base, sizes and zeroes the state (padded to whole vectors), and
  // sets each element's mass from the material density and its volume at positions x.
  // Returns the index of the first element with a non-positive volume or centre Jacobian
  // (inverted or tangled), or -1.
  int init(std::span<const std::int64_t> ids, std::span<const std::array<int, 8>> corners,
           const double* const x[3], std::size_t base);
};

struct NodalView {
  const double* x[3]; // positions at t(n)
  const double* v[3]; // velocities at t(n - 1/2)
};

// Allocates on 64-byte boundaries (the corner arrays: the kernel streams whole rows of
// corner forces past the cache when they are aligned).
template <class T>
struct CacheAligned {
  using value_type = T;
  CacheAligned() = default;
  template <class U>
  CacheAligned(const CacheAligned<U>&) noexcept {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new (n * sizeof(T), std::align_val_t{64}));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete (p, std::align_val_t{64}); }
  template <class U>
  bool operator==(const CacheAligned<U>&) const noexcept {
    return true;
  }
};
using CornerArray = std::vector<double, CacheAligned<double>>;

struct CornerView {
  double* f[3]; // corner forces, indexed by slot (best in CornerArray: aligned)
};

// What one kernel call reports back.
struct HexResult {
  double dt_stable = 1e300;        // smallest element stable time step, s
  std::int64_t stable_gid = -1;    // element that controls it
  std::int64_t inverted_gid = -1;  // first element (by gid) with non-positive volume or
                                   // centre Jacobian, or -1
  std::int64_t nonfinite_gid = -1; // first element with a non-finite force or stress, or -1
  std::int64_t eroded = 0;         // elements eroded in this call
  // Optional out (set up, not the cycle): each element's stable step, written at
  // element_dt[e] for e in [0, padded size) of every block the call covers (eroded: 1e300).
  double* element_dt = nullptr;
};

class HexWorkspace;
namespace detail {
template <int Form>
void block_forces(HexBlock&, const NodalView&, double, CornerView, HexWorkspace&, HexResult&);
}

// Scratch space reused by every call (the cycle allocates nothing), and the optional
// nodal assembly in the kernel.
class HexWorkspace {
public:
  static constexpr int chunk = 64; // elements per material batch
  HexWorkspace();

  // Nodal assembly in the kernel: between begin_nodal_forces(nodes) and
  // end_nodal_forces(f), every hex_forces call also adds each element's corner forces to
  // its nodes (local indices below `nodes`), element after element and corner after
  // corner (a node's sum starts from +0.0). When the calls come in ascending global
  // element id, which the blocks of an FeDecomposition in their order do, a node's sum
  // has the bits of gather_corners' for every node whose corners are all local: the
  // same additions in the same order, made while the corners are in registers, not
  // written to the corner slots and read back. The corner slots are then only stored for
  // the vectors of elements whose HexBlock::corner_rows entry is set (those touching a
  // node that needs the exchange and gather_corners; all of them unless the caller
  // clears some). end_nodal_forces writes the sums to f[0..2][0..nodes) and ends the
  // assembly. The buffer grows on the first call only.
  void begin_nodal_forces(int nodes);
  void end_nodal_forces(double* const f[3]);

private:
  template <int Form>
  friend void detail::block_forces(HexBlock&, const NodalView&, double, CornerView, HexWorkspace&,
                                   HexResult&);
  std::vector<double, CacheAligned<double>> buf_;   // chunk and stage scratch
  std::vector<double, CacheAligned<double>> nodes_; // x and v, 8 per node (grows to the
                                                    // largest block's node range)
  std::vector<double, CacheAligned<double>> sums_;  // nodal force sums f0 f1 f2 (pad), 4 per
                                                    // node (zero between assemblies)
  int assembled_nodes_ = -1;                        // nodes being assembled, or -1: none
};

// Cycle step 1 for one block: updates stress and state from the velocities over the
// previous interval dt_prev (0 on the first cycle: no increment), writes the corner
// forces at the current positions, accumulates element energies and reports the stable
// time step. Positions are at t(n), velocities at t(n - 1/2).
void hex_forces(HexBlock& block, const NodalView& nodes, double dt_prev, CornerView corners,
                HexWorkspace& work, HexResult& result);

// Element volumes at the given positions (setup and output).
void hex_volumes(const HexBlock& block, const double* const x[3], std::span<double> out);

// Element e's corner positions relative to its first corner (geometry from differences:
// independent of where the model sits).
void element_corners(const HexBlock& block, const double* const x[3], std::size_t e,
                     double (&xe)[8][3]);

} // namespace anvil
