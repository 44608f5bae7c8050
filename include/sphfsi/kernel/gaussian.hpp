// sphfsi: Gaussian kernel truncated at 3h (Gingold & Monaghan 1977; Liu & Liu 2003, eq. 3.xx),
//   W(q) = exp(-q^2) / (C pi^(D/2) h^D),  q = r / h < 3,
// with C the mass of the untruncated Gaussian inside q < 3, so the truncated kernel integrates exactly to 1:
//   C = 1 - exp(-9) in 2D,  C = erf(3) - 6 exp(-9) / sqrt(pi) in 3D.
// W jumps by about exp(-9) ~ 1.2e-4 of its peak at the cut-off; use it for comparisons, not production.
#pragma once

#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <cmath>
#include <numbers>

namespace sphfsi {

template <int Dim>
  requires SpatialDimension<Dim>
struct TruncatedGaussian {
  static constexpr int dimension = Dim;
  static constexpr double support = 3.0;

  template <Real T>
  static T normalisation(T h) {
    const double pi = std::numbers::pi;
    if constexpr (Dim == 2) {
      const double c = 1.0 - std::exp(-9.0);
      return static_cast<T>(1.0 / (c * pi)) / (h * h);
    } else {
      const double c = std::erf(3.0) - 6.0 * std::exp(-9.0) / std::sqrt(pi);
      return static_cast<T>(1.0 / (c * pi * std::sqrt(pi))) / (h * h * h);
    }
  }

  template <Real T>
  T value(T r, T h) const {
    const T q = r / h;
    return q < T(3) ? normalisation(h) * std::exp(-q * q) : T(0);
  }

  template <Real T>
  T derivative(T r, T h) const {
    const T q = r / h;
    return q < T(3) ? normalisation(h) / h * T(-2) * q * std::exp(-q * q) : T(0);
  }
};

}  // namespace sphfsi
