// sphfsi example: the hydrostatic tank with a refined horizontal band, shared by examples/refined_tank/main.cpp and
// tests/unit/test_particle_refinement.cpp.
//
// The tank of examples/hydrostatic_tank (dynamic walls, consistent masses) is built at the base spacing dp. Two
// nested refinement boxes span the tank's width around mid-depth: level 1 (dp/2) over `level1_rows` base rows and,
// inside it, level 2 (dp/4) over `level2_rows` base rows. The particles in the band are split at the first steps
// (fluid/particle_refinement.hpp) and the column must settle to the hydrostatic pressure as the uniform tank does.
#pragma once

#include "../hydrostatic_tank/tank_scene.hpp"

#include <sphfsi/fluid/particle_refinement.hpp>

#include <vector>

namespace sphfsi::examples::refined_tank {

using tank::Real;
using tank::System;
using tank::Vector;
using Refinement = ParticleRefinement<System>;
using RefinedSimulation = Simulation<System, SymplecticVerlet, Refinement>;

/// The tank and its band.
struct RefinedTankConfig {
  tank::TankConfig tank{};
  int level1_rows{6};   ///< base rows covered by the level-1 box (centred on mid-depth, even)
  int level2_rows{2};   ///< base rows covered by the level-2 box inside it (even, < level1_rows)
  Real buffer_rows{1};  ///< merge buffer around the boxes, in base spacings
  /// Base columns kept coarse next to each side wall by the level-1 box (the level-2 box keeps one more): the walls
  /// are built at the base spacing, and fine particles against a coarse dynamic wall are sucked onto it.
  int wall_columns{2};
  Real band_centre() const { return Real(0.5) * tank.depth; }  ///< m
};

/// The two nested boxes over the tank's width; their edges lie between base rows, so the daughters tile the
/// parents' cells.
inline std::vector<RefinementBox<2, Real>> refinement_boxes(const RefinedTankConfig& cfg) {
  const Real dp = cfg.tank.dp(), zc = cfg.band_centre();
  const Real half1 = Real(0.5) * cfg.level1_rows * dp, half2 = Real(0.5) * cfg.level2_rows * dp;
  const Real x1 = cfg.wall_columns * dp, x2 = x1 + dp, w = cfg.tank.width;
  return {{Vector(x1, zc - half1), Vector(w - x1, zc + half1), 1},
          {Vector(x2, zc - half2), Vector(w - x2, zc + half2), 2}};
}

inline RefinementParameters<Real> refinement_parameters(const RefinedTankConfig& cfg) {
  RefinementParameters<Real> params;
  params.base_spacing = cfg.tank.dp();
  params.buffer_width = cfg.buffer_rows * cfg.tank.dp();
  params.smoothing_ratio = cfg.tank.smoothing_ratio;
  return params;
}

inline Refinement make_refinement(const System& system, const RefinedTankConfig& cfg) {
  return Refinement(system.domain(), refinement_boxes(cfg), refinement_parameters(cfg));
}

/// Total fluid mass per unit thickness, kg/m.
inline Real fluid_mass(const System& system) {
  const auto& p = system.particles();
  Real m = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid) m += p.mass[i];
  return m;
}

/// Number of fluid particles at each level 0, 1, 2 (from the mass, ParticleRefinement::halvings; intermediate masses
/// counted with the coarser level).
inline std::vector<std::size_t> particles_per_level(const System& system, const Refinement& refinement) {
  std::vector<std::size_t> count(3, 0);
  const auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    const int level = refinement.halvings(p.mass[i], system.eos().reference_density()) / 2;
    ++count[static_cast<std::size_t>(std::clamp(level, 0, 2))];
  }
  return count;
}

}  // namespace sphfsi::examples::refined_tank
