// sphfsi: the EquationOfState concept, the extension point for barotropic fluids.
//
// An equation of state is a small trivially copyable struct providing, for scalar T:
//   T pressure(T rho) const;           // p(rho), with p(reference_density()) == 0
//   T sound_speed(T rho) const;        // c(rho) = sqrt(dp/drho)
//   T density(T p) const;              // inverse of pressure(), used to initialise hydrostatic columns
//   T reference_density() const;       // rho0
//   T reference_sound_speed() const;   // c0 = sound_speed(rho0)
#pragma once

#include <sphfsi/core/types.hpp>

#include <concepts>
#include <type_traits>

namespace sphfsi {

template <class E, class T>
concept EquationOfState = std::is_trivially_copyable_v<E> && requires(const E& e, T rho) {
  { e.pressure(rho) } -> std::same_as<T>;
  { e.sound_speed(rho) } -> std::same_as<T>;
  { e.density(rho) } -> std::same_as<T>;
  { e.reference_density() } -> std::same_as<T>;
  { e.reference_sound_speed() } -> std::same_as<T>;
};

}  // namespace sphfsi
