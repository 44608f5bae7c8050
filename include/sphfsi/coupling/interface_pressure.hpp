// sphfsi: coupling approach 2 of the reference paper (eqs 3-16; Antoci, Gallati & Sibilla 2007, Comput. Struct.
// 85:879, with the surface integral of Ha et al. 2011): interface-point pressure.
//
// Every surface particle s of the solid (outward normal n_s, solid_surface.hpp; eqs 5-6) carries an interface point
//   x_int = x_s + (rl + 1/2) d n_s, rl = 0 for the surface row                                   (7)
//   p_int = sum_f V_f p_f W(x_int - x_f) / sum_f V_f W(x_int - x_f)    (fluid f only, Shepard)   (12)
// Two forms of the force, InterfacePressure::form:
//
// integral (default). The surface integral of eqs 8-11 taken over every solid particle a within the kernel support
// of the interface (the reference paper: "for all solid particles at a distance less than 2h from the interface"),
// each at its own position, with the pressure of the interface point nearest the fluid particle f:
//   F_a = -sum_f 2 p_int(f) V_a V_f grad_a W(x_a - x_f)                                         (10-11, 13)
// and each pair's reaction on its own fluid particle f (the mirrored particles of eqs 14-16 are then the solid
// particles themselves: every pair's force is equal and opposite, so momentum is conserved pair by pair). Over a
// flat interface sum_a V_a sum_f V_f grad_a W = -n x area / 2 (two half-spaces share half of a kernel), so the factor
// 2, that of the fluid's own symmetric pressure sum (p_f + p_b with both at the interface pressure), makes the load
// p_int per unit area: the still column of tests/unit/test_couplings.cpp loads a solid wall with rho g H^2 / 2 to
// 0.3 %. The kinematic condition (3), u_f . n = u_s . n, enters the fluid's continuity equation:
//   drho_f/dt += rho_f V_a (v_f - v_a) . grad_f W(x_f - x_a)                                     (3)
// so fluid that presses on the solid is compressed and its interface pressure rises: without it the water runs
// through the Antoci gate. A Monaghan (1992) artificial viscosity on the same pairs (artificial_viscosity, as the
// fluid has at its walls) damps the fluid-solid contact; without it the gate's surface rows ring and break.
//
// surface_mirror. Eqs 10-16 as the reference paper prints them: the force evaluated at the interface point of the
// surface row only, F_s = -p_int sum_f V_f grad W(x_int - x_f) (per unit volume of s), and the reaction -V_s F_s
// spread over the fluid around the mirror point x_s* = x_s + d n_s with weights V_f W(x_f - x_s*) (normalised, so
// that momentum is conserved to round-off; eq. 15 as printed only does so on a full support), no kinematic term.
// The surface row alone carries 55 % of the still column's load (tests/unit/test_couplings.cpp), and nothing stops a
// fluid particle approaching the solid: on the Antoci gate the water runs through the gate
// (docs/coupling-comparison.md), as the reference paper reports for its frond.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/coupling/solid_surface.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace sphfsi {

/// Which form of the interface-pressure force InterfacePressure applies (see the header comment).
enum class InterfaceForm { integral, surface_mirror };

template <Real T>
struct InterfacePressure {
  static constexpr const char* name = "interface-pressure";
  InterfaceForm form{InterfaceForm::integral};
  /// alpha of a Monaghan viscosity on the fluid-solid pairs of the integral form (fluid-wall pairs have the fluid's),
  /// [0, 5]. On the Antoci gate 0.02 (the fluid's) lets the gate's surface rows ring until the gate breaks at 0.31 s.
  T artificial_viscosity{T(0.1)};
  T min_shepard{T(0.1)};  ///< Shepard sum below which the interface point has no fluid (no force), (0, 1)

  void validate() const {
    require_in_open_range("InterfacePressure::min_shepard", min_shepard, T(0), T(1));
    require_in_range("InterfacePressure::artificial_viscosity (alpha)", artificial_viscosity, T(0), T(5));
  }

  template <class System, class Solid>
  void apply(System& system, const Solid& solid, T /*time*/) const {
    if (form == InterfaceForm::integral) apply_integral(system, solid);
    else apply_surface_mirror(system, solid);
  }

 private:
  /// p_int (12) at the interface point x_int of surface particle slot a and, if grad_sum is given, sum_f V_f
  /// grad W(x_int - x_f) (11). Returns false where the Shepard sum is below min_shepard (no fluid at the point).
  template <class System, class Vector>
  bool interface_pressure(const System& system, std::size_t a, const Vector& x_int, T& p_int,
                          Vector* grad_sum = nullptr) const {
    const auto& p = system.particles();
    const auto& kernel = system.kernel();
    const T support = static_cast<T>(System::kernel_type::support);
    T shepard = 0, pressure_sum = 0;
    if (grad_sum) *grad_sum = Vector::Zero();
    system.for_each_neighbor(a, [&](std::size_t f, const Vector&, T, T h) {
      if (p.kind[f] != Kind::fluid) return;
      const Vector dx = x_int - p.position[f];
      const T r = dx.norm();
      if (r >= support * h) return;
      const T V = p.mass[f] / p.density[f];
      const T w = V * kernel.value(r, h);
      shepard += w;
      pressure_sum += w * p.pressure[f];
      if (grad_sum) *grad_sum += V * kernel_gradient(kernel, dx, r, h);
    });
    if (shepard < min_shepard) return false;
    p_int = pressure_sum / shepard;
    return true;
  }

  template <class System, class Solid>
  void apply_integral(System& system, const Solid& solid) const {
    using Vector = Vec<System::dimension, T>;
    auto& p = system.particles();
    const auto& kernel = system.kernel();
    const auto& ids = solid.particle_ids();
    // Scratch kept between calls (the coupling itself must stay a trivially copyable parameter struct).
    thread_local std::vector<char> surface;
    thread_local std::vector<T> nearest, fluid_p_int;
    thread_local std::vector<std::size_t> touched;
    update_solid_surface(system, ids, solid.body(), surface);
    const T d = solid.reference_spacing();
    const T infinity = std::numeric_limits<T>::infinity();
    if (nearest.size() < p.size()) {
      nearest.assign(p.size(), infinity);
      fluid_p_int.assign(p.size(), T(0));
    }
    // 1. The pressure of each interface point (12), handed to the fluid particles for which it is the nearest.
    touched.clear();
    for (std::size_t k = 0; k < ids.size(); ++k) {
      if (!surface[k]) continue;
      const std::size_t s = p.slot_of_id(ids[k]);
      const Vector x_int = p.position[s] + T(0.5) * d * p.normal[s];  // (7), rl = 0
      T p_int = 0;
      if (!interface_pressure(system, s, x_int, p_int)) continue;
      system.for_each_neighbor(s, [&](std::size_t f, const Vector&, T, T) {
        if (p.kind[f] != Kind::fluid) return;
        const T r = (p.position[f] - x_int).squaredNorm();
        if (nearest[f] == infinity) touched.push_back(f);
        if (r < nearest[f]) {
          nearest[f] = r;
          fluid_p_int[f] = p_int;
        }
      });
    }
    // 2. Every solid-fluid pair within the kernel support: the surface integral (10-11) and its reaction (14-16),
    //    and the kinematic condition (3) in the fluid's continuity equation.
    for (const std::uint32_t id : ids) {
      const std::size_t a = p.slot_of_id(id);
      const T V_a = p.mass[a] / p.density[a];
      system.for_each_neighbor(a, [&](std::size_t f, const Vector& dx_af, T r, T h) {
        if (p.kind[f] != Kind::fluid || nearest[f] == infinity) return;
        const T V_f = p.mass[f] / p.density[f];
        const Vector grad = kernel_gradient(kernel, dx_af, r, h);  // grad_a W(x_a - x_f)
        Vector pair = (T(2) * fluid_p_int[f] * V_a * V_f) * grad;  // N (N/m in 2D)
        const Vector v_af = p.velocity[a] - p.velocity[f];
        const T vr = v_af.dot(dx_af);
        if (vr < T(0) && artificial_viscosity > T(0)) {  // Monaghan (1992) viscosity of the pair, as at walls
          const T mu = h * vr / (r * r + T(0.01) * h * h);
          const T c = T(0.5) * (p.sound_speed[f] + system.eos().reference_sound_speed());
          pair += (-artificial_viscosity * c * mu * p.density[f] * V_a * V_f) * grad;
        }
        p.acceleration[a] -= pair / p.mass[a];                     // (10-11, 13): pushes a away from f
        p.acceleration[f] += pair / p.mass[f];                     // (14-16): pushes f away from a
        p.density_rate[f] += p.density[f] * V_a * v_af.dot(grad);  // (3): rho_f V_a (v_f - v_a) . grad_f W
      });
    }
    for (const std::size_t f : touched) nearest[f] = infinity;
  }

  template <class System, class Solid>
  void apply_surface_mirror(System& system, const Solid& solid) const {
    using Vector = Vec<System::dimension, T>;
    auto& p = system.particles();
    const auto& kernel = system.kernel();
    const auto& ids = solid.particle_ids();
    std::vector<char> surface;
    update_solid_surface(system, ids, solid.body(), surface);
    const T d = solid.reference_spacing();
    const T support = static_cast<T>(System::kernel_type::support);
    std::vector<std::size_t> fluid;
    std::vector<T> weight;
    for (std::size_t k = 0; k < ids.size(); ++k) {
      if (!surface[k]) continue;
      const std::size_t a = p.slot_of_id(ids[k]);
      const Vector n = p.normal[a];
      const Vector x_int = p.position[a] + T(0.5) * d * n;  // (7), rl = 0
      const Vector x_mirror = p.position[a] + d * n;        // mirror of a about the interface
      T p_int = 0;
      Vector grad_sum;
      if (!interface_pressure(system, a, x_int, p_int, &grad_sum)) continue;
      // Fluid particles around the mirror point: the neighbours of a.
      T reaction_norm = 0;
      fluid.clear();
      weight.clear();
      system.for_each_neighbor(a, [&](std::size_t f, const Vector&, T, T h) {
        if (p.kind[f] != Kind::fluid) return;
        const T rm = (p.position[f] - x_mirror).norm();
        if (rm >= support * h) return;
        const T wm = p.mass[f] / p.density[f] * kernel.value(rm, h);
        if (wm <= T(0)) return;
        fluid.push_back(f);
        weight.push_back(wm);
        reaction_norm += wm;
      });
      if (reaction_norm <= T(0)) continue;
      const Vector force_density = -p_int * grad_sum;                   // (11), N/m^3
      const Vector force = (p.mass[a] / p.density[a]) * force_density;  // V_a F_a, N (N/m in 2D)
      p.acceleration[a] += force / p.mass[a];                           // (13)
      for (std::size_t j = 0; j < fluid.size(); ++j)                    // (14-16), normalised
        p.acceleration[fluid[j]] -= (weight[j] / reaction_norm) * force / p.mass[fluid[j]];
    }
  }
};

}  // namespace sphfsi
