// sphfsi: one step of the classical fourth-order Runge-Kutta method for a small ODE system held in a std::array,
// shared by the reference solutions of analysis/ (elastica.hpp, reconfiguration.hpp).
#pragma once

#include <array>
#include <cstddef>

namespace sphfsi::analysis {

/// Advances y by one classical RK4 step of size h (negative: backwards) of y' = rate(y).
template <class T, std::size_t N, class Rate>
void runge_kutta4_step(std::array<T, N>& y, T h, Rate&& rate) {
  const std::array<T, N> k1 = rate(y);
  std::array<T, N> y2, y3, y4;
  for (std::size_t c = 0; c < N; ++c) y2[c] = y[c] + T(0.5) * h * k1[c];
  const std::array<T, N> k2 = rate(y2);
  for (std::size_t c = 0; c < N; ++c) y3[c] = y[c] + T(0.5) * h * k2[c];
  const std::array<T, N> k3 = rate(y3);
  for (std::size_t c = 0; c < N; ++c) y4[c] = y[c] + h * k3[c];
  const std::array<T, N> k4 = rate(y4);
  for (std::size_t c = 0; c < N; ++c) y[c] += h / 6 * (k1[c] + 2 * k2[c] + 2 * k3[c] + k4[c]);
}

}  // namespace sphfsi::analysis
