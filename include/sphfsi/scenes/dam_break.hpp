// sphfsi: the 2D dam break scene (Martin & Moyce 1952 geometry, default n^2 = H/a = 1), shared by the example, the
// benchmark and the regression tests.
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/scenes/builders.hpp>

#include <algorithm>
#include <cmath>

namespace sphfsi::scenes {

template <Real T>
struct DamBreakGeometry {
  T column_width{T(0.057)};     ///< a, m (Martin & Moyce's 2.25 in)
  T column_height_ratio{T(1)};  ///< n^2 = H / a (Martin & Moyce ran 1 and 2)
  T tank_length_ratio{T(5)};    ///< tank length / a
  T tank_height_ratio{T(2.5)};  ///< tank wall height / a
  T particles_across{T(40)};    ///< a / dp
  T smoothing_ratio{T(1.3)};    ///< h / dp
  T sound_speed_factor{T(10)};  ///< c0 / sqrt(g H)
  T gravity{T(9.81)};           ///< m/s^2
  WallModel walls{WallModel::dynamic};

  void validate() const {
    require_positive("DamBreakGeometry::column_width (m)", column_width);
    require_in_range("DamBreakGeometry::column_height_ratio (H/a)", column_height_ratio, T(0.1), T(10));
    require_in_range("DamBreakGeometry::tank_length_ratio", tank_length_ratio, T(1), T(100));
    require_in_range("DamBreakGeometry::tank_height_ratio", tank_height_ratio, column_height_ratio, T(100));
    require_in_range("DamBreakGeometry::particles_across (a/dp)", particles_across, T(4), T(4000));
    require_in_range("DamBreakGeometry::sound_speed_factor (c0/sqrt(gH))", sound_speed_factor, T(5), T(1000));
    require_positive("DamBreakGeometry::gravity (m/s^2)", gravity);
  }
  T a() const { return column_width; }
  T height() const { return column_height_ratio * column_width; }
  T dp() const { return column_width / particles_across; }
  T sound_speed() const { return sound_speed_factor * std::sqrt(gravity * height()); }
  /// Time scale of Martin & Moyce's normalisation T = n t sqrt(g / a), n = sqrt(H / a): t = T * time_scale().
  T time_scale() const { return std::sqrt(column_width / gravity) / std::sqrt(column_height_ratio); }
};

/// Fills `system` (empty, built with a domain from dam_break_domain) with the column and the tank walls.
template <class System>
void build_dam_break(System& system, const DamBreakGeometry<typename System::scalar_type>& g) {
  using T = typename System::scalar_type;
  using V = Vec<2, T>;
  static_assert(System::dimension == 2, "the dam break scene is 2D");
  g.validate();
  const Resolution<T> res{g.dp(), g.smoothing_ratio};
  add_fluid_block(system, V(0, 0), V(g.a(), g.height()), res, g.height(), g.gravity);
  add_box_walls(system, V(0, 0), V(g.tank_length_ratio * g.a(), g.tank_height_ratio * g.a()), res, g.walls, 3);
}

/// Domain enclosing the tank with a margin of 5 particle spacings.
template <Real T>
Domain<2, T> dam_break_domain(const DamBreakGeometry<T>& g) {
  const T m = T(5) * g.dp();
  return Domain<2, T>(Vec<2, T>(-m, -m), Vec<2, T>(g.tank_length_ratio * g.a() + m, g.tank_height_ratio * g.a() + m));
}

/// Fluid parameters of the scene: gravity, artificial viscosity alpha, delta-SPH, walls.
template <Real T>
FluidParameters<2, T> dam_break_fluid(const DamBreakGeometry<T>& g) {
  FluidParameters<2, T> f;
  f.gravity = Vec<2, T>(0, -g.gravity);
  f.walls = g.walls;
  f.repulsive.boundary_spacing = g.dp();
  return f;
}

/// Surge front: the largest x of any fluid particle.
template <class Particles>
auto surge_front(const Particles& p) {
  using T = typename Particles::scalar_type;
  T front = -std::numeric_limits<T>::max();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid) front = std::max(front, p.position[i][0]);
  return front;
}

}  // namespace sphfsi::scenes
