// sphfsi: the SmoothingKernel concept, the extension point for kernels.
//
// A kernel is a small trivially copyable struct (no virtual functions, no mutable static state, so it can be
// captured by value in any parallel loop or on a GPU) that provides:
//   static constexpr int    dimension;   // 2 or 3
//   static constexpr double support;     // support radius divided by h (W = 0 for r >= support * h)
//   template <Real T> T value(T r, T h) const;       // W(r, h), r >= 0, normalised to integrate to 1
//   template <Real T> T derivative(T r, T h) const;  // dW/dr (<= 0 inside the support)
#pragma once

#include <sphfsi/core/types.hpp>

#include <concepts>
#include <type_traits>

namespace sphfsi {

/// A smoothing kernel usable with scalar T (see the header comment for the full list of requirements).
template <class K, class T>
concept SmoothingKernel = std::is_trivially_copyable_v<K> && std::is_default_constructible_v<K> &&
    requires(const K& k, T r, T h) {
  { K::dimension } -> std::convertible_to<int>;
  { K::support } -> std::convertible_to<double>;
  { k.value(r, h) } -> std::same_as<T>;
  { k.derivative(r, h) } -> std::same_as<T>;
};

/// A kernel written for spatial dimension Dim (its normalisation depends on it). A named concept rather than a
/// parenthesized expression in ParticleSystem's requires clause, which clang-format 14 cannot format.
template <class K, int Dim>
concept KernelOfDimension = (K::dimension == Dim);

/// Gradient of W with respect to x_a, for dx = x_a - x_b and r = |dx|; zero at r = 0.
template <class K, int Dim, class T>
  requires SmoothingKernel<K, T>
inline Vec<Dim, T> kernel_gradient(const K& kernel, const Vec<Dim, T>& dx, T r, T h) {
  if (r <= T(0)) return Vec<Dim, T>::Zero();
  return dx * (kernel.derivative(r, h) / r);
}

/// Support radius of kernel K at smoothing length h.
template <class K, class T>
constexpr T support_radius(T h) {
  return static_cast<T>(K::support) * h;
}

}  // namespace sphfsi
