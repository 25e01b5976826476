// SPH particle storage on one rank of the SPH decomposition: structure of arrays, the
// rank's own particles at [0, n) in ascending global id. During the particle phase the
// arrays that neighbours read (gid, set, x, v, mass, rho, h, wave_speed) are extended by
// ghost copies
// at [n, n + ghosts); they shrink back afterwards (capacity kept: no allocation).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace anvil::sph {

struct Particles {
  // Read by neighbours (extended by ghosts during the phase).
  std::vector<std::int64_t> gid;        // global particle id (deck order, lattice order)
  std::vector<int> set;                 // particle set index (deck order)
  std::array<std::vector<double>, 3> x; // position at t(n), m
  std::array<std::vector<double>, 3> v; // velocity at t(n - 1/2) (t(n + 1/2) after predict)
  std::vector<double> mass;             // kg
  std::vector<double> rho;              // density, kg/m^3
  std::vector<double> h;                // smoothing length, m

  // The rank's own particles only.
  std::array<std::vector<double>, 3> x0;     // reference position
  std::array<std::vector<double>, 3> f;      // SPH force at t(n), N
  std::array<std::vector<double>, 6> stress; // Cauchy stress, Pa (xx yy zz xy yz xz)
  std::vector<double> energy;                // specific internal energy, J/kg
  std::vector<double> plastic_strain;        // equivalent plastic strain (0 without plasticity)
  std::vector<double> temperature;           // K (0 without a thermal model)
  std::vector<double> wave_speed;            // m/s, from the last material update
  std::vector<std::uint8_t> constrained;     // bit i: velocity component i is prescribed
  std::array<std::vector<double>, 3> v_bc;   // the prescribed value, m/s
  // The boundary condition (deck index) that constrains the component (its time history
  // scales v_bc; its reaction sums the component's), or -1 (none, or the plane of a 2-D
  // model).
  std::array<std::vector<int>, 3> bc_source;
  // Bit b: condition b (deck index, below 64) holds the component, active or not.
  std::array<std::vector<std::uint64_t>, 3> bc_holders;
  std::vector<std::int64_t> last_face; // contact face touched last cycle, or -1

  std::size_t size() const { return mass.size(); }

  // Visits every per-particle array (for migration and reordering): fn(vector<T>&).
  template <class F>
  void for_each_field(F&& fn) {
    fn(gid);
    fn(set);
    for (auto& a : x) fn(a);
    for (auto& a : v) fn(a);
    fn(mass);
    fn(rho);
    fn(h);
    for (auto& a : x0) fn(a);
    for (auto& a : f) fn(a);
    for (auto& a : stress) fn(a);
    fn(energy);
    fn(plastic_strain);
    fn(temperature);
    fn(wave_speed);
    fn(constrained);
    for (auto& a : v_bc) fn(a);
    for (auto& a : bc_source) fn(a);
    for (auto& a : bc_holders) fn(a);
    fn(last_face);
  }
};

} // namespace anvil::sph
