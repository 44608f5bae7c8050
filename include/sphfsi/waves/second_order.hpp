// sphfsi: second-order (Stokes) regular waves in constant depth and the second-order piston wavemaker.
//
// A Stokes wave of height H (a = H/2), wave number k, angular frequency omega in depth h has, to second order,
//   eta = a cos(theta) + a_2 cos(2 theta),  theta = k x - omega t,
//   a_2 = (k H^2 / 16) cosh(kh) (2 + cosh 2kh) / sinh^3(kh)        (Stokes 1847; Dean & Dalrymple 1991, sec. 11.2)
// a bound harmonic that travels with the wave (2k, 2 omega). Its crest-to-trough height is still H.
//
// A piston moved with the first-order signal X = (S/2) sin(omega t) alone cannot satisfy the second-order
// boundary condition at the paddle: it sheds, besides the bound harmonic, a *free* wave of frequency 2 omega
// that travels with its own wave number k_2 (omega_2 = 2 omega on the dispersion relation, k_2 != 2 k). The two
// second harmonics beat along the flume with the beat length L_b = 2 pi / |k_2 - 2 k|, and so does the
// zero-crossing height (Madsen 1971, J. Geophys. Res. 76:8672; Schaffer 1996, J. Fluid Mech. 307:231).
// Madsen's second-order piston signal adds the paddle motion that cancels the free wave:
//   X(t) = (S/2) sin(omega t) + X_2 sin(2 omega t),
//   X_2  = (H^2 / (32 h)) (3 cosh(kh) / sinh^3(kh) - 2 / m_1),   m_1 = H / S (Biesel's piston ratio)   (Madsen 1971)
// The free wave the first-order paddle sheds is the one this extra motion radiates, with the opposite sign:
// amplitude a_2f = m_1(k_2 h) X_2 (Biesel's piston ratio H/S is the amplitude over the excursion amplitude, at
// the free wave's own k_2 h). Shallow-water check: m_1 -> kh and a_2 -> 3 H^2 / (16 k^2 h^3), so
// X_2 -> a_2 / (2 k h), the excursion that supplies the bound harmonic's flux at the paddle.
// Second-order theory holds while the bound harmonic does not raise a secondary crest in the trough, a_2 < a / 4,
// which in shallow water is the Ursell number U = H L^2 / h^3 < 8 pi^2 / 3 = 26.3 (Madsen 1971).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/waves/linear_theory.hpp>

#include <cmath>
#include <numbers>

namespace sphfsi::waves {

/// Ursell number U = H L^2 / h^3 of a wave of height H (m): the ratio of nonlinearity to dispersion.
template <Real T>
T ursell_number(const LinearWave<T>& wave, T height) {
  require_positive("ursell_number height (m)", height);
  return height * wave.wavelength * wave.wavelength / (wave.depth * wave.depth * wave.depth);
}

/// Largest Ursell number of Madsen's (1971) second-order generation, 8 pi^2 / 3 (a_2 < a / 4 in shallow water).
template <Real T>
constexpr T second_order_ursell_limit() {
  return T(8) * std::numbers::pi_v<T> * std::numbers::pi_v<T> / T(3);
}

/// Amplitude a_2 of the bound second harmonic of a Stokes wave of height H (m), m (see the header).
template <Real T>
T stokes_second_harmonic_amplitude(const LinearWave<T>& wave, T height) {
  require_positive("stokes_second_harmonic_amplitude height (m)", height);
  const long double kh = wave.kh(), s = std::sinh(kh);
  return T((long double)(wave.wave_number) * height * height / 16 * std::cosh(kh) * (2 + std::cosh(2 * kh)) /
           (s * s * s));
}

/// Amplitude X_2 (m) of Madsen's (1971) second-harmonic piston excursion X_2 sin(2 omega t) for a wave of height
/// H (m): X_2 = (H^2 / (32 h)) (3 cosh kh / sinh^3 kh - 2 / m_1), m_1 = H / S of the piston.
template <Real T>
T madsen_piston_second_harmonic(const LinearWave<T>& wave, T height) {
  require_positive("madsen_piston_second_harmonic height (m)", height);
  const long double kh = wave.kh(), s = std::sinh(kh);
  const long double m1 = piston_height_to_stroke(double(kh));
  return T((long double)(height)*height / (32 * (long double)(wave.depth)) *
           (3 * std::cosh(kh) / (s * s * s) - 2 / m1));
}

/// The second-harmonic waves in front of a piston driven at first order only (no Madsen correction).
template <Real T>
struct FreeSecondHarmonic {
  T wave_number;  ///< k_2 of the free wave, omega_2 = 2 omega on the dispersion relation, rad/m
  T amplitude;    ///< a_2f = m_1(k_2 h) X_2, m (enters eta with a minus sign at the paddle, see the header)
  T beat_length;  ///< L_b = 2 pi / |k_2 - 2 k|, m
};

/// The free second harmonic that a first-order piston sheds for a target wave of height H (m).
template <Real T>
FreeSecondHarmonic<T> free_second_harmonic(const LinearWave<T>& wave, T height) {
  FreeSecondHarmonic<T> f{};
  f.wave_number = waves::wave_number(wave.period / T(2), wave.depth, wave.gravity);
  f.amplitude = piston_height_to_stroke(f.wave_number * wave.depth) * madsen_piston_second_harmonic(wave, height);
  f.beat_length = T(2) * std::numbers::pi_v<T> / std::abs(f.wave_number - T(2) * wave.wave_number);
  return f;
}

/// Second-order surface elevation eta(x, t) (m) in front of a piston at x = 0 in steady state (evanescent modes
/// left out): the Stokes wave of height H, and, when the paddle is driven at first order only
/// (`second_order_paddle` false), the free second harmonic it sheds, which cancels the bound one at the paddle in
/// the shallow-water limit.
template <Real T>
T piston_wave_elevation(const LinearWave<T>& wave, T height, bool second_order_paddle, T x, T t) {
  const T theta = wave.wave_number * x - wave.angular_frequency * t;
  T eta = T(0.5) * height * std::cos(theta) + stokes_second_harmonic_amplitude(wave, height) * std::cos(T(2) * theta);
  if (!second_order_paddle) {
    const auto f = free_second_harmonic(wave, height);
    eta -= f.amplitude * std::cos(f.wave_number * x - T(2) * wave.angular_frequency * t);
  }
  return eta;
}

}  // namespace sphfsi::waves
