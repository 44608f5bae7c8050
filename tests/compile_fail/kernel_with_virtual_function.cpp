// Compile-fail test (tests/compile_fail/tests.cmake): a kernel with a virtual function is not trivially
// copyable, so it cannot be captured by value in a parallel (or GPU) loop, and the SmoothingKernel concept must
// reject it. Built with SPHFSI_COMPILE_FAIL defined the kernel gets a virtual destructor and the build must fail
// naming the concept; built without it (the control) the same file must compile.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>

/// A user's kernel that wraps the 3D Wendland C2 kernel, written in an object-oriented style.
struct WrappedWendland {
  static constexpr int dimension = 3;
  static constexpr double support = sphfsi::WendlandC2<3>::support;
#ifdef SPHFSI_COMPILE_FAIL
  virtual ~WrappedWendland() = default;
#endif
  template <class T>
  T value(T r, T h) const {
    return sphfsi::WendlandC2<3>{}.value(r, h);
  }
  template <class T>
  T derivative(T r, T h) const {
    return sphfsi::WendlandC2<3>{}.derivative(r, h);
  }
};

std::size_t build_scene() {
  using Vector = sphfsi::Vec<3, float>;
  sphfsi::ParticleSystem<3, float, WrappedWendland, sphfsi::Tait<float>> system(
      sphfsi::Domain<3, float>(Vector::Zero(), Vector::Ones()), sphfsi::Tait<float>(1000.0f, 20.0f));
  return system.size();
}
