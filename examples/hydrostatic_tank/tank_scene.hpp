// sphfsi example: the hydrostatic tank scene and its measurements, shared by examples/hydrostatic_tank/main.cpp
// and tests/unit/test_walls.cpp.
//
// A 2D tank of still water (depth H, width L) settles under gravity between walls of either model: dynamic
// boundary particles (Crespo, Gomez-Gesteira & Dalrymple 2007) or Monaghan-Kos repulsive walls (Monaghan & Kos
// 1999; Rogers & Dalrymple 2008). At rest the pressure must be hydrostatic, p(z) = rho0 g (H_s - z), with H_s the
// settled free surface, and no fluid particle may leave the tank.
#pragma once

#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/scenes/builders.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace sphfsi::examples::tank {

using Real = double;
using Vector = Vec<2, Real>;
using System = ParticleSystem<2, Real, CubicSpline<2>, Tait<Real>>;
using TankSimulation = Simulation<System, SymplecticVerlet>;

/// Geometry, resolution and wall model of the tank.
struct TankConfig {
  Real depth{0.5};               ///< initial water depth H, m
  Real width{1.0};               ///< tank width L, m
  Real wall_height{0.7};         ///< height of the side walls, m
  int particles_over_depth{40};  ///< H / dp
  WallModel walls{WallModel::dynamic};
  Real sound_speed_factor{10};  ///< c0 = factor sqrt(g H) (Monaghan 1994: 10 keeps density variations ~1 %)
  Real rho0{1000};              ///< kg/m^3
  Real gravity{9.81};           ///< m/s^2
  bool depth_scaling{false};    ///< repulsive walls: eps(z) of eq. 22 with h0 = H (off: eps(z) = 1)
  Real smoothing_ratio{1.3};    ///< h / dp
  /// FluidParameters::gradient_correction: Bonet-Lok corrected pressure gradient for fluid particles whose kernel
  /// is cut by a repulsive wall (no effect with dynamic walls, which fill the kernel).
  GradientCorrection gradient_correction{GradientCorrection::near_repulsive_walls};
  /// m = rho(z) dp^2, so that the SPH volume m / rho of every particle is the dp^2 it occupies on the lattice
  /// (false: m = rho0 dp^2 for all, volumes smaller than the lattice cell by the hydrostatic compression).
  bool consistent_masses{true};

  Real dp() const { return depth / Real(particles_over_depth); }
  Real sound_speed() const { return sound_speed_factor * std::sqrt(gravity * depth); }
  Resolution<Real> resolution() const { return {dp(), smoothing_ratio}; }
  /// Period of the gravest vertical acoustic mode (quarter wave between bed and free surface), s.
  Real acoustic_period() const { return Real(4) * depth / sound_speed(); }

  void validate() const {
    require_positive("TankConfig::depth (m)", depth);
    require_positive("TankConfig::width (m)", width);
    require_in_range("TankConfig::particles_over_depth", particles_over_depth, 4, 2000);
    if (!(wall_height > depth))
      throw InputError(fmt::format("TankConfig::wall_height = {} m is invalid: valid range is (depth = {} m, inf)",
                                   wall_height, depth));
    require_in_range("TankConfig::sound_speed_factor", sound_speed_factor, Real(1), Real(100));
  }
};

/// The fluid model of the tank: the library defaults (artificial viscosity 0.01, delta-SPH 0.1) and, for repulsive
/// walls, the boundary spacing the builder used and the optional depth factor.
inline FluidParameters<2, Real> fluid_parameters(const TankConfig& cfg) {
  FluidParameters<2, Real> fluid;
  fluid.gravity = Vector(0, -cfg.gravity);
  fluid.walls = cfg.walls;
  fluid.gradient_correction = cfg.gradient_correction;
  fluid.repulsive.boundary_spacing = repulsive_wall_spacing(cfg.width, cfg.resolution());
  fluid.repulsive.strength =
      repulsive_strength_for_rest_gap(cfg.depth, cfg.gravity, cfg.sound_speed(), cfg.resolution().smoothing_ratio);
  if (cfg.depth_scaling) {
    fluid.repulsive.water_level = cfg.depth;
    fluid.repulsive.local_depth = cfg.depth;
  }
  return fluid;
}

/// Builds the tank: fluid block [0, L] x [0, H] in hydrostatic equilibrium, walls around [0, L] x [0, wall_height].
inline System make_tank(const TankConfig& cfg) {
  cfg.validate();
  const Real margin = Real(0.2) * cfg.depth;
  System system(Domain<2, Real>(Vector(-margin, -margin), Vector(cfg.width + margin, cfg.wall_height + margin)),
                Tait<Real>(cfg.rho0, cfg.sound_speed()));
  const auto res = cfg.resolution();
  add_fluid_block(system, Vector(0, 0), Vector(cfg.width, cfg.depth), res, cfg.depth, cfg.gravity);
  add_box_walls(system, Vector(0, 0), Vector(cfg.width, cfg.wall_height), res, cfg.walls);
  set_hydrostatic_wall_density(system, cfg.depth, cfg.gravity);
  if (cfg.consistent_masses) {
    auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i) p.mass[i] = p.density[i] * cfg.dp() * cfg.dp();
  }
  return system;
}

/// Shepard (normalised kernel) average of the fluid particles' pressure at point x, Pa:
///   p(x) = sum_b p_b W(x - x_b) V_b / sum_b W(x - x_b) V_b,  V_b = m_b / rho_b.
inline Real shepard_pressure(const System& system, const Vector& x) {
  const auto& p = system.particles();
  const auto& kernel = system.kernel();
  Real num = 0, den = 0;
  for (std::size_t b = 0; b < p.size(); ++b) {
    if (p.kind[b] != Kind::fluid) continue;
    const Real h = p.smoothing_length[b];
    const Real r = (x - p.position[b]).norm();
    if (r >= CubicSpline<2>::support * h) continue;
    const Real w = kernel.value(r, h) * p.mass[b] / p.density[b];
    num += p.pressure[b] * w;
    den += w;
  }
  return den > 0 ? num / den : Real(0);
}

/// Volume average of the fluid pressure over the band |z - z_c| <= half_height, x in the central half of the tank:
///   p_band = sum_b p_b V_b / sum_b V_b,  z_band = sum_b z_b V_b / sum_b V_b  (V_b = m_b / rho_b).
/// A hydrostatic (linear) field averages to its value at z_band, so p_band is compared with rho0 g (H_s - z_band).
/// Unlike the point probe it averages over many particles (a few hundred at 40 particles over depth), so the
/// particle-scale pressure noise of a disordered particle set averages out.
struct BandAverage {
  Real pressure;   ///< Pa
  Real elevation;  ///< volume-weighted mean z, m
  std::size_t particles;
};
inline BandAverage band_average_pressure(const System& system, const TankConfig& cfg, Real z_c, Real half_height) {
  const auto& p = system.particles();
  Real pv = 0, zv = 0, v = 0;
  std::size_t n = 0;
  for (std::size_t b = 0; b < p.size(); ++b) {
    if (p.kind[b] != Kind::fluid) continue;
    const Vector& x = p.position[b];
    if (std::abs(x[1] - z_c) > half_height || x[0] < Real(0.25) * cfg.width || x[0] > Real(0.75) * cfg.width) continue;
    const Real vol = p.mass[b] / p.density[b];
    pv += p.pressure[b] * vol;
    zv += x[1] * vol;
    v += vol;
    ++n;
  }
  return v > 0 ? BandAverage{pv / v, zv / v, n} : BandAverage{0, z_c, 0};
}

/// Settled free-surface height H_s, m: the water's SPH volume per unit width, sum_b m_b / rho_b / L. It counts the
/// compression of the column (through the densities) and does not depend on how the particles are arranged at the
/// surface (the height of the top particles is ragged once the lattice has rearranged).
inline Real free_surface_height(const System& system, const TankConfig& cfg) {
  const auto& p = system.particles();
  Real volume = 0;  // m^2 (per unit thickness)
  for (std::size_t b = 0; b < p.size(); ++b)
    if (p.kind[b] == Kind::fluid) volume += p.mass[b] / p.density[b];
  return volume / cfg.width;
}

/// Hydrostatic pressure rho0 g (H_s - z) of an incompressible column, Pa (the Tait column's own compressibility
/// adds a relative g (H_s - z) / (2 c0^2), 0.25 % at mid-depth for c0 = 10 sqrt(g H): neglected).
inline Real hydrostatic_pressure(const TankConfig& cfg, Real surface, Real z) {
  return cfg.rho0 * cfg.gravity * std::max(surface - z, Real(0));
}

/// Number of fluid particles outside the wall box [0, L] x [0, wall_height] (must stay 0).
inline std::size_t particles_outside(const System& system, const TankConfig& cfg) {
  const auto& p = system.particles();
  std::size_t n = 0;
  for (std::size_t b = 0; b < p.size(); ++b) {
    if (p.kind[b] != Kind::fluid) continue;
    const Vector& x = p.position[b];
    if (!(x[0] >= 0 && x[0] <= cfg.width && x[1] >= 0 && x[1] <= cfg.wall_height)) ++n;
  }
  return n;
}

/// Largest fluid particle speed, m/s.
inline Real max_fluid_speed(const System& system) {
  const auto& p = system.particles();
  Real v = 0;
  for (std::size_t b = 0; b < p.size(); ++b)
    if (p.kind[b] == Kind::fluid) v = std::max(v, p.velocity[b].norm());
  return v;
}

/// Kinetic energy of the fluid per unit tank thickness, J/m.
inline Real fluid_kinetic_energy(const System& system) {
  const auto& p = system.particles();
  Real e = 0;
  for (std::size_t b = 0; b < p.size(); ++b)
    if (p.kind[b] == Kind::fluid) e += Real(0.5) * p.mass[b] * p.velocity[b].squaredNorm();
  return e;
}

/// Smallest distance of a fluid particle from the bed z = 0 among those in the central half of the tank, m.
inline Real lowest_fluid_height(const System& system, const TankConfig& cfg) {
  const auto& p = system.particles();
  Real z = 1e30;
  for (std::size_t b = 0; b < p.size(); ++b) {
    if (p.kind[b] != Kind::fluid) continue;
    const Real x = p.position[b][0];
    if (x > Real(0.25) * cfg.width && x < Real(0.75) * cfg.width) z = std::min(z, p.position[b][1]);
  }
  return z;
}

}  // namespace sphfsi::examples::tank
