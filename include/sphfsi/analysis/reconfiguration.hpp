// sphfsi: static reconfiguration of a flexible blade in a uniform current, the reference for blade_in_current
// (docs/thin-blades.md) with any local force law.
//
// Luhar & Nepf (2011, J. Fluid Mech. 680:594) balance the bending moment of an inextensible cantilever blade of
// length l, stiffness E I and width b against a local drag: each element at the angle theta from the vertical feels a
// force per unit length normal to itself, (1/2) rho b C_D (U cos theta)^2, from the current U. Here the local law is a
// callable: per unit length, in units of (1/2) rho b C_N(0) U^2, the element feels
//     normal_load(theta)      along n = (cos theta, -sin theta)  (normal, the downstream side),
//     tangential_load(theta)  along t = (sin theta,  cos theta)  (the blade's tangent, base to tip: skin friction),
// with the current along +x and the blade bent towards it. Luhar & Nepf's law is normal_load = cos^2, tangential = 0.
// With s in units of l and G(s) the load on the blade beyond s (the shear force carried across the section s),
//     theta'' = Ca (sin theta G_y - cos theta G_x),   G' = -(normal_load n + tangential_load t),
//     theta(0) = 0 (clamped),  theta'(1) = 0 and G(1) = 0 (free tip),
//     Ca = rho C_N(0) b U^2 l^3 / (2 E I).
// Solved by shooting from the tip on theta(1) in [0, pi/2] with bisection on the sign of theta(0) (which grows with the
// tip angle), each shot integrated from the tip to the clamp by classical RK4. The effective length is the base's
// horizontal force over the upright rigid blade's: l_e / l = G_x(0) / normal_load(0).
#pragma once

#include <sphfsi/analysis/runge_kutta.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <numbers>
#include <utility>
#include <vector>

namespace sphfsi::analysis {

template <Real T>
struct Reconfiguration {
  T effective_length;  // l_e / l = F_x / F_x of the upright rigid blade
  T tip_angle;         // theta at the tip, rad from the vertical
  T tip_x, tip_z;      // tip position relative to the base, over l (downstream, up)
};

/// Static posture and effective length of a blade at Cauchy number Ca >= 0 under the local loads above (both
/// callables T(T theta), theta in [0, pi/2]; normal_load(0) > 0). `steps` RK4 steps per shot.
template <Real T, std::invocable<T> NormalLoad, std::invocable<T> TangentialLoad>
Reconfiguration<T> static_reconfiguration(T cauchy, NormalLoad&& normal_load, TangentialLoad&& tangential_load,
                                          int steps = 2000) {
  require_non_negative("static_reconfiguration Cauchy number", cauchy);
  const T upright = normal_load(T(0));
  if (!(upright > 0) || !std::isfinite(upright))
    throw InputError("static_reconfiguration: the normal load on the upright blade, normal_load(0), must be > 0");
  if (steps < 10) throw InputError("static_reconfiguration: steps must be >= 10");
  using State = std::array<T, 6>;  // theta, theta', G_x, G_y, x, z (positions relative to the tip)
  const auto rate = [&](const State& y) {
    const T c = std::cos(y[0]), s = std::sin(y[0]);
    const T fn = normal_load(y[0]), ft = tangential_load(y[0]);
    const T load_x = fn * c + ft * s, load_z = -fn * s + ft * c;
    return State{y[1], cauchy * (s * y[3] - c * y[2]), -load_x, -load_z, s, c};
  };
  const auto shoot = [&](T tip_angle) {
    State y{tip_angle, T(0), T(0), T(0), T(0), T(0)};
    const T h = T(-1) / T(steps);  // from the tip (s = 1) to the clamp (s = 0)
    for (int i = 0; i < steps; ++i) runge_kutta4_step(y, h, rate);
    return y;
  };
  T lo = 0, hi = std::numbers::pi_v<T> / 2;
  for (int i = 0; i < 55; ++i) {
    const T mid = T(0.5) * (lo + hi);
    (shoot(mid)[0] < 0 ? lo : hi) = mid;
  }
  const T tip_angle = T(0.5) * (lo + hi);
  const State y = shoot(tip_angle);
  // y[4], y[5] integrate from the tip down to the base: the base lies at (x, z) relative to the tip.
  return {y[2] / upright, tip_angle, -y[4], -y[5]};
}

/// A local load law measured at a few angles (e.g. rigid inclined blades): linear interpolation between the
/// measured angles (rad, increasing, the first 0), and linearly from the last one to `at_flat` at pi/2.
template <Real T>
class TabulatedLoad {
 public:
  TabulatedLoad(std::vector<T> angle, std::vector<T> value, T at_flat)
      : angle_(std::move(angle)), value_(std::move(value)) {
    if (angle_.size() != value_.size() || angle_.empty())
      throw InputError(fmt::format("TabulatedLoad: {} angles and {} values: need equal, non-zero counts", angle_.size(),
                                   value_.size()));
    if (angle_.front() != 0) throw InputError("TabulatedLoad: the first angle must be 0 (the upright blade)");
    for (std::size_t k = 1; k < angle_.size(); ++k)
      if (!(angle_[k] > angle_[k - 1]))
        throw InputError(fmt::format("TabulatedLoad: angle {} = {} rad is not above the one before it", k, angle_[k]));
    if (!(angle_.back() < std::numbers::pi_v<T> / 2))
      throw InputError(fmt::format("TabulatedLoad: last angle {} rad: valid range is [0, pi/2)", angle_.back()));
    for (T v : value_)
      if (!std::isfinite(v)) throw InputError("TabulatedLoad: every measured value must be finite");
    if (!std::isfinite(at_flat)) throw InputError("TabulatedLoad: at_flat must be finite");
    angle_.push_back(std::numbers::pi_v<T> / 2);
    value_.push_back(at_flat);
  }

  T operator()(T theta) const {
    if (theta <= 0) return value_.front();
    if (theta >= angle_.back()) return value_.back();
    std::size_t k = 1;
    while (angle_[k] < theta) ++k;
    const T w = (theta - angle_[k - 1]) / (angle_[k] - angle_[k - 1]);
    return (1 - w) * value_[k - 1] + w * value_[k];
  }

 private:
  std::vector<T> angle_, value_;
};

/// Luhar & Nepf's (2011) own law: normal drag on the normal velocity, cos^2 theta, no skin friction.
template <Real T>
Reconfiguration<T> luhar_nepf_reconfiguration(T cauchy, int steps = 2000) {
  return static_reconfiguration<T>(
      cauchy, [](T theta) { return std::cos(theta) * std::cos(theta); }, [](T) { return T(0); }, steps);
}

/// Luhar & Nepf's (2011) fit of their model, B = 0: l_e / l = 1 - (1 - 0.9 Ca^(-1/3)) / (1 + 8 Ca^(-3/2)).
template <Real T>
T luhar_nepf_effective_length_fit(T cauchy) {
  require_positive("luhar_nepf_effective_length_fit Cauchy number", cauchy);
  return T(1) - (T(1) - T(0.9) * std::cbrt(T(1) / cauchy)) / (T(1) + T(8) * std::pow(cauchy, T(-1.5)));
}

}  // namespace sphfsi::analysis
