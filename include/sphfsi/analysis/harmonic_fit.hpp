// sphfsi: the periodic part of a record with a slow drift, by least squares: y(t) = sum_{p <= P} c_p tau^p
// + sum_{n = 1..N} (a_n cos n omega t + b_n sin n omega t), tau = (t - t_mid) / (half the window). The amplitude of
// harmonic n is sqrt(a_n^2 + b_n^2). Used for a plant's tip in waves: its wave-frequency excursion, apart from the
// slow wander of its mean position, which the half peak-to-peak of the record counts in full.
//
// With a whole number of periods in the window and samples evenly spaced, the harmonics are orthogonal to each other
// (discrete Fourier series); the polynomial is not orthogonal to them, which is why they are fitted together rather
// than the drift removed first. Solved through Eigen's column-pivoting QR of the design matrix.
#pragma once

#include <sphfsi/core/error.hpp>

#include <fmt/format.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <vector>

namespace sphfsi::analysis {

struct HarmonicFit {
  std::vector<double> amplitude;  ///< amplitude of harmonic n at [n - 1], n = 1..N (units of y)
  std::vector<double> phase;      ///< phase phi_n of a_n cos n omega t + b_n sin n omega t = A_n cos(n omega t - phi_n)
  std::vector<double> drift;      ///< polynomial coefficients c_0..c_P in tau = (t - t_mid) / (half the window)
  double mean{0};                 ///< mean of the fitted drift over the window (units of y)
  double drift_range{0};          ///< max - min of the fitted drift over the window (units of y)
  double residual_rms{0};         ///< rms of y minus the fit (units of y)
  std::size_t samples{0};

  /// Half the peak-to-peak of the fitted periodic part sum_n A_n cos(n theta - phi_n) over one period (on 2,000
  /// phases: relative error below 2e-6 of the largest amplitude): the excursion about the drifting mean.
  double periodic_half_range() const {
    const int grid = 2000;
    double lo = 0, hi = 0;
    for (int k = 0; k < grid; ++k) {
      const double theta = 2 * std::numbers::pi * k / grid;
      double v = 0;
      for (std::size_t n = 0; n < amplitude.size(); ++n) v += amplitude[n] * std::cos(double(n + 1) * theta - phase[n]);
      lo = k == 0 ? v : std::min(lo, v), hi = k == 0 ? v : std::max(hi, v);
    }
    return 0.5 * (hi - lo);
  }
};

/// Least-squares fit of a drift polynomial of degree `drift_degree` and `harmonics` harmonics of the angular
/// frequency `omega` to (t_i, y_i) with t_i in [t_start, t_end]. Throws InputError for mismatched sizes, a
/// non-finite or non-positive omega, a window shorter than one period, non-finite samples inside it, or fewer
/// samples than twice the unknowns.
inline HarmonicFit fit_harmonics(std::span<const double> time, std::span<const double> y, double omega, double t_start,
                                 double t_end, int harmonics = 1, int drift_degree = 2) {
  if (time.size() != y.size())
    throw InputError(
        fmt::format("fit_harmonics: {} times but {} values (valid: the same count)", time.size(), y.size()));
  if (!(std::isfinite(omega) && omega > 0))
    throw InputError(fmt::format("fit_harmonics: omega = {} rad/s: valid range is (0, inf)", omega));
  if (harmonics < 1 || harmonics > 16)
    throw InputError(fmt::format("fit_harmonics: {} harmonics: valid range is [1, 16]", harmonics));
  if (drift_degree < 0 || drift_degree > 4)
    throw InputError(fmt::format("fit_harmonics: drift degree {}: valid range is [0, 4]", drift_degree));
  const double period = 2 * std::numbers::pi / omega;
  if (!(t_end - t_start >= period))
    throw InputError(
        fmt::format("fit_harmonics: window [{}, {}] s is shorter than one period {} s (valid: at least "
                    "one period)",
                    t_start, t_end, period));
  std::vector<double> t, v;
  for (std::size_t i = 0; i < time.size(); ++i) {
    if (time[i] < t_start || time[i] > t_end) continue;
    if (!std::isfinite(y[i]) || !std::isfinite(time[i]))
      throw InputError(fmt::format("fit_harmonics: sample at t = {} s is not finite", time[i]));
    t.push_back(time[i]);
    v.push_back(y[i]);
  }
  const std::size_t unknowns = std::size_t(drift_degree + 1 + 2 * harmonics);
  if (t.size() < 2 * unknowns)
    throw InputError(fmt::format("fit_harmonics: {} samples in [{}, {}] s for {} unknowns (valid: at least {})",
                                 t.size(), t_start, t_end, unknowns, 2 * unknowns));
  const double mid = 0.5 * (t_start + t_end), half = 0.5 * (t_end - t_start);
  Eigen::MatrixXd design(Eigen::Index(t.size()), Eigen::Index(unknowns));
  Eigen::VectorXd rhs(Eigen::Index(t.size()));
  for (std::size_t i = 0; i < t.size(); ++i) {
    const auto row = Eigen::Index(i);
    const double tau = (t[i] - mid) / half;
    for (int p = 0; p <= drift_degree; ++p) design(row, p) = std::pow(tau, p);
    for (int n = 1; n <= harmonics; ++n) {
      design(row, drift_degree + 2 * n - 1) = std::cos(n * omega * t[i]);
      design(row, drift_degree + 2 * n) = std::sin(n * omega * t[i]);
    }
    rhs(row) = v[i];
  }
  const Eigen::VectorXd c = design.colPivHouseholderQr().solve(rhs);
  HarmonicFit fit;
  fit.samples = t.size();
  for (int p = 0; p <= drift_degree; ++p) fit.drift.push_back(c(p));
  for (int n = 1; n <= harmonics; ++n) {
    const double a = c(drift_degree + 2 * n - 1), b = c(drift_degree + 2 * n);
    fit.amplitude.push_back(std::hypot(a, b));
    fit.phase.push_back(std::atan2(b, a));
  }
  // the drift's mean over tau in [-1, 1] (the mean of tau^p is 1 / (p + 1) for even p, 0 for odd), and its range on
  // 201 points of tau (a quadratic's vertex between two points is missed by at most |c_2| 0.005^2)
  for (int p = 0; p <= drift_degree; p += 2) fit.mean += c(p) / (p + 1);
  const int grid = 200;
  double lo = 0, hi = 0;
  for (int k = 0; k <= grid; ++k) {
    const double tau = -1 + 2.0 * k / grid;
    double d = 0;
    for (int p = drift_degree; p >= 0; --p) d = d * tau + c(p);
    lo = k == 0 ? d : std::min(lo, d), hi = k == 0 ? d : std::max(hi, d);
  }
  fit.drift_range = hi - lo;
  fit.residual_rms = std::sqrt((design * c - rhs).squaredNorm() / double(t.size()));
  return fit;
}

}  // namespace sphfsi::analysis
