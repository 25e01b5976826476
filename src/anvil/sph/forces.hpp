// The particle phase's physics (cycle step 2) for the particles of one rank, knowing
// nothing of MPI: SPH for solids with strength after Libersky and Petschek (1991) and
// Swegle, Attaway and Heinstein (PRONTO's SPH, 1994), in two passes over precomputed
// neighbour lists (neighbours.hpp):
//
//  1. kinematics: velocity gradient L_i = (1/rho_i) sum_j m_j (v_j - v_i) (x) grad_i W_ij
//     (optionally normalised, Randles and Libersky 1996), continuity
//     d rho_i / dt = -rho_i tr L_i, stress rotated by Hughes-Winget with the spin and
//     advanced by the material's batch update with D, internal energy from the stress
//     power; then S_i = sigma_i / rho_i^2 and Monaghan's artificial stress R_i (Gray,
//     Monaghan and Swift 2001) for the neighbours.
//  2. forces: the symmetric conservative momentum equation
//     m_i dv_i/dt = m_i sum_j m_j (S_i + S_j + f_ij^n (R_i + R_j) - Pi_ij I) grad_i W_ij
//     with Monaghan and Gingold's (1983) artificial viscosity Pi_ij and
//     f_ij = W(r_ij) / W(dp); the work of Pi and R as an energy rate; the particle
//     stable time step.
//
// W is evaluated at the mean smoothing length h_ij = (h_i + h_j)/2, so grad_i W_ij =
// -grad_j W_ji and the pair forces cancel exactly (momentum is conserved to round-off).
// Every sum over neighbours runs in the list's order (see neighbours.hpp).
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

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
  double alpha = 1, beta = 2;         // Monaghan-Gingold viscosity coefficients
  double epsilon = 0;                 // artificial stress coefficient (0: off)
  double exponent = 4;                // its exponent n
  double w_spacing = 1;               // kernel shape w(q) at q = 1 / smoothing_ratio
  bool corrected = false;             // normalised velocity gradient
};

// Courant number of the particle step: dt_i = courant h_i / (c_i + 1.2 (alpha c_i +
// beta max_j |mu_ij|)) (Monaghan 1992).
inline constexpr double courant = 0.3;

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
  // all: written by pass 1 for own particles, read by pass 2 for all
  double* wave_speed = nullptr;
  double* S[6] = {}; // sigma / rho^2
  double* R[6] = {}; // artificial stress
  // own, out of pass 2
  double* force[3] = {};         // N
  double* energy_rate = nullptr; // J/(kg s) from viscosity and artificial stress
};

struct SphResult {
  double dt_stable = 1e300;        // smallest particle stable step, s
  std::int64_t stable_gid = -1;    // particle that controls it
  std::int64_t nonfinite_gid = -1; // smallest gid with a non-finite force or state, or -1
};

// Scratch kept between cycles (the cycle allocates nothing in steady state).
struct SphWorkspace {
  std::vector<double> pair;        // per neighbour entry: grad W (3), f^n
  std::vector<double> d[6];        // rate of deformation of own particles
  std::vector<double> power_old;   // rotated old stress : D
  std::vector<double> energy_pred; // e predicted at the new state (equations of state)
};

// Pass 1 over own particles, over the interval dt (the previous step). Also fills the
// pair data (kernel gradients) that pass 2 reuses.
void sph_kinematics(const SphView& v, std::span<const SetParams> sets, KernelType kernel,
                    const NeighbourList& nl, double dt, SphWorkspace& work);

// Pass 2 over own particles: forces at t(n), energy rates, stable step.
void sph_forces(const SphView& v, std::span<const SetParams> sets, const NeighbourList& nl,
                SphWorkspace& work, SphResult& result);

// Smoothing length at density rho: h0 (rho0 / rho)^(1/3) (constant mass in the support).
inline double smoothing_length(const SetParams& s, double rho) {
  return s.h0 * std::cbrt(s.rho0 / rho);
}

// Principal values and axes of a symmetric tensor (xx yy zz xy yz xz) by cyclic Jacobi
// with a fixed number of sweeps (the same operations for every particle): s = Q diag Q^T,
// columns of Q the axes.
void principal(const double s[6], double lambda[3], double Q[3][3]);

} // namespace anvil::sph
