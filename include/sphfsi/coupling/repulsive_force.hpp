// sphfsi: coupling approach 3 of the reference paper (eqs 17-23): repulsive force.
//
// The surface particles of the solid (outward normals from solid_surface.hpp, eqs 5-7) act as Monaghan & Kos (1999)
// boundary particles for the fluid, with the Rogers & Dalrymple (2008) repulsion R, the tangential weight P and the
// depth/velocity factor eps (boundary/repulsive_force.hpp). The fluid particle f receives the acceleration
// a_f = n R P eps (17); the solid particle s receives the reaction -m_f a_f / m_s, so the pair conserves momentum to
// round-off. The paper retains this approach for the Antoci gate and the Posidonia meadow.
//
// Thin structures (a solid with `static constexpr bool thin_structure = true`, e.g. solid/elastic_rod.hpp: a blade
// as one line of nodes) have no interior and no colour-gradient surface: every node is a boundary particle, with
// the unit normal n_s the model publishes in p.normal, and it pushes on both faces: a fluid particle at
// dx = x_f - x_s sees the face n = sign(dx . n_s) n_s, i.e. it is pushed back to the side it is on. The repulsion
// grows like 1 / sqrt(q) as the fluid particle approaches the blade, so it cannot be crossed in one step at the
// fluid's CFL (tested: tests/unit/test_couplings.cpp).
#pragma once

#include <sphfsi/boundary/repulsive_force.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/coupling/solid_surface.hpp>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace sphfsi {

template <Real T>
struct RepulsiveForce {
  static constexpr const char* name = "repulsive-force";
  T water_level{0};     ///< still-water level z0 for eps(z), m
  T local_depth{0};     ///< h0 of eq. 22; <= 0: eps(z) = 1 (no depth scaling), m
  T sound_speed{0};     ///< c0 used in A = 0.01 c0^2 / h (19) and eps(u) (23); 0: the fluid EOS's c0, m/s
  T range_factor{1};    ///< scales the boundary spacing db used in P(xi) (eq. 20), [0.5, 3]
  T strength{T(0.01)};  ///< k of A = k c0^2 / h (eq. 19: 0.01); see repulsive_strength_for_rest_gap(), > 0
  /// eps(u_perp) of eq. 23, the push added for fluid approaching the boundary. It is one-sided (zero when the
  /// fluid recedes), so a light thin blade that jitters under the particle impacts rectifies it into a mean push:
  /// measured in examples/blade_in_current (docs/thin-blades.md), it raised a flexible blade's drag above the
  /// rigid blade's. false: eps = eps(z) only.
  bool velocity_factor{true};
  /// beta of the normal dashpot: the fluid particle's velocity normal to the solid, relative to the solid particle,
  /// relaxes at the rate beta (c0 / h) (1 - q) P(xi), and the solid receives the reaction
  /// (boundary/repulsive_force.hpp). 0: none (the paper's eqs 17-23).
  T normal_damping{T(0)};

  void validate() const {
    require_non_negative("RepulsiveForce::sound_speed (m/s)", sound_speed);
    require_in_range("RepulsiveForce::range_factor", range_factor, T(0.5), T(3));
    require_positive("RepulsiveForce::strength (k of A = k c0^2 / h)", strength);
    require_in_range("RepulsiveForce::normal_damping (beta)", normal_damping, T(0), T(1));
  }

  /// The normal dashpot is explicit: the relative normal velocity of a fluid-solid pair relaxes at about
  /// lambda = beta (c0 / h) (1 + 2 r m_f / m_s), stable for lambda dt < 2. The 2: a node of a thin structure meets
  /// fluid on both faces; r: the share of a force on m_s that accelerates it (a rod's added inertia lowers it).
  /// Returns 2 / lambda over the solid's fluid neighbours (the Simulation applies its CFL factor to it); without the
  /// dashpot the repulsion sets no step of its own here (infinity).
  template <class System, class Solid>
  T stable_time_step(const System& system, const Solid& solid) const {
    T dt = std::numeric_limits<T>::infinity();
    if (normal_damping <= T(0)) return dt;
    const auto& p = system.particles();
    const T c0 = sound_speed > T(0) ? sound_speed : system.eos().reference_sound_speed();
    const auto& ids = solid.particle_ids();
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const std::size_t s = p.slot_of_id(ids[k]);
      // a solid with added inertia (ElasticRod::inertia_ratios) accelerates by only this share of m_f a_f / m_s
      T share = T(1);
      if constexpr (requires { solid.inertia_ratios(); }) share = solid.inertia_ratios()[k];
      system.for_each_neighbor(s, [&](std::size_t f, const auto&, T, T h) {
        if (p.kind[f] != Kind::fluid) return;
        const T rate = normal_damping * (c0 / h) * (T(1) + T(2) * share * p.mass[f] / p.mass[s]);
        dt = std::min(dt, T(2) / rate);
      });
    }
    return dt;
  }

  template <class System, class Solid>
  void apply(System& system, const Solid& solid, T /*time*/) const {
    using Vector = Vec<System::dimension, T>;
    constexpr int up = System::dimension - 1;
    auto& p = system.particles();
    const auto& ids = solid.particle_ids();
    constexpr bool thin = requires { requires Solid::thin_structure; };
    std::vector<char> surface;
    if constexpr (thin) surface.assign(ids.size(), 1);  // every node, normal published by the model
    else update_solid_surface(system, ids, solid.body(), surface);
    RepulsiveForceParameters<T> params;
    params.boundary_spacing = range_factor * solid.reference_spacing();
    params.water_level = water_level;
    params.local_depth = local_depth;
    params.vertical_axis = up;
    params.strength = strength;
    params.velocity_factor = velocity_factor;
    params.normal_damping = normal_damping;
    const T c0 = sound_speed > T(0) ? sound_speed : system.eos().reference_sound_speed();
    for (std::size_t k = 0; k < ids.size(); ++k) {
      if (!surface[k]) continue;
      const std::size_t s = p.slot_of_id(ids[k]);
      const Vector n_s = p.normal[s];
      system.for_each_neighbor(s, [&](std::size_t f, const Vector& dx_sf, T, T h) {
        if (p.kind[f] != Kind::fluid) return;
        // dx_sf = x_s - x_f: a fluid particle with dx_sf . n_s > 0 is on the -n_s face of a thin structure
        const bool back_face = thin && dx_sf.dot(n_s) > T(0);
        const Vector n = back_face ? Vector(-n_s) : n_s;
        const Vector a_f = repulsive_force<System::dimension, T>(-dx_sf, p.velocity[f] - p.velocity[s], n, h, c0,
                                                                 p.position[f][up] - water_level, params);
        p.acceleration[f] += a_f;
        p.acceleration[s] -= (p.mass[f] / p.mass[s]) * a_f;
      });
    }
  }
};

}  // namespace sphfsi
