// sphfsi: coupling approach 1 of the reference paper (eqs 1-2): stress continuity.
//
// Near the interface (within the kernel support) fluid and solid particles sum over all particles regardless of
// kind: the fluid's stress is -p I, the solid's its Cauchy stress sigma, and each fluid-solid pair contributes
//   dv_a/dt += m_b (sigma_a / rho_a^2 + sigma_b / rho_b^2 - Pi_ab I) . grad_a W_ab          (eq. 13 form)
//   drho_a/dt += m_b v_ab . grad_a W_ab                                                     (fluid continuity)
// to both particles with opposite signs (grad_b W_ba = -grad_a W_ab), which enforces u_f = u_s (1) and
// sigma_s n = -sigma_f n (2) in the SPH sense. XSPH with the solid's velocity keeps fluid particles from
// interpenetrating the solid (the paper's remedy). Pair forces are antisymmetric: momentum is conserved to round-off.
// The reference paper reports that this approach deforms the plate permanently and breaks it (Figure 3, 5).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace sphfsi {

template <Real T>
struct StressContinuity {
  static constexpr const char* name = "stress-continuity";
  T artificial_viscosity{T(0.1)};  ///< alpha of the fluid-solid artificial viscosity, [0, 5]
  T xsph{T(0.5)};                  ///< epsilon of the fluid-solid XSPH correction, [0, 1)

  void validate() const {
    require_in_range("StressContinuity::artificial_viscosity (alpha)", artificial_viscosity, T(0), T(5));
    require_in_range("StressContinuity::xsph (epsilon)", xsph, T(0), T(0.999));
  }

  /// The fluid particles next to the solid feel the solid's stress directly, so the fluid step must resolve the
  /// solid's sound speed there: h / (c_solid + c_fluid) over the solid's particles (without the CFL factor).
  template <class System, class Solid>
  T stable_time_step(const System& system, const Solid& solid) const {
    const auto& p = system.particles();
    T dt = std::numeric_limits<T>::infinity();
    const T c_fluid = system.eos().reference_sound_speed();
    const T c_solid = solid.material().p_wave_speed();
    for (const std::uint32_t id : solid.particle_ids())
      dt = std::min(dt, p.smoothing_length[p.slot_of_id(id)] / (c_solid + c_fluid));
    return dt;
  }

  template <class System, class Solid>
  void apply(System& system, const Solid& solid, T /*time*/) const {
    using Vector = Vec<System::dimension, T>;
    using Matrix = Mat<System::dimension, T>;
    auto& p = system.particles();
    const auto& kernel = system.kernel();
    for (const std::uint32_t id : solid.particle_ids()) {
      const std::size_t s = p.slot_of_id(id);
      const Matrix sigma_s = solid.cauchy_stress(id) / (p.density[s] * p.density[s]);
      const T ms = p.mass[s];
      system.for_each_neighbor(s, [&](std::size_t f, const Vector& dx_sf, T r, T h) {
        if (p.kind[f] != Kind::fluid) return;
        const Vector dx = -dx_sf;                               // x_f - x_s
        const Vector grad = kernel_gradient(kernel, dx, r, h);  // grad_f W_fs
        const Vector vfs = p.velocity[f] - p.velocity[s];
        const T rho_f = p.density[f];
        const T vr = vfs.dot(dx);
        T pi = T(0);
        if (vr < T(0)) {
          const T mu = h * vr / (r * r + T(0.01) * h * h);
          pi = -artificial_viscosity * T(0.5) * (p.sound_speed[f] + p.sound_speed[s]) * mu /
               (T(0.5) * (rho_f + p.density[s]));
        }
        const Matrix stress = (-p.pressure[f] / (rho_f * rho_f) - pi) * Matrix::Identity() + sigma_s;
        const Vector pair = stress * grad;  // per unit mass of the partner
        p.acceleration[f] += ms * pair;
        p.acceleration[s] -= p.mass[f] * pair;
        p.density_rate[f] += ms * vfs.dot(grad);
        if (xsph > T(0))
          p.xsph_velocity[f] -= (xsph * ms / (T(0.5) * (rho_f + p.density[s])) * kernel.value(r, h)) * vfs;
      });
    }
  }
};

}  // namespace sphfsi
