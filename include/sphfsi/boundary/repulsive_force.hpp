// sphfsi: the repulsive boundary force of Monaghan & Kos (1999), J. Waterway Port Coastal Ocean Eng. 125:145,
// as modified by Rogers & Dalrymple (2008) (reference paper eqs 17-23). Used by repulsive walls and by the
// RepulsiveForce coupling. The result is a force per unit mass (an acceleration) on the fluid particle:
//   f = n R(d_perp) P(xi) eps(z, u_perp)                                  (17)
//   R = A (1 - q) / sqrt(q),  q = d_perp / 2h,  A = k c^2 / h, k = 0.01    (18, 19)
//   P = (1 + cos(pi xi / db)) / 2  for |xi| < db, else 0                   (20)
// Eq. 20 of the reference paper prints 2 pi; with 2 pi the force vanishes midway between two boundary
// particles. With pi (Monaghan & Kos 1999, eq. 3.4) the contributions of two neighbours sum to 1 everywhere
// along the boundary, which is the stated purpose of P ("constant and parallel"), so sphfsi uses pi.
//   eps = eps(z) + eps(u_perp)                                             (21-23)
//
// Strength. The 0.01 of eq. 19 ties A to c^2: with the usual c0 = 10 sqrt(g D) (D the deepest water) it gives
// A = g D / h, the scale of the pressure force p / (rho h) that the wall must resist at depth D. It is kept as
// the default `strength`; repulsive_strength_for_rest_gap() gives the strength with which a still column of depth
// D rests with its first particle row at dp/2 from the wall (the fluid block's initial position), so a scene
// starts in equilibrium instead of being launched off the wall. The rows j = 0, 1, ... at d_j = (j + 1/2) dp
// (mass rho0 dp per unit wall length for each column of width dp) carry the weight of the column:
//   rho0 dp sum_j A (1 - q_j) / sqrt(q_j) = rho0 g D,  A = k c0^2 / h
//     =>   k = g D (h / dp) / (c0^2 sum_j (1 - q_j) / sqrt(q_j)),
//   q_j = d_j / 2h   (q_j < 1).
//
// Depth factor. Eq. 22 scales the push with the depth below the local water level z0 (h0 the local depth), like
// the hydrostatic pressure it resists. It needs both; local_depth <= 0 (the default) switches it off
// (eps(z) = 1: the full push at every depth, which keeps the free surface a little further than dp/2 from side
// walls but needs no knowledge of the water level). For a tank of still-water depth D: water_level = bed + D,
// local_depth = D.
//
// Normal dashpot (sphfsi's addition, off by default: normal_damping = 0). The repulsion depends on position only; a
// very light thin blade (a real seagrass blade, 0.1 mm) has almost no inertia and bending stiffness to hold against
// the noise of that push from its two faces, and the SPH fluid is one fluid across it, so nothing ties the blade's
// motion to the water's: it drifts over in still water (docs/posidonia.md, session 6). The dashpot imposes the
// impermeability condition weakly, in the normal relative velocity of each pair:
//   a_f += -beta (c0 / h) (1 - q) P(xi) ((v_f - v_b) . n) n
// (the boundary particle receives the reaction), symmetric in approach and recession (unlike eq. 23's one-sided
// factor), free-slip along the boundary, and dissipative for every pair (power -m_f beta (c0/h) (1-q) P (dv.n)^2).
// It is explicit: the coupling limits the step to 2 / lambda (coupling/repulsive_force.hpp).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sphfsi {

/// Parameters of the repulsive force, all per boundary.
template <Real T>
struct RepulsiveForceParameters {
  T boundary_spacing{0};       ///< db: distance between neighbouring boundary particles, m
  T water_level{0};            ///< still-water level z0 used by eps(z); only used when local_depth > 0, m
  T local_depth{0};            ///< h0 of eq. 22; <= 0 switches the depth scaling off (eps(z) = 1), m
  int vertical_axis{1};        ///< axis of z (1 in 2D, 2 in 3D)
  T strength{T(0.01)};         ///< coefficient k of A = k c0^2 / h (eq. 19: 0.01), > 0
  bool velocity_factor{true};  ///< eps(u_perp) of eq. 23 (false: eps = eps(z) only; see RepulsiveForce)
  T normal_damping{T(0)};      ///< beta of the normal dashpot (rate beta c0 / h; see the header comment), [0, 1]

  /// Throws InputError naming the first parameter out of range.
  void validate() const {
    require_positive("RepulsiveForceParameters::boundary_spacing (db, m)", boundary_spacing);
    require_finite("RepulsiveForceParameters::water_level (m)", water_level);
    require_finite("RepulsiveForceParameters::local_depth (h0, m)", local_depth);
    require_in_range("RepulsiveForceParameters::vertical_axis", vertical_axis, 0, 2);
    require_positive("RepulsiveForceParameters::strength (k of A = k c0^2 / h)", strength);
    require_in_range("RepulsiveForceParameters::normal_damping (beta)", normal_damping, T(0), T(1));
  }
};

/// Strength k with which fluid of density `density` (kg/m^3) at a uniform pressure `pressure` (Pa) rests against a
/// repulsive wall with its first particle row at first_row x dp from it: the load rho0 g D of the header comment
/// replaced by p, e.g. the background pressure of a confined flow without gravity (FluidParameters::
/// background_pressure), which holds the fluid on both faces of a thin blade.
template <Real T>
T repulsive_strength_for_rest_pressure(T pressure, T density, T c0, T smoothing_ratio, T first_row = T(0.5)) {
  require_in_range("repulsive strength first_row (in dp)", first_row, T(0.1), T(2));
  require_positive("repulsive strength pressure (Pa)", pressure);
  require_positive("repulsive strength density (kg/m^3)", density);
  require_positive("repulsive strength c0 (m/s)", c0);
  require_in_range("repulsive strength smoothing_ratio (h/dp)", smoothing_ratio, T(0.5), T(5));
  T rows = T(0);
  for (int j = 0;; ++j) {
    const T q = (T(j) + first_row) / (T(2) * smoothing_ratio);
    if (q >= T(1)) break;
    rows += (T(1) - q) / std::sqrt(q);
  }
  return (pressure / density) * smoothing_ratio / (c0 * c0 * rows);
}

/// Strength k (A = k c0^2 / h) with which a still water column of depth `depth` (m) under gravity `gravity`
/// (m/s^2) rests on a repulsive wall with its first particle row at dp/2 from it, for sound speed c0 (m/s) and
/// smoothing ratio h / dp (see the header comment). For c0 = 10 sqrt(g D) and h = 1.3 dp it is 0.0053.
/// first_row is the distance of the first fluid row from the boundary particles in units of dp: 1/2 for a wall
/// line, 1 for the surface particles of an SPH solid (whose surface lies dp/2 outside its particle centres). With
/// the depth factor eps(z) = |z| / D of eq. 22 the same strength balances the hydrostatic load on a vertical wall.
template <Real T>
T repulsive_strength_for_rest_gap(T depth, T gravity, T c0, T smoothing_ratio, T first_row = T(0.5)) {
  require_positive("repulsive_strength_for_rest_gap depth (m)", depth);
  require_positive("repulsive_strength_for_rest_gap gravity (m/s^2)", gravity);
  return repulsive_strength_for_rest_pressure(gravity * depth, T(1), c0, smoothing_ratio, first_row);  // p / rho0
}

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
  const T A = params.strength * c0 * c0 / h;                                                     // (19)
  const T R = A * (T(1) - q) / std::sqrt(q);                                                     // (18)
  const T P = T(0.5) * (T(1) + std::cos(std::numbers::pi_v<T> * xi / params.boundary_spacing));  // (20)
  const T eps = repulsive_depth_factor(elevation, params.local_depth) +
                (params.velocity_factor ? repulsive_velocity_factor(dv.dot(n), c0) : T(0));  // (21)
  // (17), and the normal dashpot that drives the normal relative velocity to zero (impermeability)
  return n * (R * P * eps - params.normal_damping * (c0 / h) * (T(1) - q) * P * dv.dot(n));
}

}  // namespace sphfsi
