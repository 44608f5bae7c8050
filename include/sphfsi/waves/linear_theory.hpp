// sphfsi: linear (Airy) water-wave theory and Biesel's wavemaker transfer functions.
//
//   dispersion relation      omega^2 = g k tanh(k h)                                  (Dean & Dalrymple 1991, eq. 4.15)
//   celerity, group velocity c = omega / k,  c_g = n c,  n = (1 + 2kh / sinh 2kh) / 2
//   piston wavemaker         H / S = 4 sinh^2(kh) / (sinh 2kh + 2kh)                  (Biesel & Suquet 1951)
//   flap hinged at the bed   H / S = 4 (sinh kh / kh) (kh sinh kh - cosh kh + 1) / (sinh 2kh + 2kh)
// Both transfer functions are the progressive-wave part of Biesel's solution for a paddle whose horizontal
// displacement is (S/2) f(z) sin(omega t):  H / S = 4 sinh(kh) k Int_0^h f cosh(k s) ds / (sinh 2kh + 2kh),
// s the height above the bed (Dean & Dalrymple 1991, Water Wave Mechanics for Engineers and Scientists, sec. 6.2;
// f = 1 for the piston, f = s / h for the flap). tests/unit/test_waves.cpp checks both closed forms against that
// integral by quadrature, and their limits: kh (piston) and kh / 2 (flap) in shallow water, 2 in deep water.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <cmath>
#include <numbers>

namespace sphfsi::waves {

/// A regular linear wave in water of constant depth: the solution of the dispersion relation and what follows.
template <Real T>
struct LinearWave {
  T period;             ///< T, s
  T depth;              ///< h, m
  T gravity;            ///< g, m/s^2
  T angular_frequency;  ///< omega = 2 pi / T, rad/s
  T wave_number;        ///< k, rad/m
  T wavelength;         ///< L = 2 pi / k, m
  T celerity;           ///< c = omega / k, m/s
  T group_velocity;     ///< c_g, m/s

  T kh() const { return wave_number * depth; }
  /// Amplitude of the horizontal orbital velocity at the still-water surface for a wave of height H (m):
  /// (H / 2) omega / tanh(k h), m/s (Dean & Dalrymple 1991, sec. 4.4).
  T surface_orbital_velocity(T height) const { return T(0.5) * height * angular_frequency / std::tanh(kh()); }
  /// Amplitude of the horizontal orbital velocity averaged over the lowest `canopy_height` (m) of the water column,
  /// (H / 2) omega (1 / l) Int_0^l cosh(k z) dz / sinh(k h) = (H / 2) omega sinh(k l) / (k l sinh(k h)), z above the
  /// bed (the velocity scale of a canopy of height l, e.g. its Keulegan-Carpenter number), m/s.
  T canopy_orbital_velocity(T height, T canopy_height) const {
    require_in_range("LinearWave::canopy_orbital_velocity canopy height (m)", canopy_height, T(0), depth);
    const T kl = wave_number * canopy_height;
    const T shape = kl > T(1e-6) ? std::sinh(kl) / kl : T(1);
    return T(0.5) * height * angular_frequency * shape / std::sinh(kh());
  }
};

/// Solves omega^2 = g k tanh(k h) for k by Newton's method on F(x) = x tanh x - omega^2 h / g, x = k h, from
/// Eckart's (1952) estimate x0 = y / sqrt(tanh y), y = omega^2 h / g (within 5 % at all depths). F is convex
/// and increasing for x > 0, so Newton converges monotonically; 1e-14 relative accuracy in a few iterations.
template <Real T>
T wave_number(T period, T depth, T gravity = T(9.81)) {
  require_positive("wave_number period (s)", period);
  require_positive("wave_number depth (m)", depth);
  require_positive("wave_number gravity (m/s^2)", gravity);
  using W = long double;
  const W omega = W(2) * std::numbers::pi_v<W> / W(period);
  const W y = omega * omega * W(depth) / W(gravity);
  W x = y / std::sqrt(std::tanh(y));
  for (int iteration = 0; iteration < 60; ++iteration) {
    const W th = std::tanh(x);
    const W f = x * th - y;
    const W df = th + x * (W(1) - th * th);
    const W step = f / df;
    x -= step;
    if (std::abs(step) <= W(1e-15) * x) break;
  }
  return T(x / W(depth));
}

/// The linear wave of the given period in the given depth.
template <Real T>
LinearWave<T> linear_wave(T period, T depth, T gravity = T(9.81)) {
  LinearWave<T> w{};
  w.period = period;
  w.depth = depth;
  w.gravity = gravity;
  w.wave_number = wave_number(period, depth, gravity);
  w.angular_frequency = T(2) * std::numbers::pi_v<T> / period;
  w.wavelength = T(2) * std::numbers::pi_v<T> / w.wave_number;
  w.celerity = w.angular_frequency / w.wave_number;
  const T two_kh = T(2) * w.kh();
  const T n = two_kh > T(40) ? T(0.5) : T(0.5) * (T(1) + two_kh / std::sinh(two_kh));
  w.group_velocity = n * w.celerity;
  return w;
}

/// Piston wavemaker: wave height over full stroke, H / S = 4 sinh^2(kh) / (sinh 2kh + 2kh) (Biesel).
template <Real T>
T piston_height_to_stroke(T kh) {
  require_in_range("piston_height_to_stroke kh", kh, T(1e-6), T(40));
  const long double x = kh, s = std::sinh(x);
  return T(4 * s * s / (std::sinh(2 * x) + 2 * x));
}

/// Flap wavemaker hinged at the bed: H / S = 4 (sinh kh / kh)(kh sinh kh - cosh kh + 1) / (sinh 2kh + 2kh), S the
/// full stroke at the still-water level (Biesel; Dean & Dalrymple 1991, sec. 6.2).
template <Real T>
T flap_height_to_stroke(T kh) {
  require_in_range("flap_height_to_stroke kh", kh, T(1e-6), T(40));
  const long double x = kh, s = std::sinh(x);
  // x sinh x - cosh x + 1 = x^2/2 + x^4/8 + ...: summed as a series below x = 0.1, where the closed form cancels.
  const long double numerator = x < 0.1L ? x * x * (0.5L + x * x * (0.125L + x * x / 144)) : x * s - std::cosh(x) + 1;
  return T(4 * (s / x) * numerator / (std::sinh(2 * x) + 2 * x));
}

}  // namespace sphfsi::waves
