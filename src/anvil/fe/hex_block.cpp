#include "anvil/fe/hex_block.hpp"

#include <cmath>

#include "anvil/core/simd.hpp"
#include "anvil/fe/hex8.hpp"

namespace anvil {

using simd::vdouble;
using simd::width;
namespace stdx = simd::stdx;

namespace {

using simd::padded_size;

// Scratch layout inside HexWorkspace: one array of `chunk` values per entry.
enum Slot : int {
  s_d0,
  s_d1,
  s_d2,
  s_d3,
  s_d4,
  s_d5, // rate of deformation
  s_density,
  s_wave_speed,
  s_power_old, // old (rotated) stress : D
  s_volume_mid,
  s_q0,
  s_q1,
  s_q2,
  s_q3,
  s_q4,
  s_q5,
  s_q6,
  s_q7,
  s_q8, // Hughes-Winget rotation
  s_count
};

struct Gathered {
  vdouble x[8][3], v[8][3];
};

void gather(const HexBlock& b, const NodalView& n, int e, Gathered& g) {
  for (int a = 0; a < 8; ++a) {
    const int* idx = b.conn[a].data() + e;
    for (int i = 0; i < 3; ++i) {
      g.x[a][i] = simd::gather(n.x[i], idx);
      g.v[a][i] = simd::gather(n.v[i], idx);
    }
  }
}

} // namespace

int HexBlock::init(std::span<const std::int64_t> ids, std::span<const std::array<int, 8>> corners,
                   const double* const x[3], std::size_t base) {
  const int n = static_cast<int>(ids.size());
  const auto p = static_cast<std::size_t>(padded_size(n));
  gid.assign(ids.begin(), ids.end());
  corner_base = base;
  for (int a = 0; a < 8; ++a) {
    conn[a].resize(p);
    for (std::size_t e = 0; e < p; ++e) conn[a][e] = n > 0 ? corners[std::min<std::size_t>(e, n - 1)][a] : 0;
  }
  volume.assign(p, 0.0);
  hex_volumes(*this, x, volume);
  const double rho = material->elastic().density;
  mass.assign(p, 0.0);
  int bad = -1;
  for (std::size_t e = 0; e < p; ++e) {
    if (static_cast<int>(e) < n && !(volume[e] > 0) && bad < 0) bad = static_cast<int>(e);
    mass[e] = rho * volume[e];
  }
  for (auto& s : stress) s.assign(p, 0.0);
  plastic_strain.clear();
  temperature.clear();
  if (material->has_plastic_strain()) plastic_strain.assign(p, 0.0);
  if (material->has_temperature()) temperature.assign(p, material->initial_temperature());
  for (auto& h : hourglass_force) h.clear();
  if (hourglass.model == HourglassControl::Model::stiffness)
    for (auto& h : hourglass_force) h.assign(p, 0.0);
  internal_energy.assign(p, 0.0);
  hourglass_energy.assign(p, 0.0);
  return bad;
}

HexWorkspace::HexWorkspace() : buf_(static_cast<std::size_t>(s_count) * chunk, 0.0) {}

void hex_forces(HexBlock& b, const NodalView& nodes, double dt, CornerView corners,
                HexWorkspace& work, HexResult& result) {
  const int n = b.size();
  const int stride = padded_size(n); // corner slot stride of this block
  constexpr int C = HexWorkspace::chunk;
  auto scratch = [&](int slot) { return work.buf_.data() + static_cast<std::size_t>(slot) * C; };
  const double M = b.material->elastic().plane_wave_modulus();
  const bool stiff = b.hourglass.model == HourglassControl::Model::stiffness;
  const double hg = b.hourglass.coefficient;
  const double c1 = b.bulk_viscosity.linear, c2 = b.bulk_viscosity.quadratic;
  const bool has_ep = !b.plastic_strain.empty(), has_T = !b.temperature.empty();
  Gathered g;

  for (int e0 = 0; e0 < n; e0 += C) {
    const int nc = padded_size(std::min(C, n - e0)); // lanes in this chunk, whole vectors

    // Stage A: kinematics at the mid-step configuration x(n-1/2) = x(n) - dt/2 v(n-1/2);
    // rotate the old stress into the new frame.
    for (int l = 0; l < nc; l += width) {
      const int e = e0 + l;
      gather(b, nodes, e, g);
      vdouble xm[8][3], B[8][3];
      for (int a = 0; a < 8; ++a)
        for (int i = 0; i < 3; ++i) xm[a][i] = g.x[a][i] - (0.5 * dt) * g.v[a][i];
      hex8::gradient(xm, B);
      const vdouble vol = hex8::volume(xm, B);
      const vdouble inv = 1.0 / vol;
      vdouble d[6], w[3], Q[3][3], s[6];
      hex8::velocity_gradient(g.v, B, inv, d, w);
      hex8::hughes_winget(w, dt, Q);
      for (int k = 0; k < 6; ++k) s[k] = simd::load(&b.stress[k][e]);
      hex8::rotate_symmetric(Q, s);
      const vdouble power =
          s[0] * d[0] + s[1] * d[1] + s[2] * d[2] + 2.0 * (s[3] * d[3] + s[4] * d[4] + s[5] * d[5]);
      for (int k = 0; k < 6; ++k) {
        simd::store(s[k], &b.stress[k][e]);
        simd::store(d[k], scratch(s_d0 + k) + l);
      }
      simd::store(simd::load(&b.mass[e]) * inv, scratch(s_density) + l);
      simd::store(power, scratch(s_power_old) + l);
      simd::store(vol, scratch(s_volume_mid) + l);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) simd::store(Q[i][j], scratch(s_q0 + 3 * i + j) + l);
    }

    // Stage B: constitutive update of the whole chunk through the batch interface.
    MaterialBatch batch;
    batch.n = nc;
    batch.dt = dt;
    for (int k = 0; k < 6; ++k) {
      batch.d[k] = scratch(s_d0 + k);
      batch.stress[k] = b.stress[k].data() + e0;
    }
    batch.density = scratch(s_density);
    batch.plastic_strain = has_ep ? b.plastic_strain.data() + e0 : nullptr;
    batch.temperature = has_T ? b.temperature.data() + e0 : nullptr;
    batch.wave_speed = scratch(s_wave_speed);
    b.material->update(batch);

    // Stage C: forces at x(n): stress divergence, bulk viscosity, hourglass; energies and
    // the stable time step.
    for (int l = 0; l < nc; l += width) {
      const int e = e0 + l;
      gather(b, nodes, e, g);
      vdouble B[8][3];
      hex8::gradient(g.x, B);
      const vdouble vol = hex8::volume(g.x, B);
      const vdouble inv = 1.0 / vol;
      const vdouble mass = simd::load(&b.mass[e]);
      const vdouble rho = mass * inv;
      const vdouble c = simd::load(scratch(s_wave_speed) + l);
      vdouble d[6], s[6];
      for (int k = 0; k < 6; ++k) {
        d[k] = simd::load(scratch(s_d0 + k) + l);
        s[k] = simd::load(&b.stress[k][e]);
      }
      const vdouble trd = d[0] + d[1] + d[2];
      const vdouble len = stdx::cbrt(stdx::abs(vol));
      const auto compressing = trd < 0.0;
      vdouble q = 0.0, qv = 0.0; // bulk viscosity pressure and its rate term for dt
      stdx::where(compressing, q) = rho * len * (c2 * len * trd * trd - c1 * c * trd);
      stdx::where(compressing, qv) = c1 * c - c2 * len * trd;

      // f_ia = -sigma_ij B_ja, with the bulk viscosity pressure on the diagonal.
      vdouble f[8][3];
      const vdouble sxx = s[0] - q, syy = s[1] - q, szz = s[2] - q;
      for (int a = 0; a < 8; ++a) {
        f[a][0] = -(sxx * B[a][0] + s[3] * B[a][1] + s[5] * B[a][2]);
        f[a][1] = -(s[3] * B[a][0] + syy * B[a][1] + s[4] * B[a][2]);
        f[a][2] = -(s[5] * B[a][0] + s[4] * B[a][1] + szz * B[a][2]);
      }

      // Hourglass: modes q_i,alpha = sum_a v_ia gamma_alpha,a; resisting forces
      // -Q_i,alpha gamma_alpha,a.
      vdouble gam[4][8];
      hex8::hourglass_shape(g.x, B, inv, gam);
      const vdouble bb = hex8::gradient_norm2(B);
      vdouble hg_power = 0.0;
      for (int al = 0; al < 4; ++al) {
        vdouble qa[3], Qa[3];
        for (int i = 0; i < 3; ++i) {
          qa[i] = g.v[0][i] * gam[al][0];
          for (int a = 1; a < 8; ++a) qa[i] += g.v[a][i] * gam[al][a];
        }
        if (stiff) {
          vdouble old[3], rot[3];
          for (int i = 0; i < 3; ++i) old[i] = simd::load(&b.hourglass_force[3 * al + i][e]);
          for (int i = 0; i < 3; ++i) {
            rot[i] = simd::load(scratch(s_q0 + 3 * i) + l) * old[0] +
                     simd::load(scratch(s_q0 + 3 * i + 1) + l) * old[1] +
                     simd::load(scratch(s_q0 + 3 * i + 2) + l) * old[2];
          }
          const vdouble k = (hg * M / 3.0) * bb * inv;
          for (int i = 0; i < 3; ++i) {
            Qa[i] = rot[i] + dt * k * qa[i];
            simd::store(Qa[i], &b.hourglass_force[3 * al + i][e]);
            hg_power += 0.5 * (rot[i] + Qa[i]) * qa[i];
          }
        } else {
          const vdouble k = (0.25 * hg) * rho * c * len * len;
          for (int i = 0; i < 3; ++i) {
            Qa[i] = k * qa[i];
            hg_power += Qa[i] * qa[i];
          }
        }
        for (int a = 0; a < 8; ++a)
          for (int i = 0; i < 3; ++i) f[a][i] -= Qa[i] * gam[al][a];
      }

      // Energies over the step just taken (dt = 0 on the first cycle).
      const vdouble power_new =
          s[0] * d[0] + s[1] * d[1] + s[2] * d[2] + 2.0 * (s[3] * d[3] + s[4] * d[4] + s[5] * d[5]);
      const vdouble vmid = simd::load(scratch(s_volume_mid) + l);
      const vdouble dE =
          dt * vmid * (0.5 * (simd::load(scratch(s_power_old) + l) + power_new) - q * trd);
      simd::store(simd::load(&b.internal_energy[e]) + dE, &b.internal_energy[e]);
      simd::store(simd::load(&b.hourglass_energy[e]) + dt * hg_power, &b.hourglass_energy[e]);
      simd::store(vol, &b.volume[e]);

      // Stable time step: Flanagan-Belytschko bound on the maximum eigenvalue,
      // omega^2 <= 8 c^2 B:B / V^2, reduced for the bulk viscosity.
      const vdouble lc = vol / stdx::sqrt(2.0 * bb);
      const vdouble qq = qv;
      const vdouble dte = lc / (qq + stdx::sqrt(qq * qq + c * c));

      vdouble check = dte;
      for (int a = 0; a < 8; ++a)
        for (int i = 0; i < 3; ++i) {
          simd::store(f[a][i],
                      corners.f[i] + b.corner_base + static_cast<std::size_t>(a) * stride + e);
          check += f[a][i];
        }

      // Scalar bookkeeping of the vector's lanes that hold real elements.
      const int lanes = std::min(width, n - e);
      for (int k = 0; k < lanes; ++k) {
        const std::int64_t id = b.gid[e + k];
        if (!(vol[k] > 0.0)) {
          if (result.inverted_gid < 0 || id < result.inverted_gid) result.inverted_gid = id;
        } else if (!std::isfinite(check[k])) {
          if (result.nonfinite_gid < 0 || id < result.nonfinite_gid) result.nonfinite_gid = id;
        }
        if (dte[k] < result.dt_stable || (dte[k] == result.dt_stable && id < result.stable_gid)) {
          result.dt_stable = dte[k];
          result.stable_gid = id;
        }
      }
    }
  }
}

void hex_volumes(const HexBlock& b, const double* const x[3], std::span<double> out) {
  const std::size_t n = std::min(out.size(), b.conn[0].size());
  for (std::size_t e = 0; e < n; ++e) {
    double xe[8][3], B[8][3];
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) xe[a][i] = x[i][b.conn[a][e]];
    hex8::gradient(xe, B);
    out[e] = hex8::volume(xe, B);
  }
}

} // namespace anvil
