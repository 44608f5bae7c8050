// sphfsi: ordinary least-squares straight line y = intercept + slope x, with the slope's standard error propagated
// from given errors of the y values. Used by the flume examples (wave decay: ln H against x / L; standing wave: the
// log of the envelope against t).
#pragma once

#include <sphfsi/core/error.hpp>

#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace sphfsi::analysis {

struct LineFit {
  double slope{0}, intercept{0};
  /// Standard error of the slope from the y errors given to fit_line (NaN when none were given).
  double slope_error{std::numeric_limits<double>::quiet_NaN()};
  std::size_t points{0};
};

/// Unweighted least squares through (x_i, y_i): slope = sum (x_i - mx)(y_i - my) / sum (x_i - mx)^2. The slope is
/// linear in the y_i, so independent errors s_i of y_i give var(slope) = sum ((x_i - mx) / Sxx)^2 s_i^2.
/// Throws InputError for fewer than two points, sizes that differ, or all x equal.
inline LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y,
                        const std::vector<double>& y_error = {}) {
  if (x.size() != y.size())
    throw InputError(fmt::format("fit_line: {} x values but {} y values (valid: the same count)", x.size(), y.size()));
  if (!y_error.empty() && y_error.size() != y.size())
    throw InputError(
        fmt::format("fit_line: {} y errors for {} points (valid: none or one per point)", y_error.size(), y.size()));
  if (x.size() < 2) throw InputError(fmt::format("fit_line: {} points given: valid range is >= 2", x.size()));
  const double n = double(x.size());
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= n, my /= n;
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  if (!(sxx > 0)) throw InputError("fit_line: all x values are equal: the slope is undefined (valid: two distinct x)");
  LineFit fit;
  fit.points = x.size();
  fit.slope = sxy / sxx;
  fit.intercept = my - fit.slope * mx;
  if (!y_error.empty()) {
    double variance = 0;
    for (std::size_t i = 0; i < x.size(); ++i) variance += std::pow((x[i] - mx) / sxx, 2) * y_error[i] * y_error[i];
    fit.slope_error = std::sqrt(variance);
  }
  return fit;
}

}  // namespace sphfsi::analysis
