// Property tests of every equation of state (one TEMPLATE_TEST_CASE over Tait and LinearEos, float and double).
//
// A barotropic EOS for weakly compressible SPH must give zero (gauge) pressure at the reference density, a
// pressure that increases with density, a sound speed with c^2 = dp/drho, and an inverse density(p) used to
// initialise hydrostatic columns (Monaghan 1994, J. Comput. Phys. 110:399, sec. 3). Tolerances are the
// finite-difference and round-off errors derived next to each check.
#include <sphfsi/core/error.hpp>
#include <sphfsi/eos/concepts.hpp>
#include <sphfsi/eos/linear.hpp>
#include <sphfsi/eos/tait.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <type_traits>

namespace {

using namespace sphfsi;

template <class E>
struct scalar_of;
template <Real T>
struct scalar_of<Tait<T>> {
  using type = T;
  template <class U>
  using with = Tait<U>;
};
template <Real T>
struct scalar_of<LinearEos<T>> {
  using type = T;
  template <class U>
  using with = LinearEos<U>;
};

/// Largest |d^3 p / d rho^3| on [lo, hi] of the double-precision twin of the EOS (third differences with
/// step 1e-3 rho0: O(step^2) accurate, and the 1.25 margin used below covers it).
template <class E>
double max_third_derivative(const E& eos, double lo, double hi) {
  const double step = 1e-3 * eos.reference_density();
  double m = 0;
  for (int k = 0; k <= 200; ++k) {
    const double rho = lo + (hi - lo) * k / 200.0;
    const double d3 = (eos.pressure(rho + 2 * step) - 2 * eos.pressure(rho + step) + 2 * eos.pressure(rho - step) -
                       eos.pressure(rho - 2 * step)) /
                      (2 * step * step * step);
    m = std::max(m, std::abs(d3));
  }
  return m;
}

}  // namespace

// Concept checks: the shipped EOS satisfy EquationOfState; an incomplete one does not.
static_assert(EquationOfState<Tait<double>, double> && EquationOfState<Tait<float>, float>);
static_assert(EquationOfState<LinearEos<double>, double> && EquationOfState<LinearEos<float>, float>);
static_assert(!EquationOfState<Tait<double>, float>);  // precision must match the system's
namespace broken {
struct MissingSoundSpeed {
  double pressure(double rho) const { return rho; }
  double density(double p) const { return p; }
  double reference_density() const { return 1000; }
  double reference_sound_speed() const { return 10; }
};
struct MissingInverse {
  double pressure(double rho) const { return rho; }
  double sound_speed(double) const { return 10; }
  double reference_density() const { return 1000; }
  double reference_sound_speed() const { return 10; }
};
}  // namespace broken
static_assert(!EquationOfState<broken::MissingSoundSpeed, double>);
static_assert(!EquationOfState<broken::MissingInverse, double>);

TEMPLATE_TEST_CASE("equation of state properties", "[eos]", Tait<double>, Tait<float>, LinearEos<double>,
                   LinearEos<float>) {
  using E = TestType;
  using T = typename scalar_of<E>::type;
  using E64 = typename scalar_of<E>::template with<double>;
  constexpr double eps = std::numeric_limits<T>::epsilon();
  // Water at the project's usual artificial sound speed (c0 = 10 u_max, u_max ~ 2.5 m/s) and a light fluid.
  const T rho0 = GENERATE(T(1000), T(1.2));
  const T c0 = GENERATE(T(25), T(1480));
  const E eos(rho0, c0);
  const E64 eos64(static_cast<double>(rho0), static_cast<double>(c0));
  CAPTURE(sizeof(T), rho0, c0);

  SECTION("reference state: p(rho0) = 0, c(rho0) = c0, density(0) = rho0") {
    CHECK(eos.pressure(rho0) == T(0));
    CHECK(eos.reference_density() == rho0);
    CHECK(eos.reference_sound_speed() == c0);
    CHECK(eos.sound_speed(rho0) == Approx(c0).epsilon(4 * eps));
    CHECK(eos.density(T(0)) == Approx(rho0).epsilon(4 * eps));
  }

  // Densities from 20% expansion to 20% compression: far beyond the ~1% of a weakly compressible run.
  const int samples = 400;
  auto density_at = [&](int k) { return rho0 * (T(0.8) + T(0.4) * T(k) / T(samples)); };

  SECTION("pressure increases strictly with density") {
    T previous = eos.pressure(density_at(0));
    CHECK(previous < T(0));  // tension below rho0
    for (int k = 1; k <= samples; ++k) {
      const T p = eos.pressure(density_at(k));
      CAPTURE(density_at(k), p, previous);
      REQUIRE(p > previous);
      previous = p;
    }
    CHECK(previous > T(0));
  }

  SECTION("sound speed squared equals dp/drho") {
    // Central difference with step delta = cbrt(eps_T) rho0: truncation <= delta^2 / 6 max|p'''|; round-off
    // <= e_p / delta, where one pressure value carries an absolute error e_p <= 4 eps_T (|p| + rho0 c0^2)
    // (the Tait form B [(rho/rho0)^gamma - 1] loses its relative accuracy to cancellation near rho0, not its
    // absolute one). The step actually taken, r+ - r-, is used (exact in T).
    const T delta = static_cast<T>(std::cbrt(eps) * static_cast<double>(rho0));
    const double lo = static_cast<double>(density_at(0)), hi = static_cast<double>(density_at(samples));
    const double m3 = max_third_derivative(eos64, lo - 2 * double(delta), hi + 2 * double(delta));
    const double stiffness = static_cast<double>(rho0) * static_cast<double>(c0) * static_cast<double>(c0);
    for (int k = 0; k <= samples; k += 4) {
      const T rho = density_at(k);
      const T plus = rho + delta, minus = rho - delta;
      const double p_plus = static_cast<double>(eos.pressure(plus)), p_minus = static_cast<double>(eos.pressure(minus));
      const double difference = (p_plus - p_minus) / (static_cast<double>(plus) - static_cast<double>(minus));
      const double c = static_cast<double>(eos.sound_speed(rho));
      const double tolerance = 1.25 * double(delta) * double(delta) / 6.0 * m3 +
                               4.0 * eps * (std::abs(p_plus) + stiffness) / double(delta) +
                               4.0 * eps * c * c;  // c^2 itself to a few ulps
      CAPTURE(rho, difference, c * c, tolerance);
      REQUIRE(std::abs(difference - c * c) <= tolerance);
    }
  }

  SECTION("density(pressure(rho)) recovers rho") {
    // Round-off only: p/B + 1 is formed to ~2 eps_T and its 1/gamma power divides that relative error by
    // gamma, so a few ulps of rho; 8 eps_T rho bounds it.
    for (int k = 0; k <= samples; ++k) {
      const T rho = density_at(k);
      CAPTURE(rho, eos.pressure(rho), eos.density(eos.pressure(rho)));
      REQUIRE(std::abs(static_cast<double>(eos.density(eos.pressure(rho)) - rho)) <= 8.0 * eps * double(rho));
    }
  }

  SECTION("invalid parameters are rejected with an InputError naming the parameter") {
    const T inf = std::numeric_limits<T>::infinity(), nan = std::numeric_limits<T>::quiet_NaN();
    for (T bad : {T(0), T(-1000), inf, nan}) {
      CAPTURE(bad);
      CHECK_THROWS_AS(E(bad, c0), InputError);
      CHECK_THROWS_WITH(E(bad, c0), Catch::Matchers::Contains("rho0"));
      CHECK_THROWS_AS(E(rho0, bad), InputError);
      CHECK_THROWS_WITH(E(rho0, bad), Catch::Matchers::Contains("c0"));
    }
    if constexpr (std::is_same_v<E, Tait<T>>) {
      for (T bad : {T(0), T(0.5), T(-7), T(11), nan}) {
        CAPTURE(bad);
        CHECK_THROWS_AS(E(rho0, c0, bad), InputError);
        CHECK_THROWS_WITH(E(rho0, c0, bad), Catch::Matchers::Contains("gamma"));
      }
      CHECK_NOTHROW(E(rho0, c0, T(1)));
      CHECK_NOTHROW(E(rho0, c0, T(7)));
    }
  }
}

TEST_CASE("Tait equation of state matches its closed form", "[eos]") {
  // B = rho0 c0^2 / gamma (Monaghan 1994, eq. 3.4): at 1% compression of water with c0 = 25 m/s and gamma = 7,
  // p = B (1.01^7 - 1) = 89285.714 * 0.0721353521 Pa.
  const Tait<double> water(1000.0, 25.0, 7.0);
  CHECK(water.stiffness() == Approx(1000.0 * 625.0 / 7.0).epsilon(1e-15));
  CHECK(water.pressure(1010.0) == Approx(1000.0 * 625.0 / 7.0 * (std::pow(1.01, 7.0) - 1.0)).epsilon(1e-13));
  CHECK(water.sound_speed(1010.0) == Approx(25.0 * std::pow(1.01, 3.0)).epsilon(1e-14));
  // Linear EOS: p = c0^2 (rho - rho0) exactly, constant sound speed.
  const LinearEos<double> linear(1000.0, 25.0);
  CHECK(linear.pressure(1010.0) == Approx(625.0 * 10.0).epsilon(1e-15));
  CHECK(linear.sound_speed(900.0) == 25.0);
}
