// sphfsi: the elastica of a cantilever under a dead tip load, the reference for large-deflection rods
// (solid/elastic_rod.hpp; docs/thin-blades.md).
//
// With the deflection angle theta(s) along the cantilever, s in units of its length L, and the load parameter
// alpha = P L^2 / (E I) of a tip load P normal to the clamp (Bisshopp & Drucker 1945, Q. Appl. Math. 3:272):
//   theta'' = -alpha cos(theta),  theta(0) = 0,  theta'(1) = 0,
//   x' = cos(theta),  y' = sin(theta).
// Solved by shooting on theta'(0) in (0, alpha] (theta'(1) < 0 at 0, > 0 at alpha) with bisection, each shot
// integrated by classical RK4 with 4000 steps (error about 1e-12).
#pragma once

#include <sphfsi/analysis/runge_kutta.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <array>
#include <cmath>
#include <utility>

namespace sphfsi::analysis {

/// Tip deflection and shortening (L - x_tip), both over L, of the elastica under the tip-load parameter alpha > 0.
template <Real T>
std::pair<T, T> elastica_tip_load(T alpha) {
  require_positive("elastica_tip_load alpha (P L^2 / EI)", alpha);
  const auto shoot = [alpha](T slope) {
    std::array<T, 4> y{T(0), slope, T(0), T(0)};  // theta, theta', x, deflection
    const auto rate = [alpha](const std::array<T, 4>& s) {
      return std::array<T, 4>{s[1], -alpha * std::cos(s[0]), std::cos(s[0]), std::sin(s[0])};
    };
    constexpr int steps = 4000;
    const T h = T(1) / steps;
    for (int i = 0; i < steps; ++i) runge_kutta4_step(y, h, rate);
    return y;
  };
  T lo = 0, hi = alpha;
  for (int i = 0; i < 60; ++i) {
    const T mid = T(0.5) * (lo + hi);
    (shoot(mid)[1] < 0 ? lo : hi) = mid;
  }
  const auto y = shoot(T(0.5) * (lo + hi));
  return {y[3], 1 - y[2]};
}

}  // namespace sphfsi::analysis
