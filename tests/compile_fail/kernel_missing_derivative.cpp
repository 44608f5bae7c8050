// Compile-fail test (tests/compile_fail/tests.cmake): a kernel without derivative() must be rejected by the
// SmoothingKernel concept when it is plugged into a ParticleSystem. Built with SPHFSI_COMPILE_FAIL defined the
// member is left out and the build must fail naming the concept; built without it (the control) the same file
// must compile, so the failure can only come from the missing member.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/linear.hpp>

#include <algorithm>
#include <numbers>

/// A user's kernel: the 2D cubic spline written out by hand (Monaghan & Lattanzio 1985).
struct HandWrittenKernel {
  static constexpr int dimension = 2;
  static constexpr double support = 2.0;
  template <class T>
  T value(T r, T h) const {
    const T q = r / h, a = std::max(T(2) - q, T(0)), b = std::max(T(1) - q, T(0));
    return T(10) / (T(7) * std::numbers::pi_v<T> * h * h) * (T(0.25) * a * a * a - b * b * b);
  }
#ifndef SPHFSI_COMPILE_FAIL
  template <class T>
  T derivative(T r, T h) const {
    const T q = r / h, a = std::max(T(2) - q, T(0)), b = std::max(T(1) - q, T(0));
    return T(10) / (T(7) * std::numbers::pi_v<T> * h * h * h) * (T(-0.75) * a * a + T(3) * b * b);
  }
#endif
};

std::size_t build_scene() {
  using Vector = sphfsi::Vec<2, double>;
  sphfsi::ParticleSystem<2, double, HandWrittenKernel, sphfsi::LinearEos<double>> system(
      sphfsi::Domain<2, double>(Vector::Zero(), Vector::Ones()), sphfsi::LinearEos<double>(1000.0, 20.0));
  return system.size();
}
