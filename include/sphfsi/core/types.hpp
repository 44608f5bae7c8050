// sphfsi: basic vocabulary types shared by every module.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace sphfsi {

/// Fixed-size spatial vector of dimension Dim (2 or 3) and scalar T (float or double).
template <int Dim, class T>
using Vec = Eigen::Matrix<T, Dim, 1>;

/// Fixed-size Dim x Dim tensor (stress, deformation gradient, kernel-gradient correction).
template <int Dim, class T>
using Mat = Eigen::Matrix<T, Dim, Dim>;

/// What a particle is. Kinds are data, not types: one storage holds all of them.
enum class Kind : std::uint8_t {
  fluid = 0,  ///< weakly-compressible fluid, moves with the flow
  wall = 1,   ///< boundary particle, fixed or moving with a prescribed motion
  solid = 2,  ///< elastic solid particle, advanced by a solid model
};

/// Human-readable name of a particle kind (for diagnostics and output).
constexpr const char* kind_name(Kind k) noexcept {
  switch (k) {
    case Kind::fluid: return "fluid";
    case Kind::wall: return "wall";
    case Kind::solid: return "solid";
  }
  return "unknown";
}

/// Standard gravity, 9.81 m/s^2 along -z (the last axis): the default body force of fluids and solids.
template <int Dim, class T>
Vec<Dim, T> standard_gravity() {
  Vec<Dim, T> g = Vec<Dim, T>::Zero();
  g[Dim - 1] = T(-9.81);
  return g;
}

/// Dimension and scalar type a scene is built for.
template <class T>
concept Real = std::is_same_v<T, float> || std::is_same_v<T, double>;

template <int Dim>
concept SpatialDimension = (Dim == 2 || Dim == 3);

/// An edge of a thin structure (a blade as one line of nodes): the ids of its two end nodes. Solids publish their
/// edges, the fluid hides particle pairs across them (fluid/thin_structure_visibility.hpp).
using StructureEdge = std::array<std::uint32_t, 2>;

/// The (x, vertical) components of a point: the plane a blade bends in (in 3D, a ribbon: solid/elastic_rod.hpp).
template <int Dim, class T>
Vec<2, T> bending_plane(const Vec<Dim, T>& x) {
  if constexpr (Dim == 2) return x;
  else return Vec<2, T>(x[0], x[Dim - 1]);
}

}  // namespace sphfsi
