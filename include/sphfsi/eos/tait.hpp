// sphfsi: Tait / Cole equation of state (Cole 1948; Monaghan 1994, J. Comput. Phys. 110:399, eq. 3.4;
// Batchelor 1967), the SPHysics default:
//   p = B [ (rho / rho0)^gamma - 1 ],  B = c0^2 rho0 / gamma,  c^2 = c0^2 (rho / rho0)^(gamma - 1).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/eos/concepts.hpp>

#include <cmath>

namespace sphfsi {

template <Real T>
struct Tait {
  T rho0{1000};  ///< reference density, kg/m^3
  T c0{10};      ///< reference sound speed, m/s
  T gamma{7};    ///< polytropic exponent (7 for water)

  Tait() = default;
  Tait(T reference_density, T reference_sound_speed, T polytropic_exponent = T(7))
      : rho0(reference_density), c0(reference_sound_speed), gamma(polytropic_exponent) {
    require_positive("Tait::rho0 (reference density, kg/m^3)", rho0);
    require_positive("Tait::c0 (reference sound speed, m/s)", c0);
    require_in_range("Tait::gamma (polytropic exponent)", gamma, T(1), T(10));
  }

  T stiffness() const { return c0 * c0 * rho0 / gamma; }  // B, Pa
  T pressure(T rho) const { return stiffness() * (std::pow(rho / rho0, gamma) - T(1)); }
  T sound_speed(T rho) const { return c0 * std::pow(rho / rho0, T(0.5) * (gamma - T(1))); }
  T density(T p) const { return rho0 * std::pow(p / stiffness() + T(1), T(1) / gamma); }
  T reference_density() const { return rho0; }
  T reference_sound_speed() const { return c0; }
};

}  // namespace sphfsi
