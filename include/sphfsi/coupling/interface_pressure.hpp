// sphfsi: coupling approach 2 of the reference paper (eqs 3-16; Antoci, Gallati & Sibilla 2007, Comput. Struct.
// 85:879, with the surface integral of Ha et al. 2011): interface-point pressure.
//
// For every surface particle a of the solid (outward normal n_a, solid_surface.hpp; eqs 5-6):
//   interface point     x_int = x_a + (rl + 1/2) d n_a, rl = 0 for the surface row             (7)
//   interface pressure  p_int = sum_f V_f p_f W(x_int - x_f) / sum_f V_f W(x_int - x_f)          (12)
//   force on the solid  F_a = -p_int sum_f V_f grad W(x_int - x_f)   (per unit volume)            (10-11)
//                       dv_a/dt += F_a / rho_a                                                    (13)
//   reaction            -V_a F_a, spread over the fluid particles f around the mirror point
//                       x_a* = x_a + 2 (rl + 1/2) d n_a with weights V_f W(x_f - x_a*)            (14-16)
// sphfsi normalises the reaction weights (Shepard) so that the reaction equals the action exactly and momentum is
// conserved to round-off; eq. 15 as printed only does so on a full kernel support. Fluid and solid particles do not
// otherwise interact: the reference paper reports that fluid passes through the frond with this approach.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/coupling/solid_surface.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace sphfsi {

template <Real T>
struct InterfacePressure {
  static constexpr const char* name = "interface-pressure";
  T min_shepard{T(0.1)};  ///< Shepard sum below which the interface point has no fluid (no force), (0, 1)

  void validate() const { require_in_open_range("InterfacePressure::min_shepard", min_shepard, T(0), T(1)); }

  template <class System, class Solid>
  void apply(System& system, const Solid& solid, T /*time*/) const {
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
      // Fluid particles near the interface and mirror points: the neighbours of a within one extra support.
      T shepard = 0, pressure_sum = 0, reaction_norm = 0;
      Vector grad_sum = Vector::Zero();
      fluid.clear();
      weight.clear();
      const T h_a = p.smoothing_length[a];
      system.for_each_neighbor(a, [&](std::size_t f, const Vector&, T, T) {
        if (p.kind[f] != Kind::fluid) return;
        const T h = T(0.5) * (h_a + p.smoothing_length[f]);
        const T V = p.mass[f] / p.density[f];
        const Vector dx = x_int - p.position[f];
        const T r = dx.norm();
        if (r < support * h) {
          const T w = V * kernel.value(r, h);
          shepard += w;
          pressure_sum += w * p.pressure[f];
          grad_sum += V * kernel_gradient(kernel, dx, r, h);
        }
        const T rm = (p.position[f] - x_mirror).norm();
        const T wm = rm < support * h ? V * kernel.value(rm, h) : T(0);
        if (wm > T(0)) {
          fluid.push_back(f);
          weight.push_back(wm);
          reaction_norm += wm;
        }
      });
      if (shepard < min_shepard || reaction_norm <= T(0)) continue;
      const T p_int = pressure_sum / shepard;                           // (12)
      const Vector force_density = -p_int * grad_sum;                   // (11), N/m^3
      const Vector force = (p.mass[a] / p.density[a]) * force_density;  // V_a F_a, N (N/m in 2D)
      p.acceleration[a] += force / p.mass[a];                           // (13)
      for (std::size_t j = 0; j < fluid.size(); ++j)                    // (14-16), normalised
        p.acceleration[fluid[j]] -= (weight[j] / reaction_norm) * force / p.mass[fluid[j]];
    }
  }
};

}  // namespace sphfsi
