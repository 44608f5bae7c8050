// sphfsi: the Antoci et al. (2007) elastic-gate dam break (reference paper, Tables 1-2; validation-cases.md sec. 1).
//
// A water column A = 0.1 m wide and H = 0.14 m high is held by a rubber gate of length L = 0.079 m and thickness
// s = 0.005 m, clamped at its top to a rigid wall that holds the water above it; the gate's free end sits one
// particle spacing above the floor. At t = 0 the water pushes the gate open and flows out under it. The measured
// quantity is the displacement of the gate's free end (mean of its bottom row of particles).
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/solid/elastic_material.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

namespace sphfsi::scenes {

template <Real T>
struct AntociGate {
  // Table 1 geometry, m.
  T column_width{T(0.1)};      ///< A
  T column_height{T(0.14)};    ///< H
  T gate_length{T(0.079)};     ///< L
  T gate_thickness{T(0.005)};  ///< s
  T tank_length{T(1.2)};       ///< downstream floor ends in a wall here (spray reaches ~0.8 m by 0.4 s)
  // Table 2 properties.
  T fluid_density{T(1000)};    ///< kg/m^3
  T fluid_sound_speed{T(20)};  ///< c0, m/s (>= 10 x the largest flow speed sqrt(2 g H) = 1.66 m/s)
  T solid_density{T(1100)};    ///< kg/m^3
  T youngs_modulus{T(1.2e7)};  ///< E, Pa
  T poisson_ratio{T(0.4)};     ///< nu (K = 2e7 Pa, G = 4.27e6 Pa of Table 2 give nu = 0.400)
  /// The 2D gate in plane stress (a plate free to contract across the tank: bending stiffness E t^3 / 12) instead of
  /// plane strain (E t^3 / (12 (1 - nu^2)), 19 % stiffer at nu = 0.4). The real gate, 0.1 m wide and 5 mm thick, is
  /// between the two (docs/coupling-comparison.md).
  bool plane_stress{false};
  // Resolution.
  T particles_across{T(80)};  ///< A / dp (80: dp = 1.25 mm, 4 particle rows across the gate)
  T smoothing_ratio{T(1.3)};  ///< h / dp
  int clamp_rows{3};          ///< rows of fluid spacing dp above L held by the clamp
  int solid_refinement{1};    ///< the gate's particle spacing is dp / solid_refinement (1, 2 or 4; issue 9)
  T gravity{T(9.81)};

  void validate() const {
    require_positive("AntociGate::column_width (m)", column_width);
    require_positive("AntociGate::column_height (m)", column_height);
    require_in_range("AntociGate::gate_length (m)", gate_length, T(0.1) * column_height, column_height);
    require_positive("AntociGate::gate_thickness (m)", gate_thickness);
    require_in_range("AntociGate::tank_length (m)", tank_length, column_width + gate_thickness + T(0.05), T(10));
    require_positive("AntociGate::fluid_density (kg/m^3)", fluid_density);
    require_positive("AntociGate::fluid_sound_speed (m/s)", fluid_sound_speed);
    require_in_range("AntociGate::particles_across (A/dp)", particles_across, T(20), T(2000));
    require_in_range("AntociGate::smoothing_ratio (h/dp)", smoothing_ratio, T(1), T(3));
    require_in_range("AntociGate::clamp_rows", clamp_rows, 1, 10);
    if (solid_refinement != 1 && solid_refinement != 2 && solid_refinement != 4)
      throw InputError(
          fmt::format("AntociGate::solid_refinement = {} is not supported: valid values are 1, 2 and 4 "
                      "(gate spacing dp, dp / 2, dp / 4)",
                      solid_refinement));
    solid_material().validate();
    const T rows = gate_thickness / dp(), solid_rows = gate_thickness / solid_dp();
    if (std::abs(rows - std::round(rows)) > T(1e-6) || solid_rows < T(2.5))
      throw InputError(
          fmt::format("AntociGate: gate_thickness / dp = {} must be a whole number and the gate needs >= 3 "
                      "particle rows (has {}): choose particles_across as a multiple of {}",
                      rows, solid_rows, column_width / gate_thickness));
    const T max_speed = std::sqrt(T(2) * gravity * column_height);
    if (fluid_sound_speed < T(10) * max_speed)
      fmt::print(stderr,
                 "warning: AntociGate::fluid_sound_speed = {} m/s is below 10 x the largest flow speed ({:.3g} "
                 "m/s): density errors above 1 %\n",
                 fluid_sound_speed, T(10) * max_speed);
  }
  T dp() const { return column_width / particles_across; }
  T solid_dp() const { return dp() / T(solid_refinement); }  ///< the gate's particle spacing, m
  T gap() const { return dp(); }                             ///< free end to floor
  /// Height of the clamp plane: the gate's free part spans round(L/dp) particle rows above the gap.
  T clamp_height() const { return gap() + std::round(gate_length / dp()) * dp(); }
  ElasticMaterial<T> solid_material() const {
    ElasticMaterial<T> m;
    m.density = solid_density;
    m.youngs_modulus = youngs_modulus;
    m.poisson_ratio = poisson_ratio;
    return plane_stress ? m.plane_stress_equivalent() : m;
  }
  Domain<2, T> domain() const {
    const T m = T(6) * dp();
    return Domain<2, T>(Vec<2, T>(-m, -m), Vec<2, T>(tank_length + m, T(2) * column_height + m));
  }
  FluidParameters<2, T> fluid() const {
    FluidParameters<2, T> f;
    f.gravity = Vec<2, T>(0, -gravity);
    f.artificial_viscosity = T(0.02);
    f.minimum_pressure = T(0);  // the jet under the gate breaks into spray: no tension in it
    return f;
  }
};

/// Particle ids of the gate's free end (its bottom row), to measure the tip displacement.
struct AntociGateIds {
  std::int32_t gate_body{1};
  std::vector<std::uint32_t> tip;
};

/// Fills an empty 2D system with the water column, the tank walls, the rigid wall above the gate and the gate
/// (solid particles of body 1, to be clamped above clamp_height()).
template <class System>
AntociGateIds build_antoci_gate(System& system, const AntociGate<typename System::scalar_type>& g) {
  using T = typename System::scalar_type;
  using V = Vec<2, T>;
  static_assert(System::dimension == 2, "the Antoci gate scene is 2D");
  g.validate();
  const Resolution<T> res{g.dp(), g.smoothing_ratio};
  const T dp = g.dp(), x_gate = g.column_width, top = g.column_height + T(0.03);
  add_fluid_block(system, V(0, 0), V(g.column_width, g.column_height), res, g.column_height, g.gravity);
  add_box_walls(system, V(0, 0), V(g.tank_length, top), res, WallModel::dynamic, 3, 0);
  // Rigid wall above the gate's clamp: wall particles on the gate's lattice.
  const T clamp_top = g.clamp_height() + T(g.clamp_rows) * dp;
  const T rho_w = system.eos().reference_density();
  for_each_lattice_point<2, T>(V(x_gate, clamp_top), V(x_gate + g.gate_thickness, top), dp, [&](const V& x) {
    system.particles().add(Kind::wall, x, V::Zero(), rho_w, rho_w * dp * dp, res.h(), 0);
  });
  // The gate: free part [gap, gap + L] and clamped rows above it, at its own spacing ds = dp / solid_refinement
  // with h = smoothing_ratio ds (each particle carries its own mass and smoothing length).
  AntociGateIds ids;
  const T rho_s = g.solid_density, ds = g.solid_dp(), h_s = g.smoothing_ratio * ds;
  for_each_lattice_point<2, T>(V(x_gate, g.gap()), V(x_gate + g.gate_thickness, clamp_top), ds, [&](const V& x) {
    const std::size_t slot =
        system.particles().add(Kind::solid, x, V::Zero(), rho_s, rho_s * ds * ds, h_s, ids.gate_body);
    if (x[1] < g.gap() + ds) ids.tip.push_back(system.particles().id[slot]);
  });
  return ids;
}

/// Mean displacement of the gate's free end from its initial position.
template <class Particles>
auto gate_tip_position(const Particles& p, const std::vector<std::uint32_t>& tip) {
  using V = typename Particles::Vector;
  V mean = V::Zero();
  for (const std::uint32_t id : tip) mean += p.position[p.slot_of_id(id)];
  return V(mean / static_cast<typename Particles::scalar_type>(tip.size()));
}

}  // namespace sphfsi::scenes
