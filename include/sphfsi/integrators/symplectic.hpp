// sphfsi: symplectic position-Verlet integrator (Leimkuhler, Reich & Skeel 1996; Monaghan 2005, Rep. Prog. Phys.
// 68:1703, sec. 11; the DualSPHysics "Symplectic" scheme, Crespo et al. 2015, Comput. Phys. Commun. 187:204):
//   x^{n+1/2}   = x^n + dt/2 v^n,      rho^{n+1/2} = rho^n + dt/2 D^n
//   (rates at n+1/2)
//   v^{n+1}     = v^n + dt F^{n+1/2}
//   x^{n+1}     = x^{n+1/2} + dt/2 v^{n+1}
//   rho^{n+1}   = rho^n (2 - e) / (2 + e),  e = -dt D^{n+1/2} / rho^{n+1/2}
// One rate evaluation per step. XSPH corrections are added to the drift velocity.
#pragma once

#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>

namespace sphfsi {

struct SymplecticVerlet {
  static constexpr const char* name = "symplectic";

  template <class Sim, class T>
  void step(Sim& sim, T dt) const {
    auto& p = sim.system().particles();
    const T t = sim.time();
    const T half = T(0.5) * dt;
    parallel_for(p.size(), [&](std::size_t i) { begin_particle(sim, p, i, dt); });
    sim.move_walls(t + half);
    sim.evaluate_rates(t + half);
    parallel_for(p.size(), [&](std::size_t i) { finish_particle(sim, p, i, dt); });
    sim.move_walls(t + dt);
    sim.advance_models(t, dt);
  }

  /// The start of a step of dt for slot i: its state saved in the _old fields, then the half drift of density (fluid
  /// and walls) and position (fluid) to the midpoint. Also used per time level by LocalSymplecticVerlet.
  template <class Sim, class Particles, class T>
  static void begin_particle(const Sim& sim, Particles& p, std::size_t i, T dt) {
    const T half = T(0.5) * dt;
    p.position_old[i] = p.position[i];
    p.velocity_old[i] = p.velocity[i];
    p.density_old[i] = p.density[i];
    if (p.kind[i] == Kind::solid) return;
    p.density[i] = sim.limit_density(i, p.density[i] + half * p.density_rate[i]);
    if (p.kind[i] == Kind::fluid) p.position[i] += half * (p.velocity[i] + p.xsph_velocity[i]);
  }

  /// The end of the step of dt for slot i, from the midpoint rates: density in the symplectic form, the kick and the
  /// second half drift.
  template <class Sim, class Particles, class T>
  static void finish_particle(const Sim& sim, Particles& p, std::size_t i, T dt) {
    if (p.kind[i] == Kind::solid) return;
    const T half = T(0.5) * dt;
    const T e = -dt * p.density_rate[i] / p.density[i];
    p.density[i] = sim.limit_density(i, p.density_old[i] * (T(2) - e) / (T(2) + e));
    if (p.kind[i] != Kind::fluid) return;
    p.velocity[i] = p.velocity_old[i] + dt * p.acceleration[i];
    p.position[i] += half * (p.velocity[i] + p.xsph_velocity[i]);
  }
};

}  // namespace sphfsi
