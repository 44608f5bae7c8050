// sphfsi: comparison of a simulated gate-tip displacement with the Antoci et al. (2007) experiment, and the
// fluid-penetration diagnostic of FSI runs.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/io/csv.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace sphfsi::scenes {

template <class T>
struct GateTipRecord {
  std::vector<T> time, dx, dy;
  void add(T t, T x, T y) {
    time.push_back(t);
    dx.push_back(x);
    dy.push_back(y);
  }
  /// Linear interpolation of a component at time t; NaN outside the recorded range.
  T at(const std::vector<T>& v, T t) const {
    if (time.empty() || t < time.front() || t > time.back()) return std::numeric_limits<T>::quiet_NaN();
    const auto it = std::upper_bound(time.begin(), time.end(), t);
    if (it == time.end()) return v.back();
    const std::size_t j = static_cast<std::size_t>(it - time.begin());
    if (j == 0) return v.front();
    const T w = (t - time[j - 1]) / (time[j] - time[j - 1]);
    return (T(1) - w) * v[j - 1] + w * v[j];
  }
};

template <class T>
struct GateTipComparison {
  T rms_dx{0}, rms_dy{0};  ///< m
  std::size_t points{0};
};

/// RMS error at the experiment's times 0.04 ... min(0.36, t_max) s (experiment = mean of the two digitizations
/// where both exist). A time inside that window that the run did not reach makes the error NaN (a run that stopped
/// early has no score).
template <class T>
GateTipComparison<T> compare_gate_tip(const GateTipRecord<T>& sim, const io::CsvTable& data, T t_max = T(0.36)) {
  const auto t = data.column("t"), dx = data.column("dx"), dy = data.column("dy");
  const auto dx2 = data.column("dx_alt"), dy2 = data.column("dy_alt");
  GateTipComparison<T> c;
  T sx = 0, sy = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] < 0.039 || t[k] > std::min(0.361, double(t_max) + 1e-9)) continue;
    const T ex = std::isnan(dx2[k]) ? T(dx[k]) : T(0.5 * (dx[k] + dx2[k]));
    const T ey = std::isnan(dy2[k]) ? T(dy[k]) : T(0.5 * (dy[k] + dy2[k]));
    const T ex_sim = sim.at(sim.dx, T(t[k])), ey_sim = sim.at(sim.dy, T(t[k]));
    sx += (ex_sim - ex) * (ex_sim - ex);
    sy += (ey_sim - ey) * (ey_sim - ey);
    ++c.points;
  }
  if (c.points == 0) {  // the run ended before the first measured time: no score
    c.rms_dx = c.rms_dy = std::numeric_limits<T>::quiet_NaN();
    return c;
  }
  c.rms_dx = std::sqrt(sx / T(c.points));
  c.rms_dy = std::sqrt(sy / T(c.points));
  return c;
}

/// Number of fluid particles closer than half a particle spacing to a particle of solid `body`: fluid that has
/// penetrated the solid (0 for a coupling that keeps the phases apart).
template <class System>
std::size_t fluid_particles_inside_solid(const System& system, std::int32_t body) {
  using T = typename System::scalar_type;
  const auto& p = system.particles();
  std::vector<char> counted(p.size(), 0);
  std::size_t inside = 0;
  for (std::size_t s = 0; s < p.size(); ++s) {
    if (p.kind[s] != Kind::solid || p.body[s] != body) continue;
    const T dp = std::pow(p.mass[s] / p.density[s], T(1) / T(System::dimension));
    system.for_each_neighbor(s, [&](std::size_t f, const auto&, T r, T) {
      if (p.kind[f] == Kind::fluid && r < T(0.5) * dp && !counted[f]) {
        counted[f] = 1;
        ++inside;
      }
    });
  }
  return inside;
}

}  // namespace sphfsi::scenes
