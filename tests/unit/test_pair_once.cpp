// Pairs evaluated once: ParticleSystem::for_each_neighbor_once (half stencil) and WcsphFluid::compute_rates.
//
// compute_rates visits each neighbour pair once and applies it to both particles, with per-thread spill buffers
// for partners in another thread's slot range. Its rates must equal, to round-off, the WCSPH sums of
// fluid/wcsph.hpp written the plain way (every particle gathers over all its neighbours, brute force), for every
// term (pressure, artificial and laminar viscosity, delta-SPH, XSPH, dynamic and repulsive walls, solids left
// out), and must not depend on the thread count. Tolerance: 1e-9 of the largest value of each field in double
// (sums of about 20 terms that partly cancel lose a few digits, not 7).
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/linear.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/dam_break.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace {

using namespace sphfsi;

template <int D, class T>
struct PairCase {
  static constexpr int dimension = D;
  using scalar = T;
};

/// Largest |component| of a field, for relative comparisons.
template <class V>
double field_scale(const std::vector<V>& field) {
  double s = 0;
  for (const auto& v : field) {
    if constexpr (std::is_arithmetic_v<V>) s = std::max(s, std::abs(double(v)));
    else s = std::max(s, double(v.cwiseAbs().maxCoeff()));
  }
  return s;
}

/// Largest |a - b| over a field, divided by the field's scale.
template <class V>
double relative_difference(const std::vector<V>& a, const std::vector<V>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if constexpr (std::is_arithmetic_v<V>) d = std::max(d, std::abs(double(a[i]) - double(b[i])));
    else d = std::max(d, double((a[i] - b[i]).cwiseAbs().maxCoeff()));
  }
  const double s = std::max(field_scale(a), 1e-300);
  return d / s;
}

/// The WCSPH rates of fluid/wcsph.hpp, every particle gathering over all others (O(N^2)).
template <class System>
struct GatherRates {
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;
  std::vector<Vector> acceleration, xsph;
  std::vector<T> density_rate, signal_speed;

  GatherRates(const System& system, const FluidParameters<Dim, T>& f) {
    const auto& p = system.particles();
    const auto& kernel = system.kernel();
    const T rho0 = system.eos().reference_density(), c0 = system.eos().reference_sound_speed();
    const std::size_t n = p.size();
    acceleration.assign(n, Vector::Zero());
    xsph.assign(n, Vector::Zero());
    density_rate.assign(n, T(0));
    signal_speed.assign(n, T(0));
    const T support = static_cast<T>(System::kernel_type::support);
    for (std::size_t a = 0; a < n; ++a) {
      if (p.kind[a] == Kind::solid) continue;
      Vector acc = Vector::Zero();
      for (std::size_t b = 0; b < n; ++b) {
        const T h = T(0.5) * (p.smoothing_length[a] + p.smoothing_length[b]);
        const Vector dx = p.position[a] - p.position[b];
        const T r = dx.norm();
        if (b == a || !(r < support * h) || p.kind[b] == Kind::solid) continue;
        const Vector vab = p.velocity[a] - p.velocity[b];
        const Vector grad = kernel_gradient(kernel, dx, r, h);
        if (p.kind[a] == Kind::wall) {
          if (f.walls == WallModel::dynamic && p.kind[b] == Kind::fluid) density_rate[a] += p.mass[b] * vab.dot(grad);
          continue;
        }
        if (p.kind[b] == Kind::wall && f.walls == WallModel::repulsive) {
          acc +=
              repulsive_force<Dim, T>(dx, vab, p.normal[b], h, c0,
                                      p.position[a][f.repulsive.vertical_axis] - f.repulsive.water_level, f.repulsive);
          continue;
        }
        const T mb = p.mass[b], ra = p.density[a], rb = p.density[b];
        const T eta2 = T(0.01) * h * h;
        const T mu = h * vab.dot(dx) / (r * r + eta2);
        signal_speed[a] = std::max(signal_speed[a], std::abs(mu));
        density_rate[a] += mb * vab.dot(grad);
        const T pi = vab.dot(dx) < 0
                         ? -f.artificial_viscosity * (p.sound_speed[a] + p.sound_speed[b]) / 2 * mu / ((ra + rb) / 2)
                         : T(0);
        acc -= mb * (p.pressure[a] / (ra * ra) + p.pressure[b] / (rb * rb) + pi) * grad;
        acc += mb * f.kinematic_viscosity * (ra + rb) / (ra * rb) * dx.dot(grad) / (r * r + eta2) * vab;
        if (p.kind[b] == Kind::fluid) {
          const T hydrostatic = rho0 * f.gravity.dot(dx) / (c0 * c0);
          density_rate[a] +=
              f.density_diffusion * h * c0 * (mb / rb) * 2 * ((ra - rb) - hydrostatic) * dx.dot(grad) / (r * r + eta2);
          xsph[a] -= f.xsph * mb / ((ra + rb) / 2) * kernel.value(r, h) * vab;
        }
      }
      if (p.kind[a] == Kind::fluid) acceleration[a] = acc + f.gravity;
    }
  }
};

}  // namespace

TEMPLATE_TEST_CASE("for_each_neighbor_once visits every neighbour pair exactly once", "[neighbors]",
                   (PairCase<2, double>), (PairCase<3, double>), (PairCase<2, float>), (PairCase<3, float>)) {
  constexpr int Dim = TestType::dimension;
  using T = typename TestType::scalar;
  using Vector = Vec<Dim, T>;
  using System = ParticleSystem<Dim, T, CubicSpline<Dim>, LinearEos<T>>;
  const bool mixed_h = GENERATE(false, true);
  CAPTURE(Dim, sizeof(T), mixed_h);

  const Domain<Dim, T> domain(Vector::Constant(T(-0.2)), Vector::Constant(T(0.5)));
  System system(domain, LinearEos<T>(T(1000), T(20)));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const T h_max = T(0.04);
  for (int i = 0; i < (Dim == 2 ? 700 : 3000); ++i) {
    Vector x;
    for (int d = 0; d < Dim; ++d) x[d] = static_cast<T>(-0.2 + 0.7 * unit(rng));
    const T h = mixed_h ? h_max * static_cast<T>(0.3 + 0.7 * unit(rng)) : h_max;
    system.particles().add(Kind::fluid, x, Vector::Zero(), T(1000), T(1), h);
  }
  system.update_neighbors();
  CHECK(system.uniform_smoothing_length() == !mixed_h);
  const auto& p = system.particles();

  std::set<std::pair<std::uint32_t, std::uint32_t>> all, once;
  std::size_t repeated = 0, out_of_range = 0, bad_arguments = 0;
  for (std::size_t a = 0; a < p.size(); ++a) {
    system.for_each_neighbor(a, [&](std::size_t b, const Vector&, T, T) {
      all.insert({std::min(p.id[a], p.id[b]), std::max(p.id[a], p.id[b])});
    });
    system.for_each_neighbor_once(a, [&](std::size_t b, const Vector& dx, T r, T h) {
      if (!once.insert({std::min(p.id[a], p.id[b]), std::max(p.id[a], p.id[b])}).second) ++repeated;
      if (b <= a || b >= system.neighbor_once_end(a)) ++out_of_range;
      if (!(dx == p.position[a] - p.position[b]) || r != dx.norm() ||
          h != T(0.5) * (p.smoothing_length[a] + p.smoothing_length[b]))
        ++bad_arguments;
    });
  }
  CHECK(repeated == 0);
  CHECK(out_of_range == 0);
  CHECK(bad_arguments == 0);
  CHECK(all.size() > 2 * p.size());  // dense enough to test something: several neighbours per particle
  CHECK(once == all);
}

TEST_CASE("compute_rates with pairs evaluated once equals the plain WCSPH gather, for any thread count", "[fluid]") {
  using T = double;
  using System = ParticleSystem<2, T, WendlandC2<2>, Tait<T>>;
  const bool repulsive = GENERATE(false, true);
  CAPTURE(repulsive);

  scenes::DamBreakGeometry<T> scene;
  scene.particles_across = 14;
  scene.walls = repulsive ? WallModel::repulsive : WallModel::dynamic;
  System system(scenes::dam_break_domain(scene), Tait<T>(1000, scene.sound_speed()));
  scenes::build_dam_break(system, scene);
  auto& p = system.particles();
  // A few solid particles inside the column (left out of the fluid sums) and a disturbed state, so that every
  // term is non-zero: random velocities, densities within +-2 %.
  for (int k = 0; k < 5; ++k)
    p.add(Kind::solid, Vec<2, T>(0.2 * scene.a(), (0.2 + 0.1 * k) * scene.height()), Vec<2, T>::Zero(), 1000, p.mass[0],
          p.smoothing_length[0]);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] == Kind::fluid) p.velocity[i] = Vec<2, T>(unit(rng), unit(rng)) * 0.3;
    if (p.kind[i] != Kind::solid) p.density[i] *= 1 + 0.02 * unit(rng);
  }
  FluidParameters<2, T> f = scenes::dam_break_fluid(scene);
  f.artificial_viscosity = 0.05;
  f.xsph = 0.5;
  f.kinematic_viscosity = 1e-3;
  WcsphFluid<System> fluid(f);

  system.update_neighbors();
  system.update_pressure();
  const GatherRates<System> reference(system, f);
  const int threads_before = thread_count();
  for (int threads : {1, 2, 3}) {
    CAPTURE(threads);
    set_thread_count(threads);
    fluid.compute_rates(system);
    // compute_rates writes by slot; the reference was computed on the same (already sorted) slots.
    CHECK(relative_difference(p.acceleration, reference.acceleration) < 1e-9);
    CHECK(relative_difference(p.density_rate, reference.density_rate) < 1e-9);
    CHECK(relative_difference(p.xsph_velocity, reference.xsph) < 1e-9);
    CHECK(relative_difference(fluid.signal_speeds(), reference.signal_speed) < 1e-9);
    std::size_t solid_rates = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::solid && (p.acceleration[i].norm() > 0 || p.density_rate[i] != 0)) ++solid_rates;
    CHECK(solid_rates == 0);
  }
  set_thread_count(threads_before);
  CHECK(field_scale(reference.xsph) > 0);
  CHECK(field_scale(reference.density_rate) > 0);
}
