// sphfsi: Wendland C2 kernel, Wendland (1995), Adv. Comput. Math. 4:389; normalisation as in
// Dehnen & Aly (2012), MNRAS 425:1068, written with support 2h (the DualSPHysics convention):
//   W(q) = alpha (1 - q/2)_+^4 (2q + 1),  q = r / h,
//   alpha = 7 / (4 pi h^2) in 2D, 21 / (16 pi h^3) in 3D.
#pragma once

#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <numbers>

namespace sphfsi {

template <int Dim>
  requires SpatialDimension<Dim>
struct WendlandC2 {
  static constexpr int dimension = Dim;
  static constexpr double support = 2.0;

  template <Real T>
  static constexpr T normalisation(T h) {
    const T pi = std::numbers::pi_v<T>;
    if constexpr (Dim == 2) return T(7) / (T(4) * pi * h * h);
    else return T(21) / (T(16) * pi * h * h * h);
  }

  template <Real T>
  T value(T r, T h) const {
    const T q = r / h;
    const T a = std::max(T(1) - T(0.5) * q, T(0));
    return normalisation(h) * a * a * a * a * (T(2) * q + T(1));
  }

  template <Real T>
  T derivative(T r, T h) const {
    const T q = r / h;
    const T a = std::max(T(1) - T(0.5) * q, T(0));
    return normalisation(h) / h * T(-5) * q * a * a * a;
  }
};

}  // namespace sphfsi
