// sphfsi: Fickian particle shifting, to keep the fluid particles' distribution regular.
//
// Lind, Xu, Stansby & Rogers 2012 (J. Comput. Phys. 231:1499) with the speed-scaled diffusion coefficient of
// Skillen, Lind, Stansby & Rogers 2013 (Comput. Methods Appl. Mech. Engrg. 265:163), the form DualSPHysics uses
// (Crespo et al. 2015, Comput. Phys. Commun. 187:204, sec. 2.6). After a step of length dt each fluid particle a moves
// down the gradient of the particle concentration C:
//     delta r_a = -A h_a |v_a| dt grad C_a,    grad C_a = sum_b V_b grad_a W(r_ab, h_a),
// the sum over the fluid and wall particles of a's own smoothing length (with FluidParameters::same_resolution_pairs
// each resolution is a discretisation of its own; otherwise over every neighbour). The shift is capped at
// max_shift h_a. A particle is at a free surface where the divergence of position, -sum_b V_b r_ab dW/dr (Dim in a
// full support), is below Dim - surface_deficit (Lee et al. 2008, J. Comput. Phys. 227:8417; DualSPHysics: 1.5 in
// 2D). At a surface particle and within the kernel support of one, the shift's component along the surface normal
// (the kernel-weighted mean of the surface particles' grad C there) is removed: the particle moves along the surface
// only, and the surface does not diffuse outwards. Where the kernel sum sum_b V_b W_ab (about 1 in a full support)
// is below detached_fraction (a splash), no shift.
// Velocities and densities are not changed: mass and momentum are kept exactly; the first-order error of moving a
// particle by delta r through a smooth field is O(|delta r| |grad f|), and |delta r| <= max_shift h.
//
// Used by AdaptiveRefinement (AdaptiveRefinementParameters::shifting) on the particles of the refined levels, and as
// a ParticleModel of its own: its advance() shifts after each step.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace sphfsi {

/// Parameters of ParticleShifting (a small trivially copyable policy).
template <Real T>
struct ParticleShiftingParameters {
  bool enabled{false};  ///< whether the shift is applied (AdaptiveRefinement: on its refined levels)
  T coefficient{2};     ///< A of delta r = -A h |v| dt grad C (Skillen et al. 2013: 1-6), (0, 10]
  T max_shift{0.1};     ///< cap on |delta r| / h, (0, 0.5]
  /// A particle is at a free surface where its divergence of position is below Dim - surface_deficit, (0, 3]
  T surface_deficit{0.5};
  T detached_fraction{0.5};  ///< kernel sum below which no shift at all, [0, 1]
  /// Only fluid particles with a smoothing length at most this are shifted (infinity: all), m.
  T max_smoothing_length{std::numeric_limits<T>::infinity()};
  bool same_resolution_only{true};  ///< grad C from the particles of a's own smoothing length only
  /// Whether passive fluid particles (AdaptiveRefinement: not integrated, they follow interpolated values) are
  /// shifted too; they carry no conserved mass or momentum.
  bool include_passive{false};

  void validate() const {
    auto positive_up_to = [](const char* name, T value, T hi) {
      if (!(value > T(0) && value <= hi))
        throw InputError(fmt::format("{} = {} is invalid: valid range is (0, {}]", name, value, hi));
    };
    positive_up_to("ParticleShiftingParameters::coefficient (A)", coefficient, T(10));
    positive_up_to("ParticleShiftingParameters::max_shift (|delta r| / h)", max_shift, T(0.5));
    positive_up_to("ParticleShiftingParameters::surface_deficit", surface_deficit, T(3));
    require_in_range("ParticleShiftingParameters::detached_fraction", detached_fraction, T(0), T(1));
    if (!(max_smoothing_length > T(0)))
      throw InputError(
          fmt::format("ParticleShiftingParameters::max_smoothing_length = {} m is invalid: valid range is (0, inf]",
                      max_smoothing_length));
  }
};

/// What the last shift did.
struct ParticleShiftingCounts {
  std::size_t shifted{0};   ///< particles moved
  std::size_t surface{0};   ///< of them, moved along the free surface only
  std::size_t capped{0};    ///< of them, with the shift capped at max_shift h
  double largest_shift{0};  ///< largest |delta r| / h
};

/// Fickian particle shifting (see the header comment). A ParticleModel: no forces, no time-step limit; advance()
/// shifts the active fluid particles after each step. The neighbour index must be current (it is the step's).
template <class System>
class ParticleShifting {
 public:
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;
  static constexpr bool checkpoint_stateless = true;

  explicit ParticleShifting(const ParticleShiftingParameters<T>& params) : params_(params) { params_.validate(); }

  const ParticleShiftingParameters<T>& parameters() const noexcept { return params_; }
  const ParticleShiftingCounts& last_counts() const noexcept { return last_; }

  // ---- ParticleModel ----
  void compute_rates(System&, T) {}
  T stable_time_step(const System&) const { return std::numeric_limits<T>::infinity(); }
  void advance(System& system, T, T dt) {
    if (params_.enabled) shift(system, dt);
  }

  /// Computes every shift on the current positions, then applies them. Wall and solid particles stay; passive ones
  /// too unless include_passive.
  void shift(System& system, T dt) {
    auto& p = system.particles();
    const auto& kernel = system.kernel();
    using Kernel = typename System::kernel_type;
    const std::size_t n = p.size();
    gradient_.assign(n, Vector::Zero());
    shift_.assign(n, Vector::Zero());
    fullness_.assign(n, T(1));
    surface_.assign(n, 0);
    flag_.assign(n, 0);
    auto shifted = [&](std::size_t a) {
      return p.kind[a] == Kind::fluid && (!p.passive[a] || params_.include_passive) &&
             p.smoothing_length[a] <= params_.max_smoothing_length;
    };
    auto counted = [&](std::size_t a, std::size_t b, T r) {  // b in a's concentration
      return p.kind[b] != Kind::solid && r < T(Kernel::support) * p.smoothing_length[a] &&
             (!params_.same_resolution_only || p.smoothing_length[b] == p.smoothing_length[a]);
    };
    // 1. Kernel sum, divergence of position and grad C of every fluid particle that may be shifted or be a
    // shifted one's surface neighbour (with same_resolution_only: those of the shifted smoothing lengths).
    parallel_for(n, [&](std::size_t a) {
      if (p.kind[a] != Kind::fluid ||
          (params_.same_resolution_only && p.smoothing_length[a] > params_.max_smoothing_length))
        return;
      const T ha = p.smoothing_length[a];
      Vector gradient = Vector::Zero();
      T sum = p.mass[a] / p.density[a] * kernel.value(T(0), ha), divergence = T(0);
      system.for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T) {
        if (!counted(a, b, r)) return;
        const T volume = p.mass[b] / p.density[b];
        gradient += volume * kernel_gradient<Kernel, Dim, T>(kernel, dx, r, ha);
        sum += volume * kernel.value(r, ha);
        divergence -= volume * r * kernel.derivative(r, ha);
      });
      fullness_[a] = sum;
      gradient_[a] = gradient;
      surface_[a] = divergence < T(Dim) - params_.surface_deficit ? 1 : 0;
    });
    // Which particles have a surface particle in their sums: with one smoothing length per pair's sums the relation
    // is symmetric, so the (few) surface particles mark them, and only these need a neighbour loop in 2 (otherwise
    // every particle loops).
    near_surface_.assign(n, params_.same_resolution_only ? 0 : 1);
    if (params_.same_resolution_only)
      for (std::size_t s = 0; s < n; ++s) {
        if (!surface_[s]) continue;
        near_surface_[s] = 1;
        system.for_each_neighbor(s, [&](std::size_t b, const Vector&, T r, T) {
          if (counted(b, s, r)) near_surface_[b] = 1;
        });
      }
    // 2. The shifts. A particle at the surface or within the kernel support of one moves along the surface only:
    // the component along the surface normal (the kernel-weighted mean of the surface particles' grad C there) is
    // removed. (The rows below a surface have a full kernel sum, but grad C there points across the surface.)
    parallel_for(n, [&](std::size_t a) {
      if (!shifted(a)) return;
      const T ha = p.smoothing_length[a];
      const T speed = p.velocity[a].norm();
      if (!(speed > T(0)) || fullness_[a] < params_.detached_fraction) return;
      bool surface = surface_[a] != 0;
      Vector normal = surface ? Vector(kernel.value(T(0), ha) * gradient_[a]) : Vector::Zero();
      if (near_surface_[a])
        system.for_each_neighbor(a, [&](std::size_t b, const Vector&, T r, T) {
          if (p.kind[b] != Kind::fluid || !surface_[b] || !counted(a, b, r)) return;
          surface = true;
          normal += kernel.value(r, ha) * gradient_[b];
        });
      Vector dr = -params_.coefficient * ha * speed * dt * gradient_[a];
      std::uint8_t flag = 1;
      if (surface) {
        const T length = normal.norm();
        if (length > T(0)) normal /= length;
        dr -= dr.dot(normal) * normal;
        flag |= 2;
      }
      const T length = dr.norm();
      if (length > params_.max_shift * ha) {
        dr *= params_.max_shift * ha / length;
        flag |= 4;
      }
      shift_[a] = dr;
      flag_[a] = flag;
    });
    last_ = {};
    for (std::size_t a = 0; a < n; ++a) {
      if (!flag_[a]) continue;
      p.position[a] += shift_[a];
      ++last_.shifted;
      if (flag_[a] & 2) ++last_.surface;
      if (flag_[a] & 4) ++last_.capped;
      last_.largest_shift =
          std::max(last_.largest_shift, static_cast<double>(shift_[a].norm() / p.smoothing_length[a]));
    }
  }

 private:
  ParticleShiftingParameters<T> params_;
  ParticleShiftingCounts last_{};
  std::vector<Vector> shift_;
  std::vector<Vector> gradient_;            // per slot: grad C
  std::vector<T> fullness_;                 // per slot: kernel sum
  std::vector<std::uint8_t> surface_;       // per slot: divergence of position below Dim - surface_deficit
  std::vector<std::uint8_t> near_surface_;  // per slot: a surface particle in its sums
  std::vector<std::uint8_t> flag_;          // per slot: 1 shifted, | 2 along the surface only, | 4 capped
};

}  // namespace sphfsi
