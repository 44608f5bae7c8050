// sphfsi: regular-wave paddles (piston and bed-hinged flap) as moving wall particles.
//
// The paddle's horizontal excursion at the still-water level is X(t) = (S/2) r(t) sin(omega t), S the full stroke
// from Biesel's transfer function (waves/linear_theory.hpp) for the target height H, period T and depth h, and
// r(t) a half-cosine ramp over the first n periods, r = (1 - cos(pi t / t_r)) / 2, which starts the paddle from
// rest with zero acceleration jump at both ends of the ramp (Dean & Dalrymple 1991, sec. 6.2, for the transfer
// functions; the ramp limits the transient that a sudden start sheds, e.g. Altomare et al. 2017, Coastal Eng.
// 127:37, who ramp DualSPHysics paddles the same way).
//   piston:  every paddle particle translates by X(t)                  -> Simulation::set_wall_motion
//   flap:    paddle particles rotate about the hinge (x_h, z_h) by theta(t) = atan(X(t) / (h - z_h)),
//            positive theta moving the top towards +x                   -> Simulation::set_wall_kinematics
// Second-order piston generation (WavemakerParameters::order = 2; Madsen 1971, waves/second_order.hpp) adds
// r(t)^2 X_2 sin(2 omega t), the motion that keeps the paddle from shedding a free second harmonic; the ramp
// enters squared because X_2 is quadratic in the wave amplitude.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/waves/linear_theory.hpp>
#include <sphfsi/waves/second_order.hpp>

#include <cmath>
#include <numbers>
#include <utility>

namespace sphfsi::waves {

enum class PaddleType { piston, flap };

/// Target regular wave and paddle of a wavemaker.
template <Real T>
struct WavemakerParameters {
  PaddleType paddle{PaddleType::piston};
  T wave_height{T(0.028)};  ///< target H, m
  T period{T(1.4286)};      ///< T, s
  T depth{T(0.16)};         ///< still-water depth h in front of the paddle, m
  T gravity{T(9.81)};       ///< m/s^2
  T ramp_periods{T(2)};     ///< length of the start-up ramp, in periods (0: none), [0, 100]
  int order{1};             ///< 1: Biesel's first-order signal; 2: with Madsen's (1971) correction (piston only)

  void validate() const {
    require_positive("WavemakerParameters::wave_height (m)", wave_height);
    require_positive("WavemakerParameters::period (s)", period);
    require_positive("WavemakerParameters::depth (m)", depth);
    require_positive("WavemakerParameters::gravity (m/s^2)", gravity);
    require_in_range("WavemakerParameters::ramp_periods", ramp_periods, T(0), T(100));
    require_in_range("WavemakerParameters::order", order, 1, 2);
    if (order == 2 && paddle != PaddleType::piston)
      throw InputError(
          "WavemakerParameters::order = 2 is implemented for the piston paddle only (valid for a flap: 1)");
  }
};

/// A regular-wave paddle: excursion and velocity at the still-water level, and the wall motions that realise it.
template <Real T>
class Wavemaker {
 public:
  explicit Wavemaker(const WavemakerParameters<T>& params) : params_(params) {
    params_.validate();
    wave_ = linear_wave(params_.period, params_.depth, params_.gravity);
    const T ratio =
        params_.paddle == PaddleType::piston ? piston_height_to_stroke(wave_.kh()) : flap_height_to_stroke(wave_.kh());
    stroke_ = params_.wave_height / ratio;
    if (!(stroke_ < params_.depth))
      throw InputError(
          fmt::format("Wavemaker: the stroke S = {} m needed for H = {} m exceeds the depth h = {} m: "
                      "valid wave heights are below {} m for this period and depth",
                      stroke_, params_.wave_height, params_.depth, ratio * params_.depth));
    if (params_.order == 2) second_harmonic_ = madsen_piston_second_harmonic(wave_, params_.wave_height);
  }

  const WavemakerParameters<T>& parameters() const noexcept { return params_; }
  const LinearWave<T>& wave() const noexcept { return wave_; }
  /// Full stroke S (peak to peak excursion at the still-water level), m.
  T stroke() const noexcept { return stroke_; }
  /// Amplitude X_2 of the second-harmonic excursion (Madsen 1971), m; 0 for a first-order wavemaker.
  T second_harmonic() const noexcept { return second_harmonic_; }
  /// Duration of the start-up ramp, s.
  T ramp_time() const noexcept { return params_.ramp_periods * params_.period; }

  /// Ramp factor r(t) in [0, 1] and its time derivative.
  std::pair<T, T> ramp(T t) const {
    const T tr = ramp_time();
    if (t <= T(0)) return {T(0), T(0)};
    if (tr <= T(0) || t >= tr) return {T(1), T(0)};
    const T a = std::numbers::pi_v<T> / tr;
    return {T(0.5) * (T(1) - std::cos(a * t)), T(0.5) * a * std::sin(a * t)};
  }

  /// Horizontal excursion X(t) of the paddle at the still-water level, m.
  T displacement(T t) const {
    const auto [r, dr] = ramp(t);
    const T w = wave_.angular_frequency;
    return T(0.5) * stroke_ * r * std::sin(w * t) + second_harmonic_ * r * r * std::sin(T(2) * w * t);
  }

  /// dX/dt, m/s.
  T velocity(T t) const {
    const auto [r, dr] = ramp(t);
    const T w = wave_.angular_frequency;
    return T(0.5) * stroke_ * (dr * std::sin(w * t) + r * w * std::cos(w * t)) +
           second_harmonic_ * r * (T(2) * dr * std::sin(T(2) * w * t) + T(2) * r * w * std::cos(T(2) * w * t));
  }

  /// Rigid horizontal translation for Simulation::set_wall_motion (piston paddles).
  template <int Dim>
  PrescribedMotion<Dim, T> piston_motion() const {
    if (params_.paddle != PaddleType::piston)
      throw InputError("Wavemaker::piston_motion: this wavemaker is a flap (use flap_kinematics)");
    const Wavemaker self = *this;
    PrescribedMotion<Dim, T> m;
    m.displacement = [self](T t) {
      Vec<Dim, T> d = Vec<Dim, T>::Zero();
      d[0] = self.displacement(t);
      return d;
    };
    m.velocity = [self](T t) {
      Vec<Dim, T> v = Vec<Dim, T>::Zero();
      v[0] = self.velocity(t);
      return v;
    };
    return m;
  }

  /// Flap angle theta(t) about the hinge at height hinge_z above the bed level z = 0 (positive: top towards +x), rad.
  T flap_angle(T t, T hinge_z = T(0)) const { return std::atan(displacement(t) / (params_.depth - hinge_z)); }

  /// Rotation about the hinge (hinge_x, hinge_z) for Simulation::set_wall_kinematics (flap paddles). Vertical axis
  /// Dim - 1, the paddle moves in the x (axis 0) - vertical plane.
  template <int Dim>
  PrescribedKinematics<Dim, T> flap_kinematics(T hinge_x, T hinge_z = T(0)) const {
    if (params_.paddle != PaddleType::flap)
      throw InputError("Wavemaker::flap_kinematics: this wavemaker is a piston (use piston_motion)");
    require_in_range("Wavemaker::flap_kinematics hinge_z (m, below the still-water level)", hinge_z,
                     T(-10) * params_.depth, params_.depth * T(0.99));
    const Wavemaker self = *this;
    PrescribedKinematics<Dim, T> k;
    k.state = [self, hinge_x, hinge_z](const Vec<Dim, T>& reference, T t) {
      const T arm = self.params_.depth - hinge_z;
      const T X = self.displacement(t), dX = self.velocity(t);
      const T theta = std::atan(X / arm);
      const T dtheta = dX * arm / (arm * arm + X * X);
      const T c = std::cos(theta), s = std::sin(theta);
      const T rx = reference[0] - hinge_x, rz = reference[Dim - 1] - hinge_z;
      Vec<Dim, T> x = reference, v = Vec<Dim, T>::Zero();
      x[0] = hinge_x + rx * c + rz * s;
      x[Dim - 1] = hinge_z - rx * s + rz * c;
      v[0] = dtheta * (x[Dim - 1] - hinge_z);
      v[Dim - 1] = -dtheta * (x[0] - hinge_x);
      return std::pair{x, v};
    };
    return k;
  }

 private:
  WavemakerParameters<T> params_;
  LinearWave<T> wave_{};
  T stroke_{0};
  T second_harmonic_{0};  // X_2, m
};

}  // namespace sphfsi::waves
