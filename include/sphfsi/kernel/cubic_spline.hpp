// sphfsi: cubic B-spline (M4) kernel, Monaghan & Lattanzio (1985), A&A 149:135. The reference paper's choice.
//   W(q) = sigma [ (2 - q)_+^3 / 4 - (1 - q)_+^3 ],  q = r / h,  support 2h,
//   sigma = 10 / (7 pi h^2) in 2D, 1 / (pi h^3) in 3D.
// Written branch-free with (x)_+ = max(x, 0) so the pair loop can vectorize.
#pragma once

#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <numbers>

namespace sphfsi {

template <int Dim>
  requires SpatialDimension<Dim>
struct CubicSpline {
  static constexpr int dimension = Dim;
  static constexpr double support = 2.0;

  template <Real T>
  static constexpr T normalisation(T h) {
    const T pi = std::numbers::pi_v<T>;
    if constexpr (Dim == 2) return T(10) / (T(7) * pi * h * h);
    else return T(1) / (pi * h * h * h);
  }

  template <Real T>
  T value(T r, T h) const {
    const T q = r / h;
    const T a = std::max(T(2) - q, T(0));
    const T b = std::max(T(1) - q, T(0));
    return normalisation(h) * (T(0.25) * a * a * a - b * b * b);
  }

  template <Real T>
  T derivative(T r, T h) const {
    const T q = r / h;
    const T a = std::max(T(2) - q, T(0));
    const T b = std::max(T(1) - q, T(0));
    return normalisation(h) / h * (T(-0.75) * a * a + T(3) * b * b);
  }
};

}  // namespace sphfsi
