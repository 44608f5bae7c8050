// sphfsi: comparison of a simulated surge front with Martin & Moyce (1952).
//
// The measured curve's time origin is uncertain by the gate-opening time (the column needs a few hundredths of
// a second to be released). The aligned comparison shifts the simulated time so that the simulated front reaches
// the first measured position (x_f/a = 1.11, the end of the initial transient) at the measured time, then compares
// every later point. Both raw and aligned errors are reported; neither is hidden.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/io/csv.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace sphfsi::scenes {

template <class T>
struct SurgeFrontRecord {
  std::vector<T> time, front;  ///< normalised time T and front x_f / a, in increasing time
  void add(T t, T f) {
    time.push_back(t);
    front.push_back(f);
  }
  /// Linear interpolation of the front at time t (clamped to the recorded range).
  T front_at(T t) const {
    if (time.empty()) throw InputError("SurgeFrontRecord: no samples recorded");
    if (t <= time.front()) return front.front();
    if (t >= time.back()) return front.back();
    const auto it = std::upper_bound(time.begin(), time.end(), t);
    const std::size_t j = static_cast<std::size_t>(it - time.begin());
    const T w = (t - time[j - 1]) / (time[j] - time[j - 1]);
    return (T(1) - w) * front[j - 1] + w * front[j];
  }
  /// First time the front reaches x (linear interpolation); the last time if it never does.
  T time_reaching(T x) const {
    for (std::size_t j = 1; j < time.size(); ++j)
      if (front[j] >= x) {
        const T w = (x - front[j - 1]) / std::max(front[j] - front[j - 1], T(1e-12));
        return time[j - 1] + w * (time[j] - time[j - 1]);
      }
    return time.empty() ? T(0) : time.back();
  }
};

template <class T>
struct SurgeFrontComparison {
  struct Point {
    T time, measured, simulated_raw, simulated_aligned;
  };
  std::vector<Point> points;
  T shift{0};  ///< time shift of the alignment (simulated time = measured time - shift)
  T raw_max{0}, raw_rms{0}, aligned_max{0}, aligned_rms{0};  ///< relative errors in x_f / a
};

/// Compares with the experiment (columns `time`, `surge_front`) at every measured time inside the record.
template <class T>
SurgeFrontComparison<T> compare_surge_front(const SurgeFrontRecord<T>& sim, const io::CsvTable& data) {
  const auto& t_exp = data.column("time");
  const auto& x_exp = data.column("surge_front");
  SurgeFrontComparison<T> c;
  if (t_exp.empty()) throw InputError("surge-front data: no rows");
  c.shift = T(t_exp.front()) - sim.time_reaching(T(x_exp.front()));
  T raw2 = 0, al2 = 0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < t_exp.size(); ++k) {
    const T te = T(t_exp[k]), xe = T(x_exp[k]);
    if (te > sim.time.back()) break;
    typename SurgeFrontComparison<T>::Point p{te, xe, sim.front_at(te), sim.front_at(te - c.shift)};
    c.points.push_back(p);
    const T er = std::abs(p.simulated_raw - xe) / xe, ea = std::abs(p.simulated_aligned - xe) / xe;
    c.raw_max = std::max(c.raw_max, er);
    raw2 += er * er;
    if (k > 0) {  // the first point defines the alignment
      c.aligned_max = std::max(c.aligned_max, ea);
      al2 += ea * ea;
      ++n;
    }
  }
  c.raw_rms = std::sqrt(raw2 / std::max<std::size_t>(c.points.size(), 1));
  c.aligned_rms = std::sqrt(al2 / std::max<std::size_t>(n, 1));
  return c;
}

}  // namespace sphfsi::scenes
