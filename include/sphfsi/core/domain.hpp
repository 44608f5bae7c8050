// sphfsi: the axis-aligned box a scene lives in. A particle that leaves it stops the run with a diagnosis.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

namespace sphfsi {

template <int Dim, Real T>
struct Domain {
  Vec<Dim, T> lower;  ///< m
  Vec<Dim, T> upper;  ///< m

  Domain() : lower(Vec<Dim, T>::Zero()), upper(Vec<Dim, T>::Ones()) {}
  Domain(const Vec<Dim, T>& lo, const Vec<Dim, T>& hi) : lower(lo), upper(hi) {
    for (int d = 0; d < Dim; ++d) {
      require_finite("Domain::lower", lo[d]);
      require_finite("Domain::upper", hi[d]);
      if (!(hi[d] > lo[d]))
        throw InputError(fmt::format("Domain: upper[{}] = {} must be greater than lower[{}] = {}", d, hi[d], d, lo[d]));
    }
  }

  bool contains(const Vec<Dim, T>& x) const {
    for (int d = 0; d < Dim; ++d)
      if (!(x[d] >= lower[d] && x[d] <= upper[d])) return false;  // also false for NaN
    return true;
  }
};

}  // namespace sphfsi
