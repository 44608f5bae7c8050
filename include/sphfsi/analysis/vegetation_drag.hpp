// sphfsi: wave decay over vegetation and the bulk drag coefficient it implies.
//
// Dalrymple, Kirby & Hwang (1984), J. Waterway Port Coastal Ocean Eng. 110:67, regular linear waves over rigid
// stems of height l_s (emergent: l_s = h) in depth h, frontal width b_v, N stems per m^2, drag coefficient C_D:
//   H(x) = H0 / (1 + alpha x),
//   alpha = (4 / (9 pi)) C_D b_v N H0 k (sinh^3(k l_s) + 3 sinh(k l_s)) / ((sinh 2kh + 2kh) sinh kh).
// For flexible blades l_s is replaced by the effective length l_e (Luhar & Nepf 2011).
//
// fit_decay() fits H0 and alpha to measured or simulated H(x) by non-linear least squares on H itself
// (Gauss-Newton from the straight-line fit of 1/H = 1/H0 + (alpha/H0) x, which is exact for exact data). The
// parameter covariance is s^2 (J^T J)^-1, s^2 = RSS / (n - p), the usual asymptotic estimate for independent
// errors of equal variance. drag_coefficient() inverts alpha for C_D = alpha / (b_v N H0 K) (K the wave factor
// above) and propagates the fit's covariance of (H0, alpha) to first order (delta method):
//   var C_D = (dC/dalpha)^2 var alpha + (dC/dH0)^2 var H0 + 2 (dC/dalpha)(dC/dH0) cov(alpha, H0).
// Partial standing waves in a flume make the scatter of H(x) correlated in x; the standard error then
// understates the true uncertainty, which callers should say.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/waves/linear_theory.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <span>

namespace sphfsi::analysis {

/// Stem field of a Dalrymple-type meadow.
struct StemField {
  double stem_height{0};    ///< l_s (or the effective length l_e of flexible blades), m
  double frontal_width{0};  ///< b_v, m
  double density{0};        ///< N, stems per m^2
  void validate() const {
    require_positive("StemField::stem_height (m)", stem_height);
    require_positive("StemField::frontal_width (m)", frontal_width);
    require_positive("StemField::density (stems/m^2)", density);
  }
};

/// K in alpha = C_D b_v N H0 K: (4 / (9 pi)) k (sinh^3(k l_s) + 3 sinh(k l_s)) / ((sinh 2kh + 2kh) sinh kh), 1/m
/// (alpha in 1/m, H0 in m, b_v N in 1/m).
inline double dalrymple_wave_factor(double wave_number, double depth, double stem_height) {
  require_positive("dalrymple_wave_factor wave_number k (rad/m)", wave_number);
  require_positive("dalrymple_wave_factor depth h (m)", depth);
  require_in_range("dalrymple_wave_factor stem_height l_s (m)", stem_height, 1e-12, depth);
  const double k = wave_number, kh = k * depth, s = std::sinh(k * stem_height);
  return 4.0 / (9.0 * std::numbers::pi) * k * (s * s * s + 3.0 * s) /
         ((std::sinh(2.0 * kh) + 2.0 * kh) * std::sinh(kh));
}

/// Decay coefficient alpha (1/m) of Dalrymple et al. (1984) for a given C_D.
inline double dalrymple_alpha(double drag_coefficient, const StemField& stems, double incident_height,
                              double wave_number, double depth) {
  stems.validate();
  require_positive("dalrymple_alpha drag_coefficient C_D", drag_coefficient);
  require_positive("dalrymple_alpha incident_height H0 (m)", incident_height);
  return drag_coefficient * stems.frontal_width * stems.density * incident_height *
         dalrymple_wave_factor(wave_number, depth, stems.stem_height);
}

/// H(x) = H0 / (1 + alpha x) fitted by least squares, with the covariance of the estimates.
struct DecayFit {
  double incident_height{0};  ///< H0, m
  double alpha{0};            ///< 1/m
  double var_height{0}, var_alpha{0}, cov_height_alpha{0};
  double rms_residual{0};  ///< sqrt(RSS / n), m
  std::size_t points{0};
  bool incident_height_fixed{false};
  double se_alpha() const { return std::sqrt(var_alpha); }
  double se_height() const { return std::sqrt(var_height); }
  double height_at(double x) const { return incident_height / (1.0 + alpha * x); }
};

/// Fits H0 and alpha (or alpha alone when `fixed_incident_height` is given) to the points (x_i, H_i).
/// Needs at least 3 points (2 with H0 fixed), positive finite heights and at least two distinct x.
inline DecayFit fit_decay(std::span<const double> x, std::span<const double> height,
                          std::optional<double> fixed_incident_height = std::nullopt) {
  const std::size_t n = x.size();
  if (height.size() != n) throw InputError(fmt::format("fit_decay: {} positions but {} heights", n, height.size()));
  const std::size_t parameters = fixed_incident_height ? 1 : 2;
  if (n < parameters + 1)
    throw InputError(
        fmt::format("fit_decay: {} points given: valid range is >= {} (one more than the {} fitted "
                    "parameters, for an uncertainty)",
                    n, parameters + 1, parameters));
  for (std::size_t i = 0; i < n; ++i) {
    require_finite("fit_decay x (m)", x[i]);
    require_positive("fit_decay H (m)", height[i]);
    require_finite("fit_decay H (m)", height[i]);
  }
  if (fixed_incident_height) require_positive("fit_decay fixed incident height H0 (m)", *fixed_incident_height);
  double xmin = x[0], xmax = x[0];
  for (double v : x) xmin = std::min(xmin, v), xmax = std::max(xmax, v);
  if (!(xmax > xmin)) throw InputError("fit_decay: all points have the same x: the decay cannot be fitted");

  // start: 1/H = a + b x (a = 1/H0, b = alpha/H0), by ordinary least squares (a fixed when H0 is)
  double H0, alpha;
  {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double y = 1.0 / height[i];
      sx += x[i], sy += y, sxx += x[i] * x[i], sxy += x[i] * y;
    }
    if (fixed_incident_height) {
      const double a = 1.0 / *fixed_incident_height;
      const double b = sxx > 0 ? (sxy - a * sx) / sxx : 0.0;
      H0 = *fixed_incident_height, alpha = b / a;
    } else {
      const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx), a = (sy - b * sx) / double(n);
      H0 = 1.0 / a, alpha = b / a;
    }
  }
  // Gauss-Newton on r_i = H_i - H0 / (1 + alpha x_i)
  double jtj[2][2] = {}, rss = 0;
  for (int iteration = 0; iteration < 50; ++iteration) {
    double a00 = 0, a01 = 0, a11 = 0, g0 = 0, g1 = 0;
    rss = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double d = 1.0 + alpha * x[i];
      if (!(d > 0))
        throw InputError(
            fmt::format("fit_decay: the fit reached 1 + alpha x <= 0 at x = {} m (alpha = {} 1/m): "
                        "the data do not follow H0 / (1 + alpha x)",
                        x[i], alpha));
      const double r = height[i] - H0 / d;
      const double j0 = 1.0 / d, j1 = -H0 * x[i] / (d * d);
      a00 += j0 * j0, a01 += j0 * j1, a11 += j1 * j1, g0 += j0 * r, g1 += j1 * r;
      rss += r * r;
    }
    jtj[0][0] = a00, jtj[0][1] = jtj[1][0] = a01, jtj[1][1] = a11;
    double d_H0 = 0, d_alpha = 0;
    if (fixed_incident_height) {
      d_alpha = g1 / a11;
    } else {
      const double det = a00 * a11 - a01 * a01;
      d_H0 = (a11 * g0 - a01 * g1) / det;
      d_alpha = (a00 * g1 - a01 * g0) / det;
    }
    H0 += d_H0, alpha += d_alpha;
    if (std::abs(d_alpha) <= 1e-13 * (std::abs(alpha) + 1e-12) && std::abs(d_H0) <= 1e-13 * H0) break;
  }
  // final residuals and Jacobian at the solution
  double a00 = 0, a01 = 0, a11 = 0;
  rss = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = 1.0 + alpha * x[i];
    const double r = height[i] - H0 / d, j0 = 1.0 / d, j1 = -H0 * x[i] / (d * d);
    a00 += j0 * j0, a01 += j0 * j1, a11 += j1 * j1, rss += r * r;
  }
  DecayFit fit;
  fit.incident_height = H0;
  fit.alpha = alpha;
  fit.points = n;
  fit.incident_height_fixed = bool(fixed_incident_height);
  fit.rms_residual = std::sqrt(rss / double(n));
  const double s2 = rss / double(n - parameters);
  if (fixed_incident_height) {
    fit.var_alpha = s2 / a11;
  } else {
    const double det = a00 * a11 - a01 * a01;
    fit.var_height = s2 * a11 / det;
    fit.var_alpha = s2 * a00 / det;
    fit.cov_height_alpha = -s2 * a01 / det;
  }
  return fit;
}

/// Bulk drag coefficient and its standard error from a decay fit.
struct DragCoefficient {
  double value{0};           ///< C_D
  double standard_error{0};  ///< first-order propagation of the fit covariance
};

/// Inverts alpha = C_D b_v N H0 K for C_D (K = dalrymple_wave_factor) with the fitted H0 and alpha.
inline DragCoefficient drag_coefficient(const DecayFit& fit, const StemField& stems, double wave_number, double depth) {
  stems.validate();
  const double K = dalrymple_wave_factor(wave_number, depth, stems.stem_height);
  const double scale = stems.frontal_width * stems.density * K;
  DragCoefficient c;
  c.value = fit.alpha / (scale * fit.incident_height);
  const double d_alpha = 1.0 / (scale * fit.incident_height);
  const double d_H0 = -fit.alpha / (scale * fit.incident_height * fit.incident_height);
  const double var =
      d_alpha * d_alpha * fit.var_alpha + d_H0 * d_H0 * fit.var_height + 2.0 * d_alpha * d_H0 * fit.cov_height_alpha;
  c.standard_error = std::sqrt(std::max(var, 0.0));
  return c;
}

/// Keulegan-Carpenter number of a blade of width b in oscillatory flow of velocity amplitude U_m and period T:
/// KC = U_m T / b.
inline double keulegan_carpenter_number(double velocity_amplitude, double period, double width) {
  require_positive("keulegan_carpenter_number: velocity amplitude U_m (m/s)", velocity_amplitude);
  require_positive("keulegan_carpenter_number: period T (s)", period);
  require_positive("keulegan_carpenter_number: blade width b (m)", width);
  return velocity_amplitude * period / width;
}

/// Drag coefficient of a flat plate (a blade) normal to an oscillatory flow: C_D = max(10 KC^(-1/3), 1.95), the fit
/// of Luhar & Nepf (2016, J. Fluids Struct. 61:20) to the plate data of Keulegan & Carpenter (1958) and Sarpkaya &
/// O'Keefe (1996); 1.95 is the steady-flow value it tends to at large KC.
inline double oscillatory_plate_drag_coefficient(double keulegan_carpenter) {
  require_positive("oscillatory_plate_drag_coefficient: KC", keulegan_carpenter);
  return std::max(10.0 * std::cbrt(1.0 / keulegan_carpenter), 1.95);
}

}  // namespace sphfsi::analysis
