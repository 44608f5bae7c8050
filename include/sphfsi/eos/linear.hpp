// sphfsi: linear (weakly compressible, isothermal) equation of state (Morris, Fox & Zhu 1997):
//   p = c0^2 (rho - rho0),  c = c0.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/eos/concepts.hpp>

namespace sphfsi {

template <Real T>
struct LinearEos {
  T rho0{1000};  ///< reference density, kg/m^3
  T c0{10};      ///< sound speed, m/s

  LinearEos() = default;
  LinearEos(T reference_density, T reference_sound_speed) : rho0(reference_density), c0(reference_sound_speed) {
    require_positive("LinearEos::rho0 (reference density, kg/m^3)", rho0);
    require_positive("LinearEos::c0 (sound speed, m/s)", c0);
  }

  T pressure(T rho) const { return c0 * c0 * (rho - rho0); }
  T sound_speed(T) const { return c0; }
  T density(T p) const { return rho0 + p / (c0 * c0); }
  T reference_density() const { return rho0; }
  T reference_sound_speed() const { return c0; }
};

}  // namespace sphfsi
