// sphfsi: the repulsive boundary force of Monaghan & Kos (1999), J. Waterway Port Coastal Ocean Eng. 125:145,
// as modified by Rogers & Dalrymple (2008) (reference paper eqs 17-23). Used by repulsive walls and by the
// RepulsiveForce coupling. The result is a force per unit mass (an acceleration) on the fluid particle:
//   f = n R(d_perp) P(xi) eps(z, u_perp)                                  (17)
//   R = A (1 - q) / sqrt(q),  q = d_perp / 2h,  A = 0.01 c^2 / h           (18, 19)
//   P = (1 + cos(pi xi / db)) / 2  for |xi| < db, else 0                   (20)
// Eq. 20 of the reference paper prints 2 pi; with 2 pi the force vanishes midway between two boundary
// particles. With pi (Monaghan & Kos 1999, eq. 3.4) the contributions of two neighbours sum to 1 everywhere
// along the boundary, which is the stated purpose of P ("constant and parallel"), so sphfsi uses pi.
//   eps = eps(z) + eps(u_perp)                                             (21-23)
#pragma once

#include <sphfsi/core/types.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sphfsi {

/// Parameters of the repulsive force, all per boundary.
template <Real T>
struct RepulsiveForceParameters {
  T boundary_spacing{0};  ///< db: distance between neighbouring boundary particles, m
  T water_level{0};       ///< still-water level z0 used by eps(z); only used when local_depth > 0, m
  T local_depth{0};       ///< h0 of eq. 22; <= 0 switches the depth scaling off (eps(z) = 1), m
  int vertical_axis{1};   ///< axis of z (1 in 2D, 2 in 3D)
};

/// Depth factor eps(z) of eq. 22, z = elevation above the local water level, h0 = local depth.
template <Real T>
inline T repulsive_depth_factor(T z, T h0) {
  if (h0 <= T(0)) return T(1);
  if (z >= T(0)) return T(0.02);
  if (-z <= h0) return std::abs(z / h0) + T(0.02);
  return T(1);
}

/// Velocity factor eps(u_perp) of eq. 23; u_perp < 0 means the fluid approaches the boundary.
template <Real T>
inline T repulsive_velocity_factor(T u_perp, T c0) {
  if (u_perp >= T(0)) return T(0);
  const T a = std::abs(T(20) * u_perp);
  return a < c0 ? a / c0 : T(1);
}

/// Acceleration on a fluid particle at dx = x_fluid - x_boundary from a boundary particle of outward unit
/// normal n (pointing into the fluid), with relative velocity dv = v_fluid - v_boundary.
template <int Dim, Real T>
inline Vec<Dim, T> repulsive_force(const Vec<Dim, T>& dx, const Vec<Dim, T>& dv, const Vec<Dim, T>& n, T h, T c0,
                                   T elevation, const RepulsiveForceParameters<T>& params) {
  const T d_perp = dx.dot(n);
  const T q = d_perp / (T(2) * h);
  if (q <= T(0) || q >= T(1)) return Vec<Dim, T>::Zero();
  const T xi = (dx - d_perp * n).norm();
  if (xi >= params.boundary_spacing) return Vec<Dim, T>::Zero();
  const T A = T(0.01) * c0 * c0 / h;                                                            // (19)
  const T R = A * (T(1) - q) / std::sqrt(q);                                                     // (18)
  const T P = T(0.5) * (T(1) + std::cos(std::numbers::pi_v<T> * xi / params.boundary_spacing));  // (20)
  const T eps = repulsive_depth_factor(elevation, params.local_depth) +
                repulsive_velocity_factor(dv.dot(n), c0);                                       // (21)
  return n * (R * P * eps);                                                                     // (17)
}

}  // namespace sphfsi
