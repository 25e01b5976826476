#include "anvil/solver/can_crush.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "anvil/io/deck.hpp"

namespace anvil {

std::string can_crush_deck(const CanCrushOptions& o) {
  // Base model (examples/can_crush.yaml): can 36 x 50 x 1 = 1800, block 8 x 8 x 1 = 64.
  const double s = std::sqrt(static_cast<double>(o.elements_per_rank) / 1875.0);
  int can[3] = {std::max(3, static_cast<int>(std::lround(36 * s))),
                std::max(1, static_cast<int>(std::lround(50 * s))), 1};
  int block[3] = {std::max(1, static_cast<int>(std::lround(8 * s))),
                  std::max(1, static_cast<int>(std::lround(8 * s))), 1};
  // P = 2^k m, m odd: k doublings cycling through the directions, then m times around.
  int p = std::max(1, o.ranks), step = 0;
  while (p % 2 == 0) {
    can[step % 3] *= 2;
    block[step % 3] *= 2;
    p /= 2;
    ++step;
  }
  can[0] *= p;
  block[0] *= p;
  std::string termination = fmt::format("{{time: {:.17g}", o.end_time);
  if (o.cycles >= 0) termination += fmt::format(", cycles: {}", o.cycles);
  termination += "}";
  const char* wall = o.wall == CanCrushOptions::Wall::thick_shell
                         ? "thick_shell: {points: 3}"
                         : "hourglass: {model: viscous, coefficient: 0.1}";
  const char* decomposition = o.decomposition == CanCrushOptions::Decomposition::sectors
                                  ? "decomposition: {fe: rcb, scale: [1, 1, 0.25]}\n"
                                  : "";
  return fmt::format(R"(title: Scaled can crush, {} rank{}
termination: {}
time_step: {{scale: 0.9}}
materials:
  mild_steel: {{model: j2_plasticity, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3,
               yield_stress: 250.0e6, hardening_modulus: 1.0e9}}
  block_steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  can:
    mesh: {{generate: can, radius: 0.03, height: 0.1, thickness: 0.001, divisions: [{}, {}, {}]}}
    material: mild_steel
    {}
  block:
    mesh: {{generate: box, min: [-0.04, -0.04, 0.1005], max: [0.04, 0.04, 0.1105], divisions: [{}, {}, {}]}}
    material: block_steel
boundary_conditions:
  - {{set: can.bottom, fix: all}}
  - {{set: {{part: block}}, velocity: [0, 0, -10.0]}}
contact:
  - {{type: general, parts: all, penalty_scale: 0.1, friction: 0.0}}
probes:
  - {{name: block, at: [0, 0, 0.1005]}}
output: {{fields_every: 1.6e-3, history_every: 1.0e-5}}
{})",
                     o.ranks, o.ranks == 1 ? "" : "s", termination, can[0], can[1], can[2], wall,
                     block[0], block[1], block[2], decomposition);
}

Config can_crush_config(const CanCrushOptions& o) {
  return parse_deck(can_crush_deck(o), fmt::format("can-crush (P={})", o.ranks));
}

} // namespace anvil
