// sphfsi: a wave-absorbing damping zone at the end of a flume, as a ParticleModel.
//
// After every step, fluid particles with x in [x_start, x_end] have their velocity relaxed towards rest:
//   v <- v exp(-beta s(x)^2 dt),   s = (x - x_start) / (x_end - x_start) in [0, 1]  (s = 1 beyond x_end),
// so the relaxation rate grows smoothly from 0 at the entrance (limiting the reflection from the zone's edge) to
// beta at its end. This is the velocity-reduction damping zone of DualSPHysics (Altomare et al. 2017, Coastal Eng.
// 127:37, sec. 2.4), which reduces the velocity by the factor 1 - dt beta s^n each step; the exponential form used
// here equals it to first order in dt and stays in (0, 1] for any step. A zone about one wavelength long with
// beta ~ 10 /s (several wave periods of relaxation at the end) absorbs most of the incident energy; docs/flume.md
// measures the reflection. The model keeps no state (checkpoint_stateless).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>

#include <cmath>
#include <limits>

namespace sphfsi::waves {

template <Real T>
struct DampingZone {
  static constexpr bool checkpoint_stateless = true;

  T x_start{0};              ///< entrance of the zone (no damping there), m
  T x_end{1};                ///< end of the ramp (full rate beyond), m
  T relaxation_rate{T(10)};  ///< beta, 1/s

  void validate() const {
    require_finite("DampingZone::x_start (m)", x_start);
    if (!(x_end > x_start))
      throw InputError(fmt::format("DampingZone::x_end = {} m must be greater than x_start = {} m", x_end, x_start));
    require_in_range("DampingZone::relaxation_rate (beta, 1/s)", relaxation_rate, T(0), T(1e6));
  }

  /// Relaxation rate at x, 1/s.
  T rate(T x) const {
    if (x <= x_start) return T(0);
    const T s = std::min((x - x_start) / (x_end - x_start), T(1));
    return relaxation_rate * s * s;
  }

  template <class System>
  void compute_rates(System&, T) {}

  template <class System>
  T stable_time_step(const System&) const {
    return std::numeric_limits<T>::max();
  }

  template <class System>
  void advance(System& system, T, T dt) {
    auto& p = system.particles();
    parallel_for(p.size(), [&](std::size_t i) {
      if (p.kind[i] != Kind::fluid) return;
      const T beta = rate(p.position[i][0]);
      if (beta > T(0)) p.velocity[i] *= std::exp(-beta * dt);
    });
  }
};

}  // namespace sphfsi::waves
