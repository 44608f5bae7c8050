// sphfsi: the SPHysics predictor-corrector scheme (Monaghan 1989, J. Comput. Phys. 82:1; Gomez-Gesteira et al.
// 2012, Comput. Geosci. 48:289, eqs 27-30):
//   predictor  v^{n+1/2} = v^n + dt/2 F^n,  rho^{n+1/2} = rho^n + dt/2 D^n,  x^{n+1/2} = x^n + dt/2 V^n
//   (rates at n+1/2)
//   corrector  v^{n+1/2} = v^n + dt/2 F^{n+1/2},  rho^{n+1/2} = rho^n + dt/2 D^{n+1/2},
//              x^{n+1/2} = x^n + dt/2 V^{n+1/2}
//   final      phi^{n+1} = 2 phi^{n+1/2} - phi^n  for phi = v, rho, x
// with V = v + XSPH correction. F^n, D^n are the rates of the previous step's evaluation: one evaluation a step.
#pragma once

#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>

namespace sphfsi {

struct PredictorCorrector {
  static constexpr const char* name = "predictor-corrector";

  template <class Sim, class T>
  void step(Sim& sim, T dt) const {
    auto& p = sim.system().particles();
    const T t = sim.time();
    const T half = T(0.5) * dt;
    parallel_for(p.size(), [&](std::size_t i) {
      p.position_old[i] = p.position[i];
      p.velocity_old[i] = p.velocity[i];
      p.density_old[i] = p.density[i];
      if (p.kind[i] == Kind::solid) return;
      p.density[i] = sim.limit_density(i, p.density[i] + half * p.density_rate[i]);
      if (p.kind[i] != Kind::fluid) return;
      p.position[i] += half * (p.velocity[i] + p.xsph_velocity[i]);
      p.velocity[i] += half * p.acceleration[i];
    });
    sim.move_walls(t + half);
    sim.evaluate_rates(t + half);
    parallel_for(p.size(), [&](std::size_t i) {
      if (p.kind[i] == Kind::solid) return;
      const T rho_half = p.density_old[i] + half * p.density_rate[i];
      p.density[i] = sim.limit_density(i, T(2) * rho_half - p.density_old[i]);
      if (p.kind[i] != Kind::fluid) return;
      const auto v_half = (p.velocity_old[i] + half * p.acceleration[i]).eval();
      const auto x_half = (p.position_old[i] + half * (v_half + p.xsph_velocity[i])).eval();
      p.velocity[i] = T(2) * v_half - p.velocity_old[i];
      p.position[i] = T(2) * x_half - p.position_old[i];
    });
    sim.move_walls(t + dt);
    sim.advance_models(t, dt);
  }
};

}  // namespace sphfsi
