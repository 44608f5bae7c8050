// sphfsi: weakly-compressible SPH fluid (Monaghan 1994, J. Comput. Phys. 110:399) with walls.
//
// For a fluid particle a and its neighbours b (x_ab = x_a - x_b, v_ab = v_a - v_b, grad = grad_a W(r, h_ab)):
//   continuity     drho_a/dt = sum_b m_b v_ab . grad                                        (Monaghan 1992, 2.13)
//   momentum       dv_a/dt   = -sum_b m_b (p_a/rho_a^2 + p_b/rho_b^2 + Pi_ab) grad + g        (Monaghan 1992, 3.3)
//   art. viscosity Pi_ab = -alpha c_ab mu_ab / rho_ab,  mu_ab = h v_ab.x_ab / (r^2 + 0.01 h^2), v_ab.x_ab < 0
//                                                                                            (Monaghan 1992, 4.1)
//   laminar visc.  dv_a/dt += sum_b m_b nu (rho_a + rho_b)/(rho_a rho_b) x_ab.grad/(r^2 + eta^2) v_ab
//                                                                            (Morris, Fox & Zhu 1997, eq. 8)
//   delta-SPH      drho_a/dt += delta h c0 sum_b V_b 2 (rho_ab - rho_ab^H) x_ab.grad / (r^2 + eta^2)
//                  (Molteni & Colagrossi 2009, Comput. Phys. Commun. 180:861, with the hydrostatic correction
//                   rho_ab^H = rho0 g.x_ab / c0^2 of Fourtakas et al. 2019, Comput. Fluids 190:346, linearised;
//                   fluid-fluid pairs only)
//   XSPH           dx_a/dt = v_a + eps sum_b (m_b / rho_ab) (v_b - v_a) W_ab             (Monaghan 1989)
// Walls:
//   dynamic boundary particles (Crespo, Gomez-Gesteira & Dalrymple 2007, CMC 5:173; the SPHysics default):
//     wall particles obey the continuity equation with their fluid neighbours and enter the fluid's
//     pressure and viscosity sums; their density is kept >= rho0 so walls never attract fluid.
//   repulsive walls (Monaghan & Kos 1999, with Rogers & Dalrymple 2008): see boundary/repulsive_force.hpp;
//     wall particles only push the fluid along their normal and take no part in the SPH sums.
// Solid particles are skipped here: a coupling policy owns fluid-solid pairs. Contract with the solid models:
// compute_rates() zeroes the acceleration of solid particles; couplings (ParticleModels evaluated after the
// fluid) add the fluid-on-solid force per unit mass there; the solid model adds its internal forces and gravity
// when it advances its particles (possibly in several sub-steps).
#pragma once

#include <sphfsi/boundary/repulsive_force.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace sphfsi {

/// How wall particles act on the fluid.
enum class WallModel {
  dynamic,    ///< dynamic boundary particles (SPHysics default)
  repulsive,  ///< Monaghan-Kos repulsive force
};

template <int Dim, Real T>
struct FluidParameters {
  Vec<Dim, T> gravity = default_gravity();  ///< m/s^2
  T artificial_viscosity{T(0.01)};          ///< alpha of Monaghan's artificial viscosity, [0, 1]
  T density_diffusion{T(0.1)};              ///< delta of delta-SPH, [0, 1] (0 switches it off)
  T xsph{T(0)};                             ///< epsilon of XSPH, [0, 1)
  T kinematic_viscosity{T(0)};              ///< laminar viscosity nu, m^2/s (0: none)
  WallModel walls{WallModel::dynamic};
  RepulsiveForceParameters<T> repulsive{};  ///< used when walls == repulsive

  static Vec<Dim, T> default_gravity() {
    Vec<Dim, T> g = Vec<Dim, T>::Zero();
    g[Dim - 1] = T(-9.81);
    return g;
  }

  void validate() const {
    for (int d = 0; d < Dim; ++d) require_finite("FluidParameters::gravity", gravity[d]);
    require_in_range("FluidParameters::artificial_viscosity (alpha)", artificial_viscosity, T(0), T(1));
    require_in_range("FluidParameters::density_diffusion (delta)", density_diffusion, T(0), T(1));
    require_in_range("FluidParameters::xsph (epsilon)", xsph, T(0), T(0.999));
    require_non_negative("FluidParameters::kinematic_viscosity (m^2/s)", kinematic_viscosity);
    if (walls == WallModel::repulsive)
      require_positive("FluidParameters::repulsive.boundary_spacing (m)", repulsive.boundary_spacing);
  }
};

/// Computes the fluid and wall rates of a ParticleSystem and the fluid's stable time step.
template <class System>
class WcsphFluid {
 public:
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;

  explicit WcsphFluid(const FluidParameters<Dim, T>& params) : params_(params) { params_.validate(); }

  const FluidParameters<Dim, T>& parameters() const noexcept { return params_; }

  /// Per-slot signal speed max_b |mu_ab| of the last evaluation (part of the time-step state; checkpoints save it).
  const std::vector<T>& signal_speeds() const noexcept { return signal_speed_; }
  /// Restores the signal speeds saved with signal_speeds() (io/checkpoint.hpp).
  void restore_signal_speeds(std::vector<T> speeds) { signal_speed_ = std::move(speeds); }

  /// Overwrites acceleration, density_rate and xsph_velocity of fluid and wall particles
  /// (pressure and sound speed must be current: System::update_pressure()).
  void compute_rates(System& system) {
    auto& p = system.particles();
    const auto& kernel = system.kernel();
    const T rho0 = system.eos().reference_density();
    const T c0 = system.eos().reference_sound_speed();
    const Vector g = params_.gravity;
    const T alpha = params_.artificial_viscosity;
    const T delta = params_.density_diffusion;
    const T eps_xsph = params_.xsph;
    const T nu = params_.kinematic_viscosity;
    const bool dynamic_walls = params_.walls == WallModel::dynamic;
    const int up = params_.repulsive.vertical_axis;
    signal_speed_.assign(p.size(), T(0));

    parallel_for(p.size(), [&](std::size_t a) {
      const Kind ka = p.kind[a];
      if (ka == Kind::solid) {  // external (fluid-on-solid) forces start from zero; couplings add to them
        p.acceleration[a] = Vector::Zero();
        p.density_rate[a] = T(0);
        p.xsph_velocity[a] = Vector::Zero();
        return;
      }
      Vector acc = Vector::Zero(), xsph = Vector::Zero();
      T drho = T(0), mu_max = T(0);
      const Vector xa = p.position[a], va = p.velocity[a];
      const T rho_a = p.density[a], pa = p.pressure[a], ca = p.sound_speed[a];
      const T pa_over_rho2 = pa / (rho_a * rho_a);

      if (ka == Kind::wall) {
        if (dynamic_walls) {
          system.for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T h) {
            if (p.kind[b] != Kind::fluid) return;
            drho += p.mass[b] * (va - p.velocity[b]).dot(kernel_gradient(kernel, dx, r, h));
          });
        }
        p.density_rate[a] = drho;
        p.acceleration[a] = Vector::Zero();
        p.xsph_velocity[a] = Vector::Zero();
        return;
      }

      system.for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T h) {
        const Kind kb = p.kind[b];
        if (kb == Kind::solid) return;
        const Vector vab = va - p.velocity[b];
        if (kb == Kind::wall && !dynamic_walls) {
          acc += repulsive_force<Dim, T>(dx, vab, p.normal[b], h, c0, xa[up] - params_.repulsive.water_level,
                                         params_.repulsive);
          return;
        }
        const Vector grad = kernel_gradient(kernel, dx, r, h);
        const T mb = p.mass[b], rho_b = p.density[b];
        const T eta2 = T(0.01) * h * h;
        const T vr = vab.dot(dx);
        const T mu = h * vr / (r * r + eta2);
        mu_max = std::max(mu_max, std::abs(mu));
        drho += mb * vab.dot(grad);
        T pi_ab = T(0);
        if (vr < T(0)) pi_ab = -alpha * T(0.5) * (ca + p.sound_speed[b]) * mu / (T(0.5) * (rho_a + rho_b));
        acc -= mb * (pa_over_rho2 + p.pressure[b] / (rho_b * rho_b) + pi_ab) * grad;
        if (nu > T(0)) acc += (mb * nu * (rho_a + rho_b) / (rho_a * rho_b) * dx.dot(grad) / (r * r + eta2)) * vab;
        if (kb == Kind::fluid) {
          if (delta > T(0)) {
            const T hydrostatic = rho0 * g.dot(dx) / (c0 * c0);
            drho += delta * h * c0 * (mb / rho_b) * T(2) * ((rho_a - rho_b) - hydrostatic) * dx.dot(grad) /
                    (r * r + eta2);
          }
          if (eps_xsph > T(0))
            xsph -= (eps_xsph * mb / (T(0.5) * (rho_a + rho_b)) * kernel.value(r, h)) * vab;
        }
      });
      p.acceleration[a] = acc + g;
      p.density_rate[a] = drho;
      p.xsph_velocity[a] = xsph;
      signal_speed_[a] = mu_max;
    });
  }

  /// Stable time step of the last evaluated rates (Monaghan & Kos 1999; SPHysics): min of
  ///   force      sqrt(h / |a|),   acoustic/viscous   h / (c + max_b |mu_ab|),   laminar   h^2 / (8 nu),
  /// without the CFL factor (the integrator applies it).
  T stable_time_step(const System& system) const {
    const auto& p = system.particles();
    const T inf = std::numeric_limits<T>::max();
    const T nu = params_.kinematic_viscosity;
    return parallel_min(p.size(), inf, [&](std::size_t a) {
      if (p.kind[a] != Kind::fluid) return inf;
      const T h = p.smoothing_length[a];
      const T f = p.acceleration[a].norm();
      T dt = f > T(0) ? std::sqrt(h / f) : inf;
      dt = std::min(dt, h / (p.sound_speed[a] + (a < signal_speed_.size() ? signal_speed_[a] : T(0))));
      if (nu > T(0)) dt = std::min(dt, T(0.125) * h * h / nu);
      return dt;
    });
  }

 private:
  FluidParameters<Dim, T> params_;
  std::vector<T> signal_speed_;
};

}  // namespace sphfsi
