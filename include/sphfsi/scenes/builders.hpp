// sphfsi: scene builders: blocks of fluid on a lattice and box-shaped walls of either wall model.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/fluid/wcsph.hpp>

#include <array>
#include <cmath>
#include <cstdint>

namespace sphfsi {

/// Lattice of the given spacing: particle centres at lower + (i + 1/2) dp, covering [lower, upper].
template <int Dim, Real T, class F>
void for_each_lattice_point(const Vec<Dim, T>& lower, const Vec<Dim, T>& upper, T dp, F&& f) {
  std::array<std::int64_t, Dim> n{};
  for (int d = 0; d < Dim; ++d) n[d] = std::max<std::int64_t>(0, std::llround((upper[d] - lower[d]) / dp));
  std::array<std::int64_t, Dim> i{};
  std::int64_t total = 1;
  for (int d = 0; d < Dim; ++d) total *= n[d];
  for (std::int64_t k = 0; k < total; ++k) {
    std::int64_t rest = k;
    Vec<Dim, T> x;
    for (int d = 0; d < Dim; ++d) {
      i[d] = rest % n[d];
      rest /= n[d];
      x[d] = lower[d] + (T(i[d]) + T(0.5)) * dp;
    }
    f(x);
  }
}

/// Resolution of a scene: particle spacing dp and h = smoothing_ratio * dp.
template <Real T>
struct Resolution {
  T dp;                       ///< particle spacing, m
  T smoothing_ratio{T(1.3)};  ///< h / dp, [1, 3]

  void validate() const {
    require_positive("Resolution::dp (particle spacing, m)", dp);
    require_in_range("Resolution::smoothing_ratio (h/dp)", smoothing_ratio, T(1), T(3));
  }
  T h() const { return smoothing_ratio * dp; }
};

/// Fills the box [lower, upper] with fluid at rest in hydrostatic equilibrium below the free surface
/// z = surface (density from the EOS inverse of p = rho0 |g| (surface - z)). Returns the particle count.
template <class System>
std::size_t add_fluid_block(System& system, const Vec<System::dimension, typename System::scalar_type>& lower,
                            const Vec<System::dimension, typename System::scalar_type>& upper,
                            const Resolution<typename System::scalar_type>& res,
                            typename System::scalar_type surface, typename System::scalar_type gravity = 9.81) {
  using T = typename System::scalar_type;
  constexpr int Dim = System::dimension;
  res.validate();
  require_non_negative("add_fluid_block gravity (m/s^2)", gravity);
  const auto& eos = system.eos();
  const T rho0 = eos.reference_density();
  const T mass = rho0 * std::pow(res.dp, T(Dim));
  std::size_t added = 0;
  for_each_lattice_point<Dim, T>(lower, upper, res.dp, [&](const Vec<Dim, T>& x) {
    const T depth = std::max(surface - x[Dim - 1], T(0));
    const T rho = eos.density(rho0 * gravity * depth);
    system.particles().add(Kind::fluid, x, Vec<Dim, T>::Zero(), rho, mass, res.h());
    ++added;
  });
  return added;
}

/// Walls around the box [inner_lower, inner_upper] (open at the top). Dynamic walls: `layers` rows of
/// particles outside the box at (k + 1/2) dp from its faces. Repulsive walls: one row on the faces with spacing
/// dp and unit normals pointing into the box. Returns the particle count.
template <class System>
std::size_t add_box_walls(System& system, const Vec<System::dimension, typename System::scalar_type>& inner_lower,
                          const Vec<System::dimension, typename System::scalar_type>& inner_upper,
                          const Resolution<typename System::scalar_type>& res, WallModel model, int layers = 3,
                          std::int32_t body = 0) {
  using T = typename System::scalar_type;
  constexpr int Dim = System::dimension;
  using V = Vec<Dim, T>;
  res.validate();
  require_in_range("add_box_walls layers", layers, 1, 8);
  const T rho0 = system.eos().reference_density();
  const T mass = rho0 * std::pow(res.dp, T(Dim));
  std::size_t added = 0;
  const T tol = T(1e-6) * res.dp;
  if (model == WallModel::dynamic) {
    V lo = inner_lower, hi = inner_upper;
    for (int d = 0; d < Dim; ++d) {
      lo[d] -= T(layers) * res.dp;
      if (d < Dim - 1) hi[d] += T(layers) * res.dp;
    }
    for_each_lattice_point<Dim, T>(lo, hi, res.dp, [&](const V& x) {
      bool inside = true;
      for (int d = 0; d < Dim; ++d) inside = inside && x[d] > inner_lower[d] && x[d] < inner_upper[d] + tol;
      if (inside) return;
      system.particles().add(Kind::wall, x, V::Zero(), rho0, mass, res.h(), body);
      ++added;
    });
    return added;
  }
  // Repulsive walls: lattice of spacing dp on the faces (including edges), normals into the box.
  std::array<std::int64_t, Dim> n{};
  std::int64_t total = 1;
  for (int d = 0; d < Dim; ++d) {
    n[d] = std::llround((inner_upper[d] - inner_lower[d]) / res.dp) + 1;
    total *= n[d];
  }
  for (std::int64_t k = 0; k < total; ++k) {
    std::int64_t rest = k;
    V x, normal = V::Zero();
    bool on_face = false;
    for (int d = 0; d < Dim; ++d) {
      const std::int64_t i = rest % n[d];
      rest /= n[d];
      x[d] = inner_lower[d] + T(i) * res.dp;
      const bool at_lower = (i == 0), at_upper = (i == n[d] - 1) && d < Dim - 1;  // open top
      if (at_lower) normal[d] += T(1);
      if (at_upper) normal[d] -= T(1);
      on_face = on_face || at_lower || at_upper;
    }
    if (!on_face) continue;
    const std::size_t slot = system.particles().add(Kind::wall, x, V::Zero(), rho0, mass, res.h(), body);
    system.particles().normal[slot] = normal.normalized();
    ++added;
  }
  return added;
}

}  // namespace sphfsi
