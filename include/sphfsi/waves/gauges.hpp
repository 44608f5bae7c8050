// sphfsi: numerical wave gauges: free-surface elevation at fixed x over time.
//
// The surface at a gauge is found from the kernel-interpolated fluid "colour" (Shepard sum of the fluid volume)
//   C(x) = sum_b (m_b / rho_b) W(|x - x_b|, h_b),   fluid particles b only,
// which is 1 inside the fluid and falls through 1/2 where half of the kernel support lies outside it, i.e. at
// the free surface (the same half-mass criterion as the wave gauges of DualSPHysics' MeasureTool, Crespo et al.
// 2015, Comput. Phys. Commun. 187:204). Along the vertical line at the gauge, C is sampled downwards from above
// the highest fluid particle near the line in steps of dp/4; the elevation is where C first reaches 1/2, linearly
// interpolated between the two samples that bracket it, minus the still-water level: eta = z(C = 1/2) - h.
// Spray or a drop above the surface would be taken as the surface; in a non-breaking flume there is none.
// The cost is O(N) per gauge and sample (one pass over the particles), negligible at one sample per ~100 steps.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/io/csv.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace sphfsi::waves {

/// Free-surface elevation above `still_level` at horizontal position x (vertical axis Dim - 1, gauge line along it,
/// other horizontal coordinates ignored: for 2D flumes). `dp` sets the sampling step (dp / 4). Returns NaN where
/// no fluid is within a kernel support of the line. Passive particles (fluid/adaptive_refinement.hpp) are left out.
template <class System>
typename System::scalar_type free_surface_elevation(const System& system, typename System::scalar_type x,
                                                    typename System::scalar_type still_level,
                                                    typename System::scalar_type dp) {
  using T = typename System::scalar_type;
  constexpr int Dim = System::dimension;
  static_assert(Dim == 2, "free_surface_elevation: vertical gauge lines are implemented for 2D flumes");
  const auto& p = system.particles();
  const auto& kernel = system.kernel();
  const T support = static_cast<T>(System::kernel_type::support);
  struct Near {
    T dx, z, volume, h;
  };
  std::vector<Near> near;
  T z_top = -std::numeric_limits<T>::max(), z_bottom = std::numeric_limits<T>::max();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid || p.passive[i]) continue;  // passive: a second resolution of the same water
    const T dx = p.position[i][0] - x, h = p.smoothing_length[i];
    if (std::abs(dx) >= support * h) continue;
    near.push_back({dx, p.position[i][Dim - 1], p.mass[i] / p.density[i], h});
    z_top = std::max(z_top, p.position[i][Dim - 1] + support * h);
    z_bottom = std::min(z_bottom, p.position[i][Dim - 1]);
  }
  if (near.empty()) return std::numeric_limits<T>::quiet_NaN();
  auto colour = [&](T z) {
    T c = T(0);
    for (const Near& b : near) {
      const T r = std::sqrt(b.dx * b.dx + (z - b.z) * (z - b.z));
      if (r < support * b.h) c += b.volume * kernel.value(r, b.h);
    }
    return c;
  };
  const T step = dp / T(4);
  T z_above = z_top, c_above = colour(z_above);
  for (T z = z_top - step; z >= z_bottom; z -= step) {
    const T c = colour(z);
    if (c >= T(0.5)) {
      const T s = (T(0.5) - c_above) / (c - c_above);  // c_above < 1/2 <= c
      return z_above + s * (z - z_above) - still_level;
    }
    z_above = z;
    c_above = c;
  }
  return std::numeric_limits<T>::quiet_NaN();
}

/// A row of wave gauges at fixed x, written as one CSV: t, then one column "eta_<x>" per gauge (m).
template <Real T>
class WaveGauges {
 public:
  /// gauge_x: positions, m; still_level: still-water surface height, m; dp: particle spacing, m.
  WaveGauges(std::vector<T> gauge_x, T still_level, T dp) : x_(std::move(gauge_x)), still_(still_level), dp_(dp) {
    if (x_.empty()) throw InputError("WaveGauges: no gauge positions given");
    for (T x : x_) require_finite("WaveGauges gauge position x (m)", x);
    require_finite("WaveGauges still_level (m)", still_level);
    require_positive("WaveGauges dp (m)", dp);
  }

  const std::vector<T>& positions() const noexcept { return x_; }
  /// Column name of gauge i in the CSV ("eta_" then x in m with 4 decimals); gauge_position() parses it back.
  std::string column_name(std::size_t i) const { return fmt::format("eta_{:.4f}", double(x_.at(i))); }

  /// Opens the CSV `path` (header: t, eta_<x>...).
  void open(const std::filesystem::path& path, std::string_view comment = {}) {
    std::vector<std::string> columns{"t"};
    for (std::size_t i = 0; i < x_.size(); ++i) columns.push_back(column_name(i));
    csv_.emplace(path, columns, comment);
  }

  /// Measures every gauge at time t, keeps the values (times(), series(i)) and writes a row if a CSV is open.
  template <class System>
  const std::vector<T>& sample(const System& system, T t) {
    last_.resize(x_.size());
    for (std::size_t i = 0; i < x_.size(); ++i) last_[i] = free_surface_elevation(system, x_[i], still_, dp_);
    times_.push_back(t);
    series_.resize(x_.size());
    for (std::size_t i = 0; i < x_.size(); ++i) series_[i].push_back(last_[i]);
    if (csv_) {
      std::vector<double> row{double(t)};
      for (T e : last_) row.push_back(double(e));
      csv_->write_row(row);
    }
    return last_;
  }

  const std::vector<T>& times() const noexcept { return times_; }
  const std::vector<T>& series(std::size_t i) const { return series_.at(i); }

 private:
  std::vector<T> x_;
  T still_, dp_;
  std::optional<io::CsvWriter> csv_;
  std::vector<T> last_, times_;
  std::vector<std::vector<T>> series_;
};

/// Gauge position parsed from a column name written by WaveGauges ("eta_<x>"); nullopt for other columns.
inline std::optional<double> gauge_position(std::string_view column) {
  if (column.size() <= 4 || column.substr(0, 4) != "eta_") return std::nullopt;
  try {
    std::size_t used = 0;
    const std::string rest(column.substr(4));
    const double x = std::stod(rest, &used);
    if (used != rest.size()) return std::nullopt;
    return x;
  } catch (...) {
    return std::nullopt;
  }
}

}  // namespace sphfsi::waves
