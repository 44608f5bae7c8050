// The still tank with nested APR boxes (dp, dp/2, dp/4) shared by the adaptive-refinement and the local time stepping
// tests: h/dp = 20, 0.5 m wide, a level-1 box 12 x 8 dp and a level-2 box 6 x 2 dp around mid-depth, transition 2 dp.
#pragma once

#include "../../examples/hydrostatic_tank/tank_scene.hpp"

#include <sphfsi/fluid/adaptive_refinement.hpp>

#include <vector>

namespace sphfsi::tests {

struct NestedAprTank {
  examples::tank::TankConfig cfg;
  double mid_depth = 0;  ///< z of the boxes' centre, m
  std::vector<RefinementBox<2, double>> boxes;
  AdaptiveRefinementParameters<double> params;
  FluidParameters<2, double> fluid;  ///< same_resolution_pairs, artificial viscosity 0.1

  /// Kinetic energy bound of a settled tank: acoustic noise whose pressure amplitude is 2 % of the mid-depth pressure,
  /// u = 0.02 (rho g H / 2) / (rho c0), KE = M u^2 / 2 with M the fluid mass (J/m).
  double kinetic_energy_bound() const {
    const double fluid_mass = cfg.rho0 * cfg.depth * cfg.width;
    const double noise_speed = 0.02 * (0.5 * cfg.gravity * cfg.depth) / cfg.sound_speed();
    return 0.5 * fluid_mass * noise_speed * noise_speed;
  }
};

/// Kinetic energy of the active fluid (passive particles are a second copy of the same water), J/m.
inline double active_kinetic_energy(const examples::tank::System& system) {
  const auto& p = system.particles();
  double e = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid && !p.passive[i]) e += 0.5 * p.mass[i] * p.velocity[i].squaredNorm();
  return e;
}

/// SPH volume of the active fluid, m^2.
inline double active_volume(const examples::tank::System& system) {
  const auto& p = system.particles();
  double volume = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid && !p.passive[i]) volume += p.mass[i] / p.density[i];
  return volume;
}

inline NestedAprTank nested_apr_tank() {
  using V2 = Vec<2, double>;
  NestedAprTank t;
  t.cfg.particles_over_depth = 20;
  t.cfg.width = 0.5;
  const double dp = t.cfg.dp();
  t.mid_depth = 0.5 * t.cfg.depth;
  const double zc = t.mid_depth;
  t.boxes = {{V2(4 * dp, zc - 4 * dp), V2(16 * dp, zc + 4 * dp), 1}, {V2(7 * dp, zc - dp), V2(13 * dp, zc + dp), 2}};
  t.params.base_spacing = dp;
  t.params.transition_width = 2 * dp;
  t.params.smoothing_ratio = t.cfg.smoothing_ratio;
  t.fluid = examples::tank::fluid_parameters(t.cfg);
  t.fluid.same_resolution_pairs = true;
  t.fluid.artificial_viscosity = 0.1;
  return t;
}

}  // namespace sphfsi::tests
