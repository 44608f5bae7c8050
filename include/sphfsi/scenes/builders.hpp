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
                            const Resolution<typename System::scalar_type>& res, typename System::scalar_type surface,
                            typename System::scalar_type gravity = 9.81) {
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

/// Walls around the box [inner_lower, inner_upper] (open at the top). Returns the particle count.
///
/// Dynamic walls (Crespo et al. 2007) and extrapolated walls (Adami et al. 2012): `layers` rows of particles outside
/// the box at (k + 1/2) dp from its faces, so the fluid (whose first row sits dp/2 inside a face) sees a full kernel
/// support of wall particles.
///
/// Repulsive walls (Monaghan & Kos 1999; Rogers & Dalrymple 2008): one row of boundary particles ON each face,
/// each carrying that face's unit normal (into the box); `layers` is ignored. Every face is a complete row of its
/// own, corners and edges included (a corner holds one particle per face that meets there), so the weights
/// P(xi) of each face sum to one all along it and the push near a corner is the same as mid-face. The spacing
/// along each face direction is the face extent divided by round(extent / dp): exactly dp when the box is a
/// whole number of particle spacings wide (give FluidParameters::repulsive.boundary_spacing = dp then; see
/// repulsive_wall_spacing()). The fluid block's first row at dp/2 from a face then sits where the repulsion
/// balances the pressure of a column of depth c0^2 / (100 g) (docs/walls.md).
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
  for (int d = 0; d < Dim; ++d)
    if (!(inner_upper[d] > inner_lower[d]))
      throw InputError(fmt::format("add_box_walls: inner_upper[{}] = {} must be greater than inner_lower[{}] = {}", d,
                                   inner_upper[d], d, inner_lower[d]));
  const T rho0 = system.eos().reference_density();
  const T mass = rho0 * std::pow(res.dp, T(Dim));
  std::size_t added = 0;
  const T tol = T(1e-6) * res.dp;
  if (model != WallModel::repulsive) {  // dynamic or extrapolated: layers of wall particles on the lattice
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
  // Repulsive walls: one row per face. Face (axis, side) lies at x[axis] = lower or upper; the top is open.
  std::array<std::int64_t, Dim> intervals{};
  V spacing;
  for (int d = 0; d < Dim; ++d) {
    intervals[d] = std::max<std::int64_t>(1, std::llround((inner_upper[d] - inner_lower[d]) / res.dp));
    spacing[d] = (inner_upper[d] - inner_lower[d]) / T(intervals[d]);
  }
  for (int axis = 0; axis < Dim; ++axis) {
    for (int side = 0; side < 2; ++side) {
      if (axis == Dim - 1 && side == 1) continue;  // open top
      V normal = V::Zero();
      normal[axis] = side == 0 ? T(1) : T(-1);
      std::int64_t total = 1;
      for (int d = 0; d < Dim; ++d)
        if (d != axis) total *= intervals[d] + 1;
      for (std::int64_t k = 0; k < total; ++k) {
        std::int64_t rest = k;
        V x;
        for (int d = 0; d < Dim; ++d) {
          if (d == axis) {
            x[d] = side == 0 ? inner_lower[d] : inner_upper[d];
            continue;
          }
          const std::int64_t i = rest % (intervals[d] + 1);
          rest /= intervals[d] + 1;
          x[d] = inner_lower[d] + T(i) * spacing[d];
        }
        const std::size_t slot = system.particles().add(Kind::wall, x, V::Zero(), rho0, mass, res.h(), body);
        system.particles().normal[slot] = normal;
        ++added;
      }
    }
  }
  return added;
}

/// Sets the density of the wall particles of `body` (all bodies if body < 0) to the hydrostatic value of the
/// still water level `surface`: rho = EOS inverse of rho0 |g| (surface - z), rho0 above the surface. Dynamic walls
/// built at rho0 under a column initialised by add_fluid_block would push back with zero pressure at first and
/// start an acoustic oscillation of the whole column; with this they start in equilibrium (Crespo et al. 2007 let
/// the wall density evolve by continuity from there). No effect on repulsive walls, whose density is unused.
template <class System>
void set_hydrostatic_wall_density(System& system, typename System::scalar_type surface,
                                  typename System::scalar_type gravity = 9.81, std::int32_t body = -1) {
  using T = typename System::scalar_type;
  constexpr int Dim = System::dimension;
  require_finite("set_hydrostatic_wall_density surface (m)", surface);
  require_non_negative("set_hydrostatic_wall_density gravity (m/s^2)", gravity);
  auto& p = system.particles();
  const auto& eos = system.eos();
  const T rho0 = eos.reference_density();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::wall || (body >= 0 && p.body[i] != body)) continue;
    const T depth = std::max(surface - p.position[i][Dim - 1], T(0));
    p.density[i] = eos.density(rho0 * gravity * depth);
    p.density_old[i] = p.density[i];
  }
}

/// Boundary-particle spacing db that add_box_walls gives repulsive walls along the face of extent `extent`
/// (extent / round(extent / dp)); pass it as FluidParameters::repulsive.boundary_spacing.
template <Real T>
T repulsive_wall_spacing(T extent, const Resolution<T>& res) {
  res.validate();
  require_positive("repulsive_wall_spacing extent (m)", extent);
  return extent / T(std::max<std::int64_t>(1, std::llround(extent / res.dp)));
}

}  // namespace sphfsi
