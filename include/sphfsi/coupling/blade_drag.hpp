// sphfsi: a Morison-drag coupling for thin blades that stand for a 3D canopy in a 2D scene (porous blades).
//
// A 2D full-width blade (scenes/meadow.hpp) is a wall to the 2D fluid: with the repulsive coupling and the
// normal dashpot it holds the whole pressure difference and the meadow is a dam; without them the fluid leaks
// through it in the SPH sums at a rate no physics sets (docs/meadow.md). In the 3D meadow it stands for, the water
// passes between the blades, and what the blades take from the flow is their drag. This coupling gives the 2D
// blade exactly that: the fluid is not blocked, and each node k of the blade exchanges with the fluid the Morison
// drag of its share ds_k of the blade's length (per unit width of the 2D blade, which is the real blade's drag per
// unit width at the equivalent spacing dx_b = 1 / (N b)):
//   F_k = (1/2) rho_w ds_k [ C_D |u_n| u_n n + C_f |u_t| u_t t ],   u = u_f(x_k) - v_k,
// with n, t the node's normal and tangent, u_n = u . n, u_t = u . t, and u_f(x_k) the fluid velocity at the node,
// Shepard-interpolated from the fluid particles in its kernel support:
//   u_f(x_k) = sum_f w_kf v_f,   w_kf = V_f W(x_k - x_f, h) / sum_g V_g W(x_k - x_g, h).
// The node receives F_k / m_k; each fluid particle f receives -phi w_kf F_k / m_f, so the pair set conserves linear
// momentum to round-off (sum_f w_kf = 1; the rod counted with the weight phi, below), and the power
// phi (F_k . v_k - sum_f w_kf F_k . v_f) = -phi F_k . u <= 0: the coupling only dissipates.
// phi = `frontal_fraction`, the share of the 2D scene's width that the blades it stands for cover: 1 for a full-width
// row (a meadow at the equivalent spacing, scenes/meadow.hpp), b / W for a single blade of width b in a flume of
// width W (blade_in_current). The rod's properties are per unit width of blade; per unit width of the scene the
// blade has phi times its force, mass and momentum, and the fluid feels phi times its drag. Morison et al. (1950) for
// the force form; its use for flexible blades resolved as beams with the normal and tangential components above: Luhar
// & Nepf (2016, J. Fluids Struct. 61:20), who also include the added-mass force (here the rod's added inertia,
// ElasticRodParameters::added_mass_per_area; the force of the fluid's own acceleration is not included) and a
// Keulegan-Carpenter dependent C_D (analysis/vegetation_drag.hpp: oscillatory_plate_drag_coefficient). A node with no
// fluid in its support (above the free surface) exchanges nothing. Passive fluid particles (a refined region,
// fluid/adaptive_refinement.hpp) are left out of u_f and get no reaction: the drag acts on the integrated fluid,
// which around a node inside a refinement box is its fine resolution only.
//
// Limits: it needs a thin structure (one line of nodes with published normals, solid/elastic_rod.hpp). It does not
// keep the fluid on one side of the blade (crossings are the point here), so it is not the coupling for a blade
// that must be impermeable (docs/thin-blades.md: the repulsive coupling with the normal dashpot). The drag uses the
// local, smoothed SPH velocity at the node, which the canopy's drag itself lowers, as a canopy model uses the
// in-canopy velocity.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace sphfsi {

/// Added mass per unit length and unit width of a flat plate of width b moving normal to itself, C_M rho pi b / 4,
/// kg/m^2 (potential flow: C_M = 1). A porous blade does not move the fluid aside, so the rod has to carry it
/// (ElasticRodParameters::added_mass_per_area).
template <Real T>
T plate_added_mass_per_area(T fluid_density, T width, T coefficient = T(1)) {
  return coefficient * fluid_density * std::numbers::pi_v<T> * width / T(4);
}

template <Real T>
struct BladeDrag {
  static constexpr const char* name = "blade-drag";
  /// The water passes through the blade (coupling/concepts.hpp): no thin-structure edges.
  static constexpr bool permeable = true;
  /// C_D on the velocity normal to the blade (1.95: a flat plate normal to a steady flow, the value of the
  /// Luhar & Nepf 2011 reconfiguration model), [0, 10].
  T drag_coefficient{T(1.95)};
  /// C_f on the velocity along the blade, both faces together (0: none), [0, 1].
  T friction_coefficient{T(0)};
  /// rho_w of the drag, kg/m^3; 0: the fluid EOS's reference density.
  T fluid_density{T(0)};
  /// phi: share of the scene's width covered by the blades this 2D blade stands for (see the header), (0, 1].
  T frontal_fraction{T(1)};

  void validate() const {
    require_in_range("BladeDrag::drag_coefficient (C_D)", drag_coefficient, T(0), T(10));
    require_in_range("BladeDrag::friction_coefficient (C_f)", friction_coefficient, T(0), T(1));
    require_non_negative("BladeDrag::fluid_density (kg/m^3)", fluid_density);
    require_in_range("BladeDrag::frontal_fraction (phi)", frontal_fraction, std::numeric_limits<T>::min(), T(1));
  }

  /// The drag force per unit width on a blade element of length ds moving at relative velocity u = u_f - v_s
  /// (eq. in the header), with unit normal n (2D).
  Vec<2, T> element_force(const Vec<2, T>& u, const Vec<2, T>& n, T ds, T rho) const {
    const Vec<2, T> t(-n[1], n[0]);
    const T un = u.dot(n), ut = u.dot(t);
    return (T(0.5) * rho * ds) *
           ((drag_coefficient * std::abs(un) * un) * n + (friction_coefficient * std::abs(ut) * ut) * t);
  }

  /// The drag is explicit: the relative velocity of node k and its fluid relaxes at about
  /// lambda_k = (1/2) rho ds_k (C_D + C_f) |u_k| (r_k / m_k + phi sum_f w_kf^2 / m_f) (r_k: the share of a force on the
  /// node that accelerates it, ElasticRod::inertia_ratios), stable for lambda dt < 2. Returns 2 / max_k lambda_k of
  /// the last evaluation's velocities (the Simulation applies its CFL factor); infinity while nothing moves.
  template <class System, class Solid>
  T stable_time_step(const System& system, const Solid& solid) const {
    T dt = std::numeric_limits<T>::infinity();
    const auto& p = system.particles();
    const T rho = density(system);
    const auto& ids = solid.particle_ids();
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const Sample s = sample(system, ids, k);
      if (!(s.weight_sum > T(0))) continue;
      T share = T(1);
      if constexpr (requires { solid.inertia_ratios(); }) share = solid.inertia_ratios()[k];
      const std::size_t node = p.slot_of_id(ids[k]);
      const T speed = (s.fluid_velocity - p.velocity[node]).norm();
      const T rate = T(0.5) * rho * s.length * (drag_coefficient + friction_coefficient) * speed *
                     (share / p.mass[node] + frontal_fraction * s.inverse_fluid_mass);
      if (rate > T(0)) dt = std::min(dt, T(2) / rate);
    }
    return dt;
  }

  /// The velocity of the fluid relative to node k, u_f(x_k) - v_k (zero for a node with no fluid in its support):
  /// what the drag acts on, e.g. for the Keulegan-Carpenter number of the relative motion.
  template <class System, class Solid>
  Vec<2, T> relative_velocity(const System& system, const Solid& solid, std::size_t k) const {
    const auto& ids = solid.particle_ids();
    const Sample s = sample(system, ids, k);
    if (!(s.weight_sum > T(0))) return Vec<2, T>::Zero();
    return s.fluid_velocity - system.particles().velocity[system.particles().slot_of_id(ids[k])];
  }

  template <class System, class Solid>
  void apply(System& system, const Solid& solid, T /*time*/) const {
    static_assert(System::dimension == 2, "BladeDrag: 2D thin structures only");
    static_assert(
        requires { requires Solid::thin_structure; },
        "BladeDrag needs a thin structure (one line of nodes that publish their normals, e.g. ElasticRod)");
    auto& p = system.particles();
    const T rho = density(system);
    const auto& ids = solid.particle_ids();
    const auto& kernel = system.kernel();
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const Sample s = sample(system, ids, k);
      if (!(s.weight_sum > T(0))) continue;
      const std::size_t node = p.slot_of_id(ids[k]);
      const Vec<2, T> force = element_force(s.fluid_velocity - p.velocity[node], p.normal[node], s.length, rho);
      p.acceleration[node] += force / p.mass[node];
      const Vec<2, T> per_weight = (frontal_fraction / s.weight_sum) * force;
      system.for_each_neighbor(node, [&](std::size_t f, const Vec<2, T>&, T r, T h) {
        if (p.kind[f] != Kind::fluid || p.passive[f]) return;
        const T w = p.mass[f] / p.density[f] * kernel.value(r, h);
        p.acceleration[f] -= (w / p.mass[f]) * per_weight;
      });
    }
  }

 private:
  struct Sample {
    Vec<2, T> fluid_velocity = Vec<2, T>::Zero();  // u_f(x_k), Shepard
    T weight_sum{0};                               // sum_f V_f W
    T inverse_fluid_mass{0};                       // sum_f w_kf^2 / m_f: the fluid's response to F_k
    T length{0};                                   // ds_k: half of each adjacent edge
  };

  template <class System>
  T density(const System& system) const {
    return fluid_density > T(0) ? fluid_density : system.eos().reference_density();
  }

  template <class System, class Ids>
  static Sample sample(const System& system, const Ids& ids, std::size_t k) {
    const auto& p = system.particles();
    const auto& kernel = system.kernel();
    const std::size_t node = p.slot_of_id(ids[k]);
    Sample s;
    if (k > 0) s.length += T(0.5) * (p.position[node] - p.position[p.slot_of_id(ids[k - 1])]).norm();
    if (k + 1 < ids.size()) s.length += T(0.5) * (p.position[p.slot_of_id(ids[k + 1])] - p.position[node]).norm();
    system.for_each_neighbor(node, [&](std::size_t f, const Vec<2, T>&, T r, T h) {
      if (p.kind[f] != Kind::fluid || p.passive[f]) return;
      const T w = p.mass[f] / p.density[f] * kernel.value(r, h);
      s.weight_sum += w;
      s.fluid_velocity += w * p.velocity[f];
      s.inverse_fluid_mass += w * w / p.mass[f];
    });
    if (s.weight_sum > T(0)) {
      s.fluid_velocity /= s.weight_sum;
      s.inverse_fluid_mass /= s.weight_sum * s.weight_sum;
    }
    return s;
  }
};

}  // namespace sphfsi
