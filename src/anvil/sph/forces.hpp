// The particle phase's physics (cycle step 2) for the particles of one rank, knowing
// nothing of MPI: SPH for solids with strength after Libersky and Petschek (1991) and
// Swegle, Attaway and Heinstein (PRONTO's SPH, 1994), in two passes over precomputed
// neighbour lists (neighbours.hpp):
//
//  1. kinematics: velocity gradient L_i = sum_j V_j (v_j - v_i) (x) grad_i W_ij with the
//     volumes V_j = m_j / rho_j (optionally normalised, Randles and Libersky 1996),
//     continuity d rho_i / dt = -rho_i tr L_i (or, per set, the summation
//     rho_i = sum_j m_j W_ij over the neighbours and i itself), stress rotated by Hughes-Winget
//     with the spin and advanced by the material's batch update with D, internal energy from the
//     stress power sigma : D / rho; then Monaghan's artificial stress R_i (Gray,
//     Monaghan and Swift 2001) for the neighbours.
//  2. forces: the symmetric conservative momentum equation that matches that gradient
//     (so that the stress power and the forces' work cancel exactly, pair by pair)
//     dv_i/dt = sum_j m_j ((P_i + P_j + f_ij^n (R_i + R_j)) / (rho_i rho_j)
//                          - Pi_ij I) grad_i W_ij
//     with P = sigma, or P = sigma B^-T where the gradient is normalised (Bonet and Lok
//     1999: the same normalisation in both equations keeps the pair forces equal and
//     opposite and the energy exact, and lets a free surface carry its stress gradient)
//     with Monaghan and Gingold's (1983) artificial viscosity Pi_ij and
//     f_ij = W(r_ij) / W(dp); the work of Pi and R as an energy rate; the particle
//     stable time step. The (sigma_i + sigma_j)/(rho_i rho_j) form with volume-weighted
//     gradients stays consistent across density jumps (Sod's tube, different materials),
//     where the sigma/rho^2 form with (1/rho_i) sum m_j weights does not.
//
// W is evaluated at the mean smoothing length h_ij = (h_i + h_j)/2, so grad_i W_ij =
// -grad_j W_ji and the pair forces cancel exactly (momentum is conserved to round-off).
// Each pair is evaluated once, in the half-list row of its particle of lower global id
// (neighbours.hpp), for both particles: the row's particle takes its terms at once,
// the partner's terms are added to the partner's running sum of lower neighbours. The
// rows run in ascending global id, so a particle's lower sum receives its terms in
// ascending global id and is complete when its own row comes; its row's terms are summed
// simd::width entries at a time, lane l summing the entries l, l + width, ... in list
// order, the lanes added in lane order, then added to the lower sum. Every sum is thus a
// function of the neighbour lists alone, and each pair's terms are the same operations on
// the same inputs on any rank (a ghost's row holds the pairs with own particles).
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "anvil/core/huge_pages.hpp"
#include "anvil/material/material.hpp"
#include "anvil/sph/kernel.hpp"
#include "anvil/sph/neighbours.hpp"

namespace anvil::sph {

// The formulation's parameters of one particle set. Pair terms use the mean of the two
// particles' sets (symmetric, so momentum stays conserved between sets).
struct SetParams {
  const Material* material = nullptr; // not owned
  double rho0 = 0;                    // reference density, kg/m^3
  double h0 = 0;                      // smoothing length at rho0, m
  double h_min = 0, h_max = 0;        // bounds of h, m (h_min <= h0 <= h_max)
  double alpha = 1, beta = 2;         // Monaghan-Gingold viscosity coefficients
  double epsilon = 0;                 // artificial stress coefficient (0: off)
  double exponent = 4;                // its exponent n
  double w_spacing = 1;               // kernel shape w(q) at q = 1 / smoothing_ratio
  bool corrected = false;             // normalised velocity gradient
  bool summation = false;             // density by summation, sum_j m_j W_ij (with j = i)
  int dimensions = 3;                 // of the particle model (1, 2 or 3)
};

// Courant number of the particle step: dt_i = courant h_i / (c_i + 1.2 (alpha c_i +
// beta max_j |mu_ij|)) (Monaghan 1992).
inline constexpr double courant = 0.3;

// Largest move of a particle in one step, as a fraction of its h: dt_i <= move h_i / |v_i|
// (v(n - 1/2)). The Courant condition bounds the step by the sound speed and the
// approach of neighbours only: bodies approaching from outside each other's support, or
// a cold gas (c = 0), would otherwise jump through the kernel support in one step (or
// take an unbounded step). The same 0.3 as the Courant number: a particle moves no
// further in a step than a sound wave may, as LS-DYNA's SPH step h / (c + |v|) and
// LAMMPS's `fix dt/reset` (a largest displacement Xmax per step) bound it.
inline constexpr double max_move = 0.3;

// Arrays over the particles of one rank: own particles [0, n_local), ghost copies after
// them up to n_all. `in` arrays hold n_all values, `own` arrays n_local, `all` arrays
// n_all whose ghost part the caller fills between the two passes.
struct SphView {
  std::size_t n_local = 0, n_all = 0;
  // in
  const std::int64_t* gid = nullptr;
  const int* set = nullptr;
  const double* x[3] = {};
  const double* v[3] = {}; // v(n - 1/2)
  const double* mass = nullptr;
  const double* h = nullptr;
  // all: density (own part advanced by pass 1; ghost part old until the exchange)
  double* rho = nullptr;
  // own: state advanced by pass 1
  double* stress[6] = {};
  double* energy = nullptr; // specific internal energy, J/kg
  double* plastic_strain = nullptr;
  double* temperature = nullptr;
  // own: written by pass 1 (and into pass 2's records, NeighbourRead2)
  double* wave_speed = nullptr;
  // The stress the momentum equation pairs, P = sigma B^-T (xx yy zz xy yz xz yx zy zx,
  // row index first), Pa: sigma itself (the last three repeat the shear) unless the set
  // normalises its gradient. Pass 1 writes its first six components into pass 2's
  // records (SphWorkspace::read2) and the last three here; all: the ghost part from the
  // exchange.
  double* S678[3] = {};
  double* R[6] = {}; // artificial stress, Pa
  // (S678 and R are written only where some set normalises its gradient or has an
  // artificial stress: pass 2 reads them only then.)
  // own, out of pass 2
  double* force[3] = {};         // N
  double* energy_rate = nullptr; // J/(kg s) from viscosity and artificial stress
};

struct SphResult {
  double dt_stable = 1e300;        // smallest particle stable step, s
  std::int64_t stable_gid = -1;    // particle that controls it
  std::int64_t nonfinite_gid = -1; // smallest gid with a non-finite force or state, or -1
};

// What one pass reads of a neighbour, packed per particle in groups of four doubles
// (simd::gather4 loads a group of `width` neighbours and transposes it: vector loads
// instead of lane-by-lane gathers), for own and ghost particles. Pass 1's record, built
// at its start:
struct alignas(64) NeighbourRead1 {
  double x[3], h;
  double v[3], volume; // m / rho
};
// Pass 2's record, by offsets (groups of four), in two arrays so that the loop's common
// path reads only the first, 128 bytes per neighbour (the whole record was 256 bytes: at
// 32^3 particles the records of the +2 lattice planes a sweep of rows reads no longer fit
// in a 1 MB L2 cache). NeighbourRead2: x, h; v, c; S0-S3; S4, S5, rho, m: every value a
// pair needs without a normalised gradient or an artificial stress (a neighbour's 1/rho
// is divided in the loop, the row particle's once per row). Filled where its values are
// made instead of copied from the arrays at the start of pass 2: x, h and v at pass 1's
// start (a copy of NeighbourRead1's two groups, whose volume c replaces), the new
// stress, rho, m and c after pass 1's material update for own particles, and by the
// ghost exchange for the ghosts (SphPhase). (One record for both passes, pass 1
// reading the first 64 bytes of 128, was 4% slower at 32^3: pass 1 and the filter read
// twice the memory.)
// NeighbourRead2Rest (96 bytes, whole 32-byte groups): a normalised gradient reads the
// first group (S6-S8), the artificial stress the first (has_r), second and third, sets of
// different viscosity the third (alpha, beta); packed by pass 2 only where one of them is
// there.
// The row particle takes its own alpha, beta from its set.
struct alignas(64) NeighbourRead2 {
  static constexpr int x = 0, h = 3, v = 4, c = 7, S = 8, S45 = 12, rho = 14, mass = 15;
  double a[16];
};
struct alignas(32) NeighbourRead2Rest {
  static constexpr int S6 = 0, has_r = 3, R = 4, R45 = 8, alpha = 10, beta = 11;
  double a[12];
};

// A particle's running sums over its lower neighbours (their rows' terms for it), in
// groups of four doubles (simd::scatter_add4). Pass 1: the velocity gradient's
// sum_j V_j (v_j - v_i) (x) grad_i W_ij (row-major), sum_j m_j W_ij, and
// sum_j V_j (x_i - x_j) (x) grad_i W_ij (the normalisation's B, negated).
struct alignas(32) LowerSums1 {
  static constexpr int L = 0, mw = 9, B = 10;
  double a[20];
};
// Pass 2: sum_j m_j T_ij grad_j W_ji (the force's sum with its sign reversed), the
// energy rate sum_j m_j (Pi_ij v_ij . grad_i W_ij / 2 - f v_ij . R_i grad_i W_ij / (rho_i rho_j))
// and the largest approach max_j -mu_ij (0 if none).
struct alignas(64) LowerSums2 {
  double f[3], e, mu, pad[3];
};

// Scratch kept between cycles (the cycle allocates nothing in steady state).
struct SphWorkspace {
  // The arrays the pair loops read at scattered places on huge pages (fewer TLB misses:
  // about 3-4% less time at 32^3, docs/sph.md).
  HugePageVector<NeighbourRead1> read1;
  HugePageVector<NeighbourRead2> read2;
  HugePageVector<NeighbourRead2Rest> read2r;
  NeighbourList nl;                // this step's neighbours (filtered candidates, half lists)
  HugePageVector<double> dwr, wk;  // per entry of nl: (1/r) dW/dr and W (artificial
                                   // stress, summation density)
  HugePageVector<LowerSums1> low1; // per particle (own and ghost), pass 1
  std::vector<double> g_row;       // pass 1: a row's kernel gradients, 3 vectors per entry
  HugePageVector<LowerSums2> low2; // and pass 2
  // low1, low2 hold zeros: each row zeroes its particle's lower sums after the last term
  // for them, so a pass with a row for every particle leaves them zero for the next step.
  bool low1_zero = false, low2_zero = false;
  std::vector<double> lgrad[9];    // velocity gradient of own particles (row-major)
  std::vector<double> summed;      // 1 where an own particle's set sums its density
  std::vector<double> d[6];        // rate of deformation of own particles
  std::vector<double> binv;        // B^-1 of own particles, 9 per particle (row-major)
  std::vector<double> power_old;   // rotated old stress : D
  std::vector<double> energy_pred; // e predicted at the new state (equations of state)
};

// Pass 1 for own particles, over the interval dt (the previous step): selects this
// step's neighbours among the candidate half lists (work.nl: the candidates within the
// kernel's support at the current positions and h; rows of own and ghost particles,
// find_candidates) and keeps each entry's kernel derivative for pass 2. The candidates
// must hold every pair within the support that concerns an own particle.
void sph_kinematics(const SphView& v, std::span<const SetParams> sets, KernelType kernel,
                    const NeighbourList& candidates, double dt, SphWorkspace& work);

// Pass 2 for own particles, over work.nl: forces at t(n), energy rates, stable step.
void sph_forces(const SphView& v, std::span<const SetParams> sets, KernelType kernel,
                SphWorkspace& work, SphResult& result);

// Smoothing lengths at the densities: h[i] = h0 (rho0 / rho[i])^(1/d) (constant mass in
// the support) of set[i]'s h0 and rho0, clamped to the set's [h_min, h_max], for i < n,
// simd::width particles at a time (the cube root by simd::cube_root: the same operations
// and bits for every particle). Every set has the same dimensions d.
void smoothing_lengths(std::span<const SetParams> sets, const int* set, const double* rho,
                       std::size_t n, double* h);

// Principal values and axes of a symmetric tensor (xx yy zz xy yz xz) by cyclic Jacobi
// with a fixed number of sweeps (the same operations for every particle): s = Q diag Q^T,
// columns of Q the axes.
void principal(const double s[6], double lambda[3], double Q[3][3]);

} // namespace anvil::sph
