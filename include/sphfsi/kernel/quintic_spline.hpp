// sphfsi: quintic spline (M6) kernel, Morris, Fox & Zhu (1997), J. Comput. Phys. 136:214.
//   W(q) = sigma [ (3-q)_+^5 - 6 (2-q)_+^5 + 15 (1-q)_+^5 ],  q = r / h,  support 3h,
//   sigma = 7 / (478 pi h^2) in 2D, 1 / (120 pi h^3) in 3D.
// (The 3D value 3 / (359 pi h^3) found in parts of the literature is 0.28% too large: the radial integral
// 4 pi int_0^3 q^2 [...] dq = 4 pi (3^8 - 6 2^8 + 15) / 168 = 120 pi.)
#pragma once

#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <numbers>

namespace sphfsi {

template <int Dim>
  requires SpatialDimension<Dim>
struct QuinticSpline {
  static constexpr int dimension = Dim;
  static constexpr double support = 3.0;

  template <Real T>
  static constexpr T normalisation(T h) {
    const T pi = std::numbers::pi_v<T>;
    if constexpr (Dim == 2) return T(7) / (T(478) * pi * h * h);
    else return T(1) / (T(120) * pi * h * h * h);
  }

  template <Real T>
  T value(T r, T h) const {
    const T q = r / h;
    const T a = std::max(T(3) - q, T(0));
    const T b = std::max(T(2) - q, T(0));
    const T c = std::max(T(1) - q, T(0));
    const T a2 = a * a, b2 = b * b, c2 = c * c;
    return normalisation(h) * (a2 * a2 * a - T(6) * b2 * b2 * b + T(15) * c2 * c2 * c);
  }

  template <Real T>
  T derivative(T r, T h) const {
    const T q = r / h;
    const T a = std::max(T(3) - q, T(0));
    const T b = std::max(T(2) - q, T(0));
    const T c = std::max(T(1) - q, T(0));
    const T a2 = a * a, b2 = b * b, c2 = c * c;
    return normalisation(h) / h * T(-5) * (a2 * a2 - T(6) * b2 * b2 + T(15) * c2 * c2);
  }
};

}  // namespace sphfsi
