// sphfsi: wave height and period of a surface-elevation record by zero up-crossing (or down-crossing) analysis
// (IAHR/PIANC 1986 list of sea-state parameters; Goda 2010, Random Seas and Design of Maritime Structures, sec. 2.2).
//
// Within the analysis window [t_start, t_end] the mean elevation is removed; a wave runs from one up-crossing of
// the mean level to the next (crossing times linearly interpolated between samples); its height is the crest
// maximum minus the trough minimum between those crossings and its period the time between them. Only complete
// waves inside the window count. NaN samples (a gauge that saw no fluid) are rejected.
#pragma once

#include <sphfsi/core/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace sphfsi::analysis {

enum class Crossing { up, down };

struct ZeroCrossingWaves {
  std::vector<double> heights;  ///< H of each complete wave, m
  std::vector<double> periods;  ///< T of each complete wave, s
  double mean_level{0};         ///< mean elevation over the window (removed before the analysis), m
  double mean_height{0};        ///< mean H, m
  double rms_height{0};         ///< H_rms = sqrt(mean H^2), m
  double height_std{0};         ///< sample standard deviation of H (0 for a single wave), m
  double mean_period{0};        ///< mean T, s
  std::size_t count() const noexcept { return heights.size(); }
};

/// Zero-crossing analysis of eta(t) over [t_start, t_end]. Throws InputError for mismatched or non-increasing
/// times, NaN elevations inside the window, or a window holding no complete wave.
inline ZeroCrossingWaves zero_crossing_analysis(std::span<const double> time, std::span<const double> eta,
                                                double t_start, double t_end, Crossing crossing = Crossing::up) {
  if (time.size() != eta.size())
    throw InputError(fmt::format("zero_crossing_analysis: {} times but {} elevations", time.size(), eta.size()));
  if (!(t_end > t_start))
    throw InputError(
        fmt::format("zero_crossing_analysis: t_end = {} s must be greater than t_start = {} s", t_end, t_start));
  std::vector<double> t, e;
  for (std::size_t i = 0; i < time.size(); ++i) {
    if (i > 0 && !(time[i] > time[i - 1]))
      throw InputError(fmt::format("zero_crossing_analysis: times must increase (t[{}] = {} after t[{}] = {})", i,
                                   time[i], i - 1, time[i - 1]));
    if (time[i] < t_start || time[i] > t_end) continue;
    if (!std::isfinite(eta[i]))
      throw InputError(fmt::format("zero_crossing_analysis: elevation at t = {} s is not finite", time[i]));
    t.push_back(time[i]);
    e.push_back(eta[i]);
  }
  ZeroCrossingWaves out;
  if (e.size() < 3)
    throw InputError(fmt::format("zero_crossing_analysis: only {} samples in [{}, {}] s", e.size(), t_start, t_end));
  double mean = 0;
  for (double v : e) mean += v;
  mean /= double(e.size());
  out.mean_level = mean;
  const double sign = crossing == Crossing::up ? 1.0 : -1.0;
  for (double& v : e) v = sign * (v - mean);

  // crossing i -> i+1 where e[i] < 0 <= e[i+1]
  std::vector<double> crossing_time;
  std::vector<std::size_t> crossing_index;  // first sample after the crossing
  for (std::size_t i = 0; i + 1 < e.size(); ++i) {
    if (e[i] < 0 && e[i + 1] >= 0) {
      crossing_time.push_back(t[i] + (t[i + 1] - t[i]) * (-e[i]) / (e[i + 1] - e[i]));
      crossing_index.push_back(i + 1);
    }
  }
  for (std::size_t w = 0; w + 1 < crossing_time.size(); ++w) {
    const auto first = e.begin() + std::ptrdiff_t(crossing_index[w]);
    const auto last = e.begin() + std::ptrdiff_t(crossing_index[w + 1]);
    const auto [lo, hi] = std::minmax_element(first, last);
    out.heights.push_back(*hi - *lo);
    out.periods.push_back(crossing_time[w + 1] - crossing_time[w]);
  }
  if (out.heights.empty())
    throw InputError(fmt::format("zero_crossing_analysis: no complete wave in [{}, {}] s ({} crossings)", t_start,
                                 t_end, crossing_time.size()));
  const double n = double(out.count());
  double sum = 0, sum2 = 0, tsum = 0;
  for (std::size_t w = 0; w < out.count(); ++w) {
    sum += out.heights[w];
    sum2 += out.heights[w] * out.heights[w];
    tsum += out.periods[w];
  }
  out.mean_height = sum / n;
  out.rms_height = std::sqrt(sum2 / n);
  out.mean_period = tsum / n;
  if (out.count() > 1) {
    double var = 0;
    for (double hgt : out.heights) var += (hgt - out.mean_height) * (hgt - out.mean_height);
    out.height_std = std::sqrt(var / (n - 1));
  }
  return out;
}

}  // namespace sphfsi::analysis
