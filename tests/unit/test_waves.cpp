// Tests of the wave flume tools: linear theory and Biesel transfer functions, the wavemaker's motion, zero-crossing
// analysis, the Dalrymple et al. (1984) decay fit and drag-coefficient inversion, the damping zone and the gauges.
#include <sphfsi/analysis/harmonic_fit.hpp>
#include <sphfsi/analysis/line_fit.hpp>
#include <sphfsi/analysis/vegetation_drag.hpp>
#include <sphfsi/analysis/wave_reflection.hpp>
#include <sphfsi/analysis/zero_crossing.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/wave_flume.hpp>
#include <sphfsi/waves/damping_zone.hpp>
#include <sphfsi/waves/gauges.hpp>
#include <sphfsi/waves/linear_theory.hpp>
#include <sphfsi/waves/second_order.hpp>
#include <sphfsi/waves/wavemaker.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

using namespace sphfsi;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {
constexpr double pi = std::numbers::pi;

// Biesel's progressive-wave height over stroke for a paddle excursion (S/2) f(s), s the height above the bed:
// H/S = 4 sinh(kh) k Int_0^h f(s) cosh(k s) ds / (sinh 2kh + 2kh), by Simpson's rule (independent of the closed forms).
template <class F>
double biesel_by_quadrature(double kh, F profile) {
  const int n = 2000;
  double sum = 0;
  for (int i = 0; i <= n; ++i) {
    const double u = double(i) / n;  // s / h
    const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    sum += w * profile(u) * std::cosh(kh * u);
  }
  const double integral = sum / (3.0 * n) * kh;  // k Int_0^h f cosh(ks) ds = kh Int_0^1 f(u) cosh(kh u) du
  return 4 * std::sinh(kh) * integral / (std::sinh(2 * kh) + 2 * kh);
}

// Mean and standard deviation of statistic(y + noise) over n draws of white noise of standard deviation s.
template <class Statistic>
std::pair<double, double> noisy_scatter(const std::vector<double>& y, double s, int n, unsigned seed,
                                        Statistic statistic) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, s);
  double sum = 0, sum2 = 0;
  for (int k = 0; k < n; ++k) {
    std::vector<double> yk = y;
    for (double& v : yk) v += noise(rng);
    const double q = statistic(yk);
    sum += q, sum2 += q * q;
  }
  return {sum / n, std::sqrt(sum2 / n - (sum / n) * (sum / n))};
}
}  // namespace

TEST_CASE("dispersion relation: the known answer of validation-cases.md section 4", "[waves]") {
  // h = 0.16 m, T = 1.4286 s: k = 3.706 1/m, L = 1.695 m, piston H/S = 0.591 (given to the digits shown)
  const auto w = waves::linear_wave(1.4286, 0.16);
  CHECK_THAT(w.wave_number, WithinAbs(3.706, 0.0005));
  CHECK_THAT(w.wavelength, WithinAbs(1.695, 0.0005));
  CHECK_THAT(w.kh(), WithinAbs(0.593, 0.0005));
  CHECK_THAT(waves::piston_height_to_stroke(w.kh()), WithinAbs(0.591, 0.0005));
  // float gives the same to float precision
  const auto wf = waves::linear_wave(1.4286f, 0.16f);
  CHECK_THAT(double(wf.wave_number), WithinRel(w.wave_number, 1e-6));
}

TEST_CASE("dispersion relation: residual and limits at all depths", "[waves]") {
  const double g = 9.81;
  for (double depth : {1e-3, 0.01, 0.16, 1.0, 10.0, 1000.0}) {
    for (double period : {0.3, 1.4286, 10.0}) {
      const auto w = waves::linear_wave(period, depth, g);
      const double omega = 2 * pi / period;
      CHECK_THAT(g * w.wave_number * std::tanh(w.kh()), WithinRel(omega * omega, 1e-12));
      CHECK_THAT(w.celerity * period, WithinRel(w.wavelength, 1e-12));
      if (w.kh() < 0.05) {  // shallow water: c -> sqrt(g h), c_g -> c, to O((kh)^2)
        CHECK_THAT(w.celerity, WithinRel(std::sqrt(g * depth), w.kh() * w.kh()));
        CHECK_THAT(w.group_velocity, WithinRel(w.celerity, w.kh() * w.kh()));
      }
      if (w.kh() > 10) {  // deep water: k -> omega^2 / g, c_g -> c / 2, to O(exp(-2kh))
        CHECK_THAT(w.wave_number, WithinRel(omega * omega / g, 1e-8));
        CHECK_THAT(w.group_velocity, WithinRel(0.5 * w.celerity, 1e-8));
      }
    }
  }
  CHECK_THROWS_AS(waves::wave_number(0.0, 1.0), InputError);
  CHECK_THROWS_AS(waves::wave_number(1.0, -1.0), InputError);
}

TEST_CASE("canopy orbital velocity: the depth average of Airy's u amplitude over the canopy", "[waves]") {
  // (1 / l) Int_0^l (H / 2) omega cosh(k z) / sinh(k h) dz by Simpson's rule against the closed form
  const auto w = waves::linear_wave(1.2, 0.2);
  const double H = 0.03;
  for (double l : {1e-9, 0.02, 0.08, 0.2}) {
    const int n = 2000;
    double sum = 0;
    for (int i = 0; i <= n; ++i) {
      const double z = l * i / n, weight = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
      sum += weight * 0.5 * H * w.angular_frequency * std::cosh(w.wave_number * z) / std::sinh(w.kh());
    }
    CHECK_THAT(w.canopy_orbital_velocity(H, l), WithinRel(sum / (3 * n), 1e-10));
  }
  // the full depth: (H / 2) omega / (k h), the depth-mean velocity amplitude (volume flux / h)
  CHECK_THAT(w.canopy_orbital_velocity(H, 0.2), WithinRel(0.5 * H * w.angular_frequency / w.kh(), 1e-12));
  CHECK_THROWS_AS(w.canopy_orbital_velocity(H, 0.3), InputError);
  CHECK_THROWS_AS(w.canopy_orbital_velocity(H, -0.01), InputError);
}

TEST_CASE("Biesel transfer functions: closed forms against the quadrature of Biesel's integral, and limits",
          "[waves]") {
  for (double kh : {0.05, 0.3, 0.593, 1.0, 2.0, 4.0}) {
    // Simpson with 2000 intervals: relative error ~ (kh/2000)^4, far below 1e-9
    CHECK_THAT(waves::piston_height_to_stroke(kh),
               WithinRel(biesel_by_quadrature(kh, [](double) { return 1.0; }), 1e-9));
    CHECK_THAT(waves::flap_height_to_stroke(kh), WithinRel(biesel_by_quadrature(kh, [](double u) { return u; }), 1e-9));
  }
  // shallow water: piston H/S -> kh (the displaced volume S h fills a crest of the wave), flap -> kh / 2
  for (double kh : {1e-4, 1e-3}) {
    CHECK_THAT(waves::piston_height_to_stroke(kh), WithinRel(kh, kh));
    CHECK_THAT(waves::flap_height_to_stroke(kh), WithinRel(kh / 2, kh));
  }
  // deep water: both -> 2
  CHECK_THAT(waves::piston_height_to_stroke(20.0), WithinRel(2.0, 1e-12));
  CHECK_THAT(waves::flap_height_to_stroke(20.0), WithinRel(2.0, 0.06));  // 2 (1 - 1/kh): 5 % below at kh = 20
  CHECK_THROWS_AS(waves::piston_height_to_stroke(0.0), InputError);
}

TEST_CASE("wavemaker: Biesel stroke, ramp, velocity, piston and flap motions", "[waves]") {
  waves::WavemakerParameters<double> p;  // h = 0.16 m, T = 1.4286 s, H = 0.028 m, piston, 2-period ramp
  const waves::Wavemaker<double> piston(p);
  const double ratio = waves::piston_height_to_stroke(piston.wave().kh());
  CHECK_THAT(piston.stroke(), WithinRel(0.028 / ratio, 1e-12));
  CHECK_THAT(piston.stroke(), WithinAbs(0.0474, 0.0001));  // 0.028 / 0.591
  // starts from rest; full amplitude S/2 after the ramp
  CHECK(piston.displacement(0.0) == 0.0);
  CHECK(piston.velocity(0.0) == 0.0);
  const double T = p.period, tr = piston.ramp_time();
  CHECK_THAT(tr, WithinRel(2 * T, 1e-15));
  CHECK_THAT(piston.displacement(tr + 0.25 * T), WithinRel(0.5 * piston.stroke(), 1e-12));
  // velocity is the time derivative of the displacement (central differences, error ~ dt^2 X''' ~ 1e-10 m/s)
  for (double t : {0.1, 0.7, 1.5, 2.8, 2.9, 5.0}) {
    const double dt = 1e-5;
    const double fd = (piston.displacement(t + dt) - piston.displacement(t - dt)) / (2 * dt);
    CHECK_THAT(piston.velocity(t), WithinAbs(fd, 1e-8));
  }
  const auto motion = piston.piston_motion<2>();
  CHECK(motion.displacement(3.3)[0] == piston.displacement(3.3));
  CHECK(motion.displacement(3.3)[1] == 0.0);
  CHECK_THROWS_AS(piston.flap_kinematics<2>(0.0), InputError);

  p.paddle = waves::PaddleType::flap;
  const waves::Wavemaker<double> flap(p);
  CHECK_THAT(flap.stroke(), WithinRel(0.028 / waves::flap_height_to_stroke(flap.wave().kh()), 1e-12));
  CHECK(flap.stroke() > piston.stroke());  // a flap displaces less water per stroke
  const auto k = flap.flap_kinematics<2>(0.0, 0.0);
  for (double t : {1.0, 3.3, 4.0}) {
    // the paddle line crosses the still-water level at x = X(t); points keep their distance to the hinge
    const Vec<2, double> bottom(0, 0.01), top(0, 0.2);
    const auto [xb, vb] = k.state(bottom, t);
    const auto [xt, vt] = k.state(top, t);
    const double x_at_surface = xb[0] + (xt[0] - xb[0]) * (0.16 - xb[1]) / (xt[1] - xb[1]);
    CHECK_THAT(x_at_surface, WithinAbs(flap.displacement(t), 1e-14));
    CHECK_THAT(xt.norm(), WithinRel(0.2, 1e-14));
    // velocity is the time derivative of the position
    const double dt = 1e-6;
    const Vec<2, double> fd = (k.state(top, t + dt).first - k.state(top, t - dt).first) / (2 * dt);
    CHECK_THAT(vt[0], WithinAbs(fd[0], 1e-8));
    CHECK_THAT(vt[1], WithinAbs(fd[1], 1e-8));
  }
  waves::WavemakerParameters<double> bad;
  bad.wave_height = 1.0;  // needs a stroke beyond the depth
  CHECK_THROWS_AS(waves::Wavemaker<double>(bad), InputError);
  bad = {};
  bad.period = -1;
  CHECK_THROWS_AS(waves::Wavemaker<double>(bad), InputError);
}

TEST_CASE("second-order waves: Stokes harmonic, Madsen's piston correction and the free harmonic in their limits",
          "[waves]") {
  const double g = 9.81, height = 0.01;
  // Deep water (kh = 20): a_2 -> k a^2 / 2 (Stokes), up to terms of order exp(-2 kh) ~ 4e-18
  {
    const auto w = waves::linear_wave(0.4, 2.0, g);
    REQUIRE(w.kh() > 19);
    const double a = height / 2;
    CHECK_THAT(waves::stokes_second_harmonic_amplitude(w, height), WithinRel(0.5 * w.wave_number * a * a, 1e-12));
  }
  // Shallow water (kh = 0.01): a_2 -> 3 H^2 / (16 k^2 h^3) and X_2 -> a_2 / (2 kh) = 3 H^2 / (32 k^3 h^4); the
  // series of the closed forms give relative corrections +2 (kh)^2 / 3 and -2 (kh)^2 / 3 = 6.7e-5: tolerance 1e-4.
  // In that limit the free wave a first-order paddle sheds cancels the bound one at the paddle: a_2f -> a_2.
  {
    const double depth = 0.01;
    const double omega = std::sqrt(g * 1.0 * std::tanh(0.01));  // k = 1 1/m on the dispersion relation
    const auto w = waves::linear_wave(2 * pi / omega, depth, g);
    REQUIRE_THAT(w.kh(), WithinRel(0.01, 1e-3));
    const double k = w.wave_number, h = depth, H = 1e-4;
    const double a2 = waves::stokes_second_harmonic_amplitude(w, H);
    CHECK_THAT(a2, WithinRel(3 * H * H / (16 * k * k * h * h * h), 1e-4));
    const double x2 = waves::madsen_piston_second_harmonic(w, H);
    CHECK_THAT(x2, WithinRel(3 * H * H / (32 * k * k * k * h * h * h * h), 1e-4));
    const auto free = waves::free_second_harmonic(w, H);
    CHECK_THAT(free.amplitude, WithinRel(a2, 2e-4));  // both ends carry an O((kh)^2) correction
    CHECK_THAT(waves::piston_wave_elevation(w, H, false, 0.0, 0.3),
               WithinAbs(0.5 * H * std::cos(-w.angular_frequency * 0.3), 2e-4 * a2));
  }
  // The validation wave (h = 0.16 m, T = 1.4286 s, H = 0.028 m): U = 19.6 below Madsen's 8 pi^2 / 3 = 26.3, where
  // a_2 < a / 4 (no secondary crest in the trough); the correction is 7 % of the first-order excursion.
  const auto w = waves::linear_wave(1.4286, 0.16, g);
  const double H = 0.028;
  CHECK_THAT(waves::ursell_number(w, H), WithinAbs(19.65, 0.01));
  CHECK(waves::ursell_number(w, H) < waves::second_order_ursell_limit<double>());
  CHECK_THAT(waves::second_order_ursell_limit<double>(), WithinRel(26.319, 1e-4));
  const double a2 = waves::stokes_second_harmonic_amplitude(w, H);
  CHECK(a2 < H / 8);
  CHECK_THAT(a2, WithinAbs(0.003276, 1e-6));
  const waves::Wavemaker<double> linear({});
  const double x2 = waves::madsen_piston_second_harmonic(w, H);
  CHECK_THAT(x2 / (0.5 * linear.stroke()), WithinAbs(0.0705, 0.0005));
  // Zero-crossing heights of second-order theory: H everywhere with the corrected paddle; beating with the beat
  // length 2 pi / |k_2 - 2k| (2.55 L here) with the first-order paddle, between H at the paddle and about 1.09 H.
  const auto free = waves::free_second_harmonic(w, H);
  CHECK_THAT(free.beat_length / w.wavelength, WithinAbs(2.545, 0.001));
  auto crest_to_trough = [&](bool corrected, double x) {
    double hi = -1, lo = 1;
    for (int i = 0; i < 4000; ++i) {
      const double e = waves::piston_wave_elevation(w, H, corrected, x, w.period * i / 4000.0);
      hi = std::max(hi, e), lo = std::min(lo, e);
    }
    return hi - lo;
  };
  for (double x : {0.0, 0.7, 1.9, 3.2}) CHECK_THAT(crest_to_trough(true, x), WithinRel(H, 1e-5));
  CHECK_THAT(crest_to_trough(false, 0.3), WithinRel(crest_to_trough(false, 0.3 + free.beat_length), 1e-5));
  double largest = 0;
  for (int i = 0; i < 50; ++i) largest = std::max(largest, crest_to_trough(false, free.beat_length * i / 50.0));
  CHECK_THAT(largest / H, WithinAbs(1.09, 0.01));
  CHECK_THROWS_AS(waves::stokes_second_harmonic_amplitude(w, -1.0), InputError);
  CHECK_THROWS_AS(waves::madsen_piston_second_harmonic(w, 0.0), InputError);
}

TEST_CASE("wavemaker: second-order piston signal (Madsen 1971)", "[waves]") {
  waves::WavemakerParameters<double> p;
  p.order = 2;
  const waves::Wavemaker<double> second(p);
  const waves::Wavemaker<double> first({});
  const double x2 = waves::madsen_piston_second_harmonic(second.wave(), p.wave_height);
  CHECK(second.second_harmonic() == x2);
  CHECK(first.second_harmonic() == 0.0);
  CHECK(second.stroke() == first.stroke());
  // after the ramp: X = (S/2) sin(wt) + X_2 sin(2wt)
  const double w = second.wave().angular_frequency;
  for (double t : {3.0, 4.1, 7.77}) {
    CHECK_THAT(second.displacement(t),
               WithinAbs(0.5 * second.stroke() * std::sin(w * t) + x2 * std::sin(2 * w * t), 1e-15));
  }
  CHECK(second.displacement(0.0) == 0.0);
  CHECK(second.velocity(0.0) == 0.0);
  for (double t : {0.1, 0.7, 1.5, 2.8, 2.9, 5.0}) {  // during and after the ramp
    const double dt = 1e-5;
    const double fd = (second.displacement(t + dt) - second.displacement(t - dt)) / (2 * dt);
    CHECK_THAT(second.velocity(t), WithinAbs(fd, 1e-8));
  }
  p.order = 3;
  CHECK_THROWS_AS(waves::Wavemaker<double>(p), InputError);
  p.order = 2;
  p.paddle = waves::PaddleType::flap;
  CHECK_THROWS_AS(waves::Wavemaker<double>(p), InputError);
}

TEST_CASE("zero-crossing analysis of synthetic records", "[waves][analysis]") {
  const double T = 1.4286, a = 0.014, dt = T / 40;
  std::vector<double> t, eta, eta2;
  for (int i = 0; i <= 40 * 12; ++i) {
    const double ti = i * dt;
    t.push_back(ti);
    eta.push_back(0.003 + a * std::sin(2 * pi * ti / T + 0.3));  // offset removed by the analysis
    // a Stokes-like second harmonic: crests sharper than troughs; H from a dense evaluation of the same signal
    eta2.push_back(a * std::cos(2 * pi * ti / T) + 0.2 * a * std::cos(4 * pi * ti / T));
  }
  const auto w = analysis::zero_crossing_analysis(t, eta, 2.0, t.back());
  CHECK(w.count() >= 9);
  // samples every T/40 miss a crest by at most half a step: H low by at most a (1 - cos(pi/40)) per extremum
  CHECK_THAT(w.mean_height, WithinAbs(2 * a, 2 * a * (1 - std::cos(pi / 40))));
  // crossing times by linear interpolation: error ~ (dt^2 / 8) |eta''| / |eta'| at a crossing = dt^2 (2 pi/T) / 8
  CHECK_THAT(w.mean_period, WithinAbs(T, 1e-3));
  CHECK_THAT(w.mean_level, WithinAbs(0.003, 2 * a / 10));  // window not a whole number of periods
  const auto down = analysis::zero_crossing_analysis(t, eta, 2.0, t.back(), analysis::Crossing::down);
  CHECK_THAT(down.mean_height, WithinAbs(2 * a, 2 * a * (1 - std::cos(pi / 40))));

  double hi = -1, lo = 1;
  for (int i = 0; i < 100000; ++i) {
    const double s = T * i / 100000.0;
    const double e = a * std::cos(2 * pi * s / T) + 0.2 * a * std::cos(4 * pi * s / T);
    hi = std::max(hi, e), lo = std::min(lo, e);
  }
  const auto w2 = analysis::zero_crossing_analysis(t, eta2, 0.0, t.back());
  CHECK_THAT(w2.mean_height, WithinRel(hi - lo, 0.01));  // sampling error as above, at most ~0.6 %
  CHECK_THAT(w2.mean_period, WithinAbs(T, 1e-3));

  CHECK_THROWS_AS(analysis::zero_crossing_analysis(t, eta, 2.0, 2.5), InputError);  // no complete wave
  eta[100] = std::nan("");
  CHECK_THROWS_AS(analysis::zero_crossing_analysis(t, eta, 0.0, t.back()), InputError);
}

TEST_CASE("Dalrymple decay: fit and C_D inversion recover a known drag coefficient", "[waves][analysis]") {
  // Luhar et al. (2017)-like meadow: h = 0.16 m, T = 1.4286 s, stems 0.13 m tall, 3 mm wide, 7200 per m^2
  const auto w = waves::linear_wave(1.4286, 0.16);
  const analysis::StemField stems{0.13, 0.003, 7200};
  const double cd = 1.4, H0 = 0.028;
  const double alpha = analysis::dalrymple_alpha(cd, stems, H0, w.wave_number, 0.16);
  std::vector<double> x, H;
  for (int i = 0; i <= 25; ++i) {
    x.push_back(0.2 * i);
    H.push_back(H0 / (1 + alpha * x.back()));
  }
  // exact data: exact recovery
  const auto exact = analysis::fit_decay(x, H);
  CHECK_THAT(exact.alpha, WithinRel(alpha, 1e-9));
  CHECK_THAT(exact.incident_height, WithinRel(H0, 1e-9));
  CHECK_THAT(analysis::drag_coefficient(exact, stems, w.wave_number, 0.16).value, WithinRel(cd, 1e-9));
  CHECK(exact.se_alpha() < 1e-9 * alpha);
  const auto fixed = analysis::fit_decay(x, H, H0);
  CHECK_THAT(fixed.alpha, WithinRel(alpha, 1e-9));

  // noisy data: the standard error must describe the scatter of the estimates. Over 400 realisations with 2 %
  // Gaussian noise, the truth lies within one standard error of the estimate in about 68 % of them; the binomial
  // standard deviation of that fraction is sqrt(0.68 * 0.32 / 400) = 2.3 %, so [0.58, 0.78] is +-4.3 sigma.
  std::mt19937 rng(2017);
  std::normal_distribution<double> noise(0.0, 0.02);
  int inside = 0;
  const int trials = 400;
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<double> Hn(H);
    for (double& v : Hn) v *= 1 + noise(rng);
    const auto fit = analysis::fit_decay(x, Hn);
    const auto c = analysis::drag_coefficient(fit, stems, w.wave_number, 0.16);
    if (std::abs(c.value - cd) <= c.standard_error) ++inside;
    if (trial == 0) {
      INFO("C_D = " << c.value << " +- " << c.standard_error);
      CHECK(std::abs(c.value - cd) <= 3 * c.standard_error);
      CHECK(c.standard_error < 0.2 * cd);
    }
  }
  const double coverage = double(inside) / trials;
  INFO("one-standard-error coverage " << coverage);
  CHECK(coverage > 0.58);
  CHECK(coverage < 0.78);

  CHECK_THROWS_AS(analysis::fit_decay(std::vector<double>{0, 1}, std::vector<double>{1, 0.9}), InputError);
  CHECK_THROWS_AS(analysis::fit_decay(std::vector<double>{0, 1, 2}, std::vector<double>{1, -0.9, 0.8}), InputError);
  CHECK_THROWS_AS(analysis::dalrymple_wave_factor(w.wave_number, 0.16, 0.2), InputError);  // stems above water
}

TEST_CASE("damping zone: relaxation rate profile and velocity decay", "[waves]") {
  using System = ParticleSystem<2, double, WendlandC2<2>, Tait<double>>;
  System system(Domain<2, double>(Vec<2, double>(-1, -1), Vec<2, double>(3, 1)), Tait<double>(1000, 10));
  waves::DampingZone<double> zone{1.0, 2.0, 10.0};
  zone.validate();
  CHECK(zone.rate(0.5) == 0.0);
  CHECK(zone.rate(1.0) == 0.0);
  CHECK_THAT(zone.rate(1.5), WithinRel(2.5, 1e-15));
  CHECK_THAT(zone.rate(2.5), WithinRel(10.0, 1e-15));
  auto& p = system.particles();
  for (double x : {0.5, 1.5, 2.5}) p.add(Kind::fluid, Vec<2, double>(x, 0), Vec<2, double>(1, -1), 1000, 1, 0.1);
  p.add(Kind::wall, Vec<2, double>(2.5, -0.5), Vec<2, double>(1, 0), 1000, 1, 0.1);
  zone.advance(system, 0.0, 0.01);
  CHECK(p.velocity[0][0] == 1.0);
  CHECK_THAT(p.velocity[1][0], WithinRel(std::exp(-0.025), 1e-14));
  CHECK_THAT(p.velocity[2][1], WithinRel(-std::exp(-0.1), 1e-14));
  CHECK(p.velocity[3][0] == 1.0);  // walls untouched
  waves::DampingZone<double> bad{1.0, 1.0, 10.0};
  CHECK_THROWS_AS(bad.validate(), InputError);
}

TEST_CASE("wave gauge: the surface of a still flume at the still-water level", "[waves]") {
  using System = ParticleSystem<2, double, WendlandC2<2>, Tait<double>>;
  scenes::WaveFlumeGeometry<double> g;
  g.particles_per_depth = 10;
  g.length_wavelengths = 1;
  g.damping_wavelengths = 0.3;
  System system(scenes::wave_flume_domain(g), Tait<double>(1000, g.sound_speed()));
  const auto layout = scenes::build_wave_flume(system, g);
  CHECK(layout.fluid_particles == std::size_t(std::llround(g.length() / g.dp())) * 10);
  // The half-level of the colour of a half-space lies on its boundary (the kernel is even). The lattice's top row
  // sits dp/2 below z = h, so the discrete colour's half-level is there up to the kernel quadrature error on the
  // lattice, a few per cent of dp for h_sph = 1.3 dp: allow dp/10.
  for (double x : {0.3, 0.8, 1.2}) {
    const double eta = waves::free_surface_elevation(system, x, layout.still_level, g.dp());
    INFO("x = " << x << " eta/dp = " << eta / g.dp());
    CHECK(std::abs(eta) < 0.1 * g.dp());
  }
  CHECK(std::isnan(waves::free_surface_elevation(system, -5.0, layout.still_level, g.dp())));
  // Passive particles (another resolution of the same water, fluid/adaptive_refinement.hpp) are left out: a passive
  // copy of the top rows a spacing higher would otherwise lift the surface by about dp.
  {
    using V2 = Vec<2, double>;
    System copy(scenes::wave_flume_domain(g), Tait<double>(1000, g.sound_speed()));
    scenes::build_wave_flume(copy, g);
    auto& p = copy.particles();
    const std::size_t n = p.size();
    for (std::size_t i = 0; i < n; ++i)
      if (p.kind[i] == Kind::fluid && p.position[i][1] > layout.still_level - 3 * g.dp()) {
        const std::size_t c = p.add(Kind::fluid, V2(p.position[i] + V2(0, g.dp())), V2::Zero(), p.density[i], p.mass[i],
                                    p.smoothing_length[i]);
        p.passive[c] = 1;
      }
    for (double x : {0.3, 0.8})
      CHECK(waves::free_surface_elevation(copy, x, layout.still_level, g.dp()) ==
            waves::free_surface_elevation(system, x, layout.still_level, g.dp()));
  }
  waves::WaveGauges<double> gauges({0.5, 1.0}, layout.still_level, g.dp());
  CHECK(gauges.column_name(1) == "eta_1.0000");
  CHECK(waves::gauge_position("eta_1.0000").value() == 1.0);
  CHECK_FALSE(waves::gauge_position("t").has_value());
  gauges.sample(system, 0.0);
  CHECK(gauges.series(0).size() == 1);
}

TEST_CASE("fit_line: an exact line, the slope's standard error against Monte Carlo, and bad input",
          "[waves][analysis]") {
  const std::vector<double> x{0, 1, 2, 3, 4};
  std::vector<double> y;
  for (double xi : x) y.push_back(0.5 - 0.02 * xi);
  const auto exact = analysis::fit_line(x, y);
  CHECK_THAT(exact.slope, WithinAbs(-0.02, 1e-15));
  CHECK_THAT(exact.intercept, WithinAbs(0.5, 1e-15));
  CHECK(exact.points == 5);
  CHECK(std::isnan(exact.slope_error));
  // errors s_i: var(slope) = sum ((x_i - 2) / 10)^2 s_i^2; with s = 0.01 at every point, s / sqrt(10)
  const std::vector<double> s(5, 0.01);
  CHECK_THAT(analysis::fit_line(x, y, s).slope_error, WithinRel(0.01 / std::sqrt(10.0), 1e-12));
  // the same against the scatter of 20,000 noisy fits (relative standard error of a standard deviation from
  // n samples: 1 / sqrt(2 n) = 0.5 %; 3 % allows six of them)
  const auto [mean_slope, sd] =
      noisy_scatter(y, 0.01, 20000, 17, [&](const std::vector<double>& yk) { return analysis::fit_line(x, yk).slope; });
  CHECK_THAT(mean_slope, WithinAbs(-0.02, 4 * sd / std::sqrt(20000.0)));
  CHECK_THAT(sd, WithinRel(0.01 / std::sqrt(10.0), 0.03));
  CHECK_THROWS_AS(analysis::fit_line({1.0}, {2.0}), InputError);
  CHECK_THROWS_AS(analysis::fit_line({1.0, 1.0}, {2.0, 3.0}), InputError);
  CHECK_THROWS_AS(analysis::fit_line({1.0, 2.0}, {2.0}), InputError);
  CHECK_THROWS_AS(analysis::fit_line({1.0, 2.0}, {2.0, 3.0}, {0.1}), InputError);
}

TEST_CASE(
    "fit_harmonics: a drifting two-harmonic record recovered exactly, noise at the least-squares error, bad input",
    "[waves][analysis]") {
  // 4.9 periods of T = 1.2 s sampled at T / 40 (the flume's tip record): A1 = 15 mm, A2 = 2 mm, under a quadratic
  // drift that moves the mean by 10 mm over the window
  const double T = 1.2, omega = 2 * pi / T, t0 = 4.74, t1 = t0 + 4.9 * T;
  std::vector<double> t, y;
  for (double ti = t0; ti <= t1 + 1e-12; ti += T / 40) {
    const double tau = (ti - 0.5 * (t0 + t1)) / (0.5 * (t1 - t0));
    t.push_back(ti);
    y.push_back(-0.003 + 0.005 * tau + 0.002 * tau * tau + 0.015 * std::cos(omega * ti - 0.7) +
                0.002 * std::cos(2 * omega * ti + 0.3));
  }
  const auto fit = analysis::fit_harmonics(t, y, omega, t0, t1, 2, 2);
  CHECK_THAT(fit.amplitude.at(0), WithinAbs(0.015, 1e-12));
  CHECK_THAT(fit.amplitude.at(1), WithinAbs(0.002, 1e-12));
  CHECK_THAT(fit.phase.at(0), WithinAbs(0.7, 1e-10));
  CHECK_THAT(fit.phase.at(1), WithinAbs(-0.3, 1e-10));
  CHECK_THAT(fit.drift.at(1), WithinAbs(0.005, 1e-12));
  // mean of c0 + c1 tau + c2 tau^2 over [-1, 1]: c0 + c2 / 3
  CHECK_THAT(fit.mean, WithinAbs(-0.003 + 0.002 / 3, 1e-12));
  CHECK_THAT(fit.drift_range, WithinAbs(0.010, 1e-9));  // from tau = -1 (-0.006) to tau = 1 (+0.004)
  CHECK(fit.residual_rms < 1e-13);
  // the periodic part's half range: A1 alone for one harmonic; with the second, the extremes of 15 cos(theta - 0.7)
  // + 2 cos(2 theta + 0.3) mm, found here by bisection on the derivative (independent of the fit's phase grid)
  auto part = [](double th) { return 0.015 * std::cos(th - 0.7) + 0.002 * std::cos(2 * th + 0.3); };
  auto slope = [](double th) { return -0.015 * std::sin(th - 0.7) - 0.004 * std::sin(2 * th + 0.3); };
  auto root = [&](double a, double b) {
    for (int i = 0; i < 100; ++i) {
      const double c = 0.5 * (a + b);
      (slope(a) * slope(c) <= 0 ? b : a) = c;
    }
    return 0.5 * (a + b);
  };
  const double top = part(root(0.7 - 1, 0.7 + 1)), bottom = part(root(0.7 + pi - 1, 0.7 + pi + 1));
  CHECK_THAT(fit.periodic_half_range(), WithinAbs(0.5 * (top - bottom), 1e-7));
  CHECK_THAT(analysis::fit_harmonics(t, y, omega, t0, t1, 1, 2).periodic_half_range(),
             WithinRel(analysis::fit_harmonics(t, y, omega, t0, t1, 1, 2).amplitude[0], 1e-5));
  // the half peak-to-peak of the same record counts the drift: well above A1
  const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
  CHECK(0.5 * (*hi - *lo) > 0.018);
  // a drift left out of the model (degree 0) biases A1 and leaves a residual
  CHECK(analysis::fit_harmonics(t, y, omega, t0, t1, 2, 0).residual_rms > 1e-3);
  // white noise s: the amplitude's standard error is about s sqrt(2 / n) (n samples, the harmonics nearly orthogonal to
  // the drift); the scatter of 2,000 fits has a relative standard error of 1 / sqrt(4,000) = 1.6 %: 5 % allows three
  const int fits = 2000;
  const auto [mean_amplitude, sd] = noisy_scatter(y, 0.002, fits, 5, [&](const std::vector<double>& yk) {
    return analysis::fit_harmonics(t, yk, omega, t0, t1, 2, 2).amplitude[0];
  });
  CHECK_THAT(mean_amplitude, WithinAbs(0.015, 4 * sd / std::sqrt(double(fits)) + 1e-5));
  CHECK_THAT(sd, WithinRel(0.002 * std::sqrt(2.0 / double(t.size())), 0.05));
  CHECK_THROWS_AS(analysis::fit_harmonics(t, y, 0.0, t0, t1), InputError);
  CHECK_THROWS_AS(analysis::fit_harmonics(t, y, omega, t0, t0 + 0.5 * T), InputError);
  CHECK_THROWS_AS(analysis::fit_harmonics(t, y, omega, t0, t1, 0), InputError);
  CHECK_THROWS_AS(analysis::fit_harmonics(t, y, omega, t0, t1, 1, 5), InputError);
  CHECK_THROWS_AS(analysis::fit_harmonics(std::vector<double>{1.0}, y, omega, t0, t1), InputError);
  std::vector<double> bad = y;
  bad[10] = std::nan("");
  CHECK_THROWS_AS(analysis::fit_harmonics(t, bad, omega, t0, t1), InputError);
}

TEST_CASE("oscillatory plate drag: C_D = max(10 KC^(-1/3), 1.95) of Luhar & Nepf 2016", "[waves][analysis]") {
  using namespace sphfsi::analysis;
  // the Luhar et al. 2017 H1 blades: U_m = 0.1024 m/s (linear wave, canopy mean), T = 1.4286 s, b = 3 mm
  const double kc = keulegan_carpenter_number(0.1024, 1.4286, 3e-3);
  CHECK_THAT(kc, Catch::Matchers::WithinRel(48.76, 1e-3));
  CHECK_THAT(oscillatory_plate_drag_coefficient(kc), Catch::Matchers::WithinRel(10.0 / std::cbrt(48.76), 1e-3));
  CHECK_THAT(oscillatory_plate_drag_coefficient(1000.0), Catch::Matchers::WithinRel(1.95, 1e-15));  // steady limit
  CHECK_THAT(oscillatory_plate_drag_coefficient(1.0), Catch::Matchers::WithinRel(10.0, 1e-15));
  CHECK_THROWS_WITH(keulegan_carpenter_number(0.1, 1.4, 0.0), Catch::Contains("blade width b"));
  CHECK_THROWS_WITH(oscillatory_plate_drag_coefficient(-1.0), Catch::Contains("KC"));
}

TEST_CASE("incident and reflected waves: Mansard & Funke's least squares recovers a known reflection",
          "[waves][analysis]") {
  const double period = 1.4286, omega = 2 * pi / period, k = waves::linear_wave(period, 0.16).wave_number;
  const double L = 2 * pi / k, a = 0.014, r = 0.0035;  // K_r = 0.25
  const std::vector<double> x{3.0, 3.0 + L / 10, 3.0 + L / 4};
  std::vector<double> t;
  for (int j = 0; j < 40 * 6; ++j) t.push_back(10.0 + j * period / 40);  // 6 periods at T / 40
  auto records = [&](double mean, double second_harmonic, double noise) {
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0.0, 1.0);
    std::vector<std::vector<double>> eta(x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      for (double tj : t)
        eta[i].push_back(mean + a * std::cos(omega * tj - k * x[i] + 0.4) + r * std::cos(omega * tj + k * x[i] - 1.1) +
                         second_harmonic * std::cos(2 * omega * tj - 2.3 * k * x[i]) + noise * n(rng));
    return eta;
  };
  const double from = t.front(), to = t.front() + 6 * period - 1e-9;
  // pure waves, a mean level and a second harmonic: exact over whole periods
  const auto clean = analysis::separate_incident_reflected<double>(t, records(0.002, 0.003, 0), x, omega, k, from, to);
  CHECK_THAT(clean.incident_amplitude, WithinRel(a, 1e-9));
  CHECK_THAT(clean.reflected_amplitude, WithinRel(r, 1e-9));
  CHECK_THAT(clean.reflection_coefficient, WithinRel(0.25, 1e-9));
  CHECK(clean.residual < 1e-9);
  CHECK(clean.samples == 240);
  // noise of 10 % of a per sample: the amplitudes within a few standard errors, sigma sqrt(2 / N) per gauge
  const auto noisy = analysis::separate_incident_reflected<double>(t, records(0, 0, 0.1 * a), x, omega, k, from, to);
  CHECK(std::abs(noisy.reflection_coefficient - 0.25) < 0.03);
  // a purely progressive wave has no reflection; two gauges suffice
  const std::vector<double> two{x[0], x[1]};
  std::vector<std::vector<double>> progressive(2);
  for (std::size_t i = 0; i < 2; ++i)
    for (double tj : t) progressive[i].push_back(a * std::cos(omega * tj - k * two[i]));
  const auto none = analysis::separate_incident_reflected<double>(t, progressive, two, omega, k, from, to);
  CHECK(none.reflection_coefficient < 1e-9);
  CHECK_THAT(none.incident_amplitude, WithinRel(a, 1e-9));
  // bad input: one gauge, gauges half a wavelength apart, a window shorter than a period
  CHECK_THROWS_WITH(
      analysis::separate_incident_reflected<double>(t, {progressive[0]}, std::vector<double>{x[0]}, omega, k, from, to),
      Catch::Contains("at least two gauges"));
  CHECK_THROWS_WITH(analysis::separate_incident_reflected<double>(
                        t, progressive, std::vector<double>{x[0], x[0] + L / 2}, omega, k, from, to),
                    Catch::Contains("half a wavelength"));
  CHECK_THROWS_WITH(
      analysis::separate_incident_reflected<double>(t, progressive, two, omega, k, from, from + 0.5 * period),
      Catch::Contains("at least one period"));
}
