// Compile-fail test (tests/compile_fail/tests.cmake): an equation of state without sound_speed() must be
// rejected by the EquationOfState concept when it is plugged into a ParticleSystem. Built with
// SPHFSI_COMPILE_FAIL defined the member is left out and the build must fail naming the concept; built without
// it (the control) the same file must compile.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>

#include <cmath>

/// A user's EOS: an isothermal ideal gas, p = c^2 (rho - rho0) written as a gauge pressure.
struct IsothermalGas {
  double rho0 = 1.2;  ///< kg/m^3
  double c = 340.0;   ///< m/s
  double pressure(double rho) const { return c * c * (rho - rho0); }
#ifndef SPHFSI_COMPILE_FAIL
  double sound_speed(double) const { return c; }
#endif
  double density(double p) const { return rho0 + p / (c * c); }
  double reference_density() const { return rho0; }
  double reference_sound_speed() const { return c; }
};

std::size_t build_scene() {
  using Vector = sphfsi::Vec<2, double>;
  sphfsi::ParticleSystem<2, double, sphfsi::CubicSpline<2>, IsothermalGas> system(
      sphfsi::Domain<2, double>(Vector::Zero(), Vector::Ones()), IsothermalGas{});
  return system.size();
}
