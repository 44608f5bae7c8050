// sphfsi: separation of incident and reflected regular waves from an array of gauges (Mansard & Funke 1980,
// Proc. 17th ICCE, "The measurement of incident and reflected spectra using a least squares method"; with two
// gauges it is the method of Goda & Suzuki 1976).
//
// At the wave frequency omega each gauge i at x_i records eta_i(t) = Re(Z_i exp(i omega t)) (plus a mean and other
// frequencies). A wave travelling towards +x, a cos(omega t - k x + phi), and one travelling towards -x,
// r cos(omega t + k x + psi), give
//     Z_i = C_I exp(-i k x_i) + C_R exp(+i k x_i),   |C_I| = a, |C_R| = r.
// Step 1 fits each record over the window [from, to] by least squares to c_i + A_i cos(omega t) + B_i sin(omega t)
// (Z_i = A_i - i B_i). Step 2 solves the over-determined system above for C_I and C_R by least squares (normal
// equations of the 2 x 2 complex system). The reflection coefficient is K_r = |C_R| / |C_I|.
//
// The system is singular when every pair of gauges is a multiple of half a wavelength apart (the two waves cannot be
// told apart there): the call fails unless det(M) >= 0.1 n^2 (M the normal matrix, n gauges; det = n^2 -
// |sum exp(2 i k x_i)|^2, equal to n^2 for well-spread gauges). Mansard & Funke recommend, for three gauges,
// x_12 = L / 10 and L / 6 < x_13 < L / 3 with x_13 != L / 5, 3 L / 10.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <fmt/format.h>

#include <cmath>
#include <complex>
#include <cstddef>
#include <numbers>
#include <span>
#include <vector>

namespace sphfsi::analysis {

/// Incident and reflected wave amplitudes at one frequency (lengths in the unit of eta).
template <Real T>
struct WaveSeparation {
  T incident_amplitude{0};      ///< a = |C_I|
  T reflected_amplitude{0};     ///< r = |C_R|
  T reflection_coefficient{0};  ///< K_r = r / a
  T residual{0};           ///< RMS over the gauges of |Z_i - C_I e^(-ikx_i) - C_R e^(ikx_i)| / a (0 for two gauges)
  std::size_t samples{0};  ///< samples per gauge in the window
};

/// Amplitude of the harmonic of angular frequency omega in (t, eta) over [from, to], as the complex Z of
/// eta = c + Re(Z exp(i omega t)) fitted by least squares (3 x 3 normal equations).
template <Real T>
std::complex<T> harmonic_amplitude(std::span<const T> t, std::span<const T> eta, T omega, T from, T to,
                                   std::size_t* count = nullptr) {
  if (t.size() != eta.size())
    throw InputError(fmt::format("harmonic_amplitude: {} times but {} values", t.size(), eta.size()));
  // sums for the basis (1, cos, sin)
  long double s[3][3] = {}, r[3] = {};
  std::size_t n = 0;
  for (std::size_t j = 0; j < t.size(); ++j) {
    if (t[j] < from || t[j] > to) continue;
    const long double b[3] = {1.0L, std::cos((long double)omega * t[j]), std::sin((long double)omega * t[j])};
    for (int p = 0; p < 3; ++p) {
      r[p] += b[p] * (long double)eta[j];
      for (int q = 0; q < 3; ++q) s[p][q] += b[p] * b[q];
    }
    ++n;
  }
  const long double period = 2.0L * std::numbers::pi_v<long double> / (long double)omega;
  if (n < 8 || (long double)(to - from) < period)
    throw InputError(
        fmt::format("harmonic_amplitude: the window [{}, {}] s holds {} samples (valid: at least 8 "
                    "over at least one period, {} s)",
                    double(from), double(to), n, double(period)));
  // Cramer's rule on the symmetric 3 x 3 system
  auto det3 = [](const long double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const long double d = det3(s);
  long double solution[3];
  for (int c = 0; c < 3; ++c) {
    long double m[3][3];
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) m[p][q] = q == c ? r[p] : s[p][q];
    solution[c] = det3(m) / d;
  }
  if (count) *count = n;
  return {T(solution[1]), T(-solution[2])};
}

/// Separates the incident (towards +x) and reflected (towards -x) waves of angular frequency omega and wave number k
/// from gauge records eta[i] at positions x[i], all sampled at times t, over [from, to] (Mansard & Funke 1980; see
/// the header). At least two gauges, not all a multiple of half a wavelength apart.
template <Real T>
WaveSeparation<T> separate_incident_reflected(std::span<const T> t, const std::vector<std::vector<T>>& eta,
                                              std::span<const T> x, T omega, T wave_number, T from, T to) {
  require_positive("separate_incident_reflected: omega (rad/s)", omega);
  require_positive("separate_incident_reflected: wave number k (rad/m)", wave_number);
  if (x.size() < 2 || eta.size() != x.size())
    throw InputError(
        fmt::format("separate_incident_reflected: {} gauge positions and {} records (valid: at least "
                    "two gauges, one record each)",
                    x.size(), eta.size()));
  using C = std::complex<T>;
  const std::size_t n = x.size();
  std::vector<C> z(n);
  WaveSeparation<T> out;
  for (std::size_t i = 0; i < n; ++i)
    z[i] = harmonic_amplitude<T>(t, std::span<const T>(eta[i]), omega, from, to, &out.samples);
  // normal equations of z_i = C_I e_i^* + C_R e_i, e_i = exp(i k x_i)
  C s2(0), rhs_i(0), rhs_r(0);
  for (std::size_t i = 0; i < n; ++i) {
    const C e = std::polar(T(1), wave_number * x[i]);
    s2 += e * e;
    rhs_i += e * z[i];             // conj(e^*) z
    rhs_r += std::conj(e) * z[i];  // conj(e) z
  }
  const T nn = T(n), det = nn * nn - std::norm(s2);
  if (!(det >= T(0.1) * nn * nn))
    throw InputError(
        fmt::format("separate_incident_reflected: the gauges cannot tell the two waves apart (det = "
                    "{:.3g} of n^2 = {}; valid: at least 0.1 n^2): they are spaced near multiples of "
                    "half a wavelength, {} m",
                    double(det), double(nn * nn), double(std::numbers::pi_v<T> / wave_number)));
  // A^H A [C_I; C_R] = A^H z with the rows (e_i^*, e_i) of A: [n, s2; conj(s2), n] [C_I; C_R] = [rhs_i; rhs_r]
  const C ci = (nn * rhs_i - s2 * rhs_r) / det;
  const C cr = (nn * rhs_r - std::conj(s2) * rhs_i) / det;
  out.incident_amplitude = std::abs(ci);
  out.reflected_amplitude = std::abs(cr);
  out.reflection_coefficient = out.reflected_amplitude / out.incident_amplitude;
  T sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const C e = std::polar(T(1), wave_number * x[i]);
    sum += std::norm(z[i] - ci * std::conj(e) - cr * e);
  }
  out.residual = std::sqrt(sum / nn) / out.incident_amplitude;
  return out;
}

}  // namespace sphfsi::analysis
