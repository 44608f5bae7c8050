// sphfsi: the generic particle system, the template every scene is built on.
//
//   ParticleSystem<Dim, T, Kernel, Eos>
//
// holds the structure-of-arrays particle storage, the scene's domain, the neighbour search and the two
// compile-time policies every physics model needs: the smoothing kernel and the fluid's equation of state.
// Physics (fluid, walls, solids, couplings) lives above it in its own headers and only reads and writes the
// particle arrays; nothing here names a particular physics.
//
// Particles of different sizes: pair interactions use the averaged smoothing length h_ab = (h_a + h_b) / 2
// (Hernquist & Katz 1989, ApJS 70:419; Monaghan 1992, ARA&A 30:543, sec. 6), so W_ab = W_ba and pair forces
// cancel exactly. With one size the neighbour search is one cell grid (neighbors/cell_list.hpp, cell edge the support
// radius); with sizes more than a factor 2 apart it is the multi-level search of
// neighbors/multilevel_cell_list.hpp (one nested grid per size level), which keeps the particle order and the
// reach of the single grid.
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/particle_set.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/eos/concepts.hpp>
#include <sphfsi/kernel/concepts.hpp>
#include <sphfsi/neighbors/cell_list.hpp>
#include <sphfsi/neighbors/multilevel_cell_list.hpp>

#include <cmath>
#include <limits>
#include <utility>

namespace sphfsi {

template <int Dim, Real T, class Kernel, class Eos>
  requires SpatialDimension<Dim> && SmoothingKernel<Kernel, T> && EquationOfState<Eos, T> &&
      KernelOfDimension<Kernel, Dim>
class ParticleSystem {
 public:
  static constexpr int dimension = Dim;
  using scalar_type = T;
  using kernel_type = Kernel;
  using eos_type = Eos;
  using Vector = Vec<Dim, T>;
  using Particles = ParticleSet<Dim, T>;

  ParticleSystem(const Domain<Dim, T>& domain, const Eos& eos, const Kernel& kernel = Kernel{})
      : domain_(domain), eos_(eos), kernel_(kernel) {}

  Particles& particles() noexcept { return particles_; }
  const Particles& particles() const noexcept { return particles_; }
  const Domain<Dim, T>& domain() const noexcept { return domain_; }
  const Eos& eos() const noexcept { return eos_; }
  const Kernel& kernel() const noexcept { return kernel_; }
  std::size_t size() const noexcept { return particles_.size(); }

  /// Throws BlowUpError naming the first particle outside the domain or with a non-finite state.
  void check_state(T time) const {
    const auto& p = particles_;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const char* bad = nullptr;
      if (!p.position[i].allFinite()) bad = "position";
      else if (!p.velocity[i].allFinite()) bad = "velocity";
      else if (!std::isfinite(p.density[i]) || !(p.density[i] > T(0))) bad = "density";
      if (bad)
        throw BlowUpError(fmt::format(
            "blow-up at t = {:.6g} s: {} particle id {} has a non-finite or non-physical "
            "{} (x = [{}], v = [{}], rho = {})",
            time, kind_name(p.kind[i]), p.id[i], bad, fmt_vec(p.position[i]), fmt_vec(p.velocity[i]), p.density[i]));
      if (!domain_.contains(p.position[i]))
        throw BlowUpError(fmt::format(
            "at t = {:.6g} s: {} particle id {} left the domain: x = [{}], domain [{}] to [{}]", time,
            kind_name(p.kind[i]), p.id[i], fmt_vec(p.position[i]), fmt_vec(domain_.lower), fmt_vec(domain_.upper)));
    }
  }

  /// Re-sorts particles by cell and rebuilds the neighbour index. Call after particles moved.
  void update_neighbors(T time = T(0)) {
    check_state(time);
    T h_max = T(0), h_min = std::numeric_limits<T>::max();
    for (T h : particles_.smoothing_length) {
      h_max = std::max(h_max, h);
      h_min = std::min(h_min, h);
    }
    uniform_h_ = h_max > T(0) && h_min == h_max;
    if (h_max <= T(0)) h_max = T(1);
    h_uniform_ = h_max;
    constexpr T support = static_cast<T>(Kernel::support);
    if (uniform_h_ || !multilevel_enabled_) {
      cells_.build(particles_, domain_, support * h_max);
      multilevel_ = false;
    } else {
      multilevel_ = levels_.build(particles_, domain_, support, cells_) > 1;
    }
  }

  /// Lets update_neighbors() build the multi-level search when the sizes ask for it (the default), or forces the single
  /// grid (for comparisons: benchmarks/mixed_resolution_search.cpp).
  void enable_multilevel_search(bool enabled) noexcept { multilevel_enabled_ = enabled; }

  /// Whether the last update_neighbors() built the multi-level search (sizes more than a factor 2 apart); if not,
  /// cells() alone is the search.
  bool multilevel_search() const noexcept { return multilevel_; }

  /// Whether every particle had the same smoothing length at the last update_neighbors().
  bool uniform_smoothing_length() const noexcept { return uniform_h_; }

  /// Throws InputError if two particles of different kinds or bodies lie closer than `fraction` times the smaller
  /// of their spacings (m / rho)^(1/Dim): overlapping bodies in a scene (checked before the first step). Solid
  /// particles inside walls are allowed (a clamped end embedded in a wall).
  /// Neighbours must be current (update_neighbors()).
  void check_overlaps(T fraction = T(0.4)) const {
    const auto& p = particles_;
    for (std::size_t a = 0; a < p.size(); ++a) {
      const T spacing_a = std::pow(p.mass[a] / p.density[a], T(1) / T(Dim));
      for_each_neighbor(a, [&](std::size_t b, const Vector&, T r, T) {
        if (p.kind[a] == p.kind[b] && p.body[a] == p.body[b]) return;
        const bool embedded = (p.kind[a] == Kind::wall && p.kind[b] == Kind::solid) ||
                              (p.kind[a] == Kind::solid && p.kind[b] == Kind::wall);
        if (embedded) return;  // a solid's clamped part may lie inside a wall
        const T spacing = std::min(spacing_a, std::pow(p.mass[b] / p.density[b], T(1) / T(Dim)));
        if (r < fraction * spacing)
          throw InputError(fmt::format(
              "overlapping bodies: {} particle id {} (body {}) and {} particle id {} (body {}) are {:.3g} m apart; "
              "particles of different bodies must be at least {} x their spacing ({:.3g} m) apart",
              kind_name(p.kind[a]), p.id[a], p.body[a], kind_name(p.kind[b]), p.id[b], p.body[b], r, fraction,
              fraction * spacing));
      });
    }
  }

  /// Calls f(j, dx, r, h_ab) for every particle j != i with r = |x_i - x_j| < support * h_ab.
  template <class F>
  void for_each_neighbor(std::size_t i, F&& f) const {
    if (multilevel_ && levels_.needs_levels(i))
      visit_neighbors(i, f, [this](std::size_t a, auto&& g) { levels_.for_each_candidate(a, g); });
    else visit_neighbors(i, f, [this](std::size_t a, auto&& g) { cells_.for_each_candidate(a, g); });
  }

  /// Calls f(j, dx, r, h_ab) like for_each_neighbor, but only for the neighbours j > i of the half stencil: over
  /// all i every neighbour pair is visited exactly once (pair forces evaluated once, applied to both particles).
  /// Every j lies in [i + 1, neighbor_once_end(i)).
  template <class F>
  void for_each_neighbor_once(std::size_t i, F&& f) const {
    if (multilevel_ && levels_.needs_levels(i))
      visit_neighbors(i, f, [this](std::size_t a, auto&& g) { levels_.for_each_candidate_once(a, g); });
    else visit_neighbors(i, f, [this](std::size_t a, auto&& g) { cells_.for_each_candidate_once(a, g); });
  }

  /// for_each_neighbor and for_each_neighbor_once for pair loops that take only partners whose smoothing length lies
  /// within the relative `tolerance` of h (FluidParameters::same_resolution_pairs; a particle's children): the
  /// multi-level search skips the cells of the other sizes. Every such neighbour is passed to f, and neighbours of
  /// other sizes may be too (the caller still tests the size); with one search grid these are for_each_neighbor and
  /// for_each_neighbor_once.
  template <class F>
  void for_each_neighbor_of_size(std::size_t i, T h, T tolerance, F&& f) const {
    if (multilevel_ && levels_.needs_levels(i)) {
      const std::pair<T, T> band = size_band(h, tolerance);  // no structured binding: clang < 16 cannot capture one
      const T low = band.first, high = band.second;
      visit_neighbors(
          i, f, [this, low, high](std::size_t a, auto&& g) { levels_.for_each_candidate_of_size(a, low, high, g); });
    } else {
      visit_neighbors(i, f, [this](std::size_t a, auto&& g) { cells_.for_each_candidate(a, g); });
    }
  }
  template <class F>
  void for_each_neighbor_once_of_size(std::size_t i, T h, T tolerance, F&& f) const {
    if (multilevel_ && levels_.needs_levels(i)) {
      const std::pair<T, T> band = size_band(h, tolerance);  // no structured binding: clang < 16 cannot capture one
      const T low = band.first, high = band.second;
      visit_neighbors(i, f, [this, low, high](std::size_t a, auto&& g) {
        levels_.for_each_candidate_once_of_size(a, low, high, g);
      });
    } else {
      visit_neighbors(i, f, [this](std::size_t a, auto&& g) { cells_.for_each_candidate_once(a, g); });
    }
  }

  /// One past the largest slot for_each_neighbor_once(i, f) can visit. The multi-level search keeps the storage
  /// order of the level-0 grid cells() and every neighbour in its 3^D cells, so the bound is the same.
  std::size_t neighbor_once_end(std::size_t i) const { return cells_.candidate_once_end(i); }

  /// Recomputes pressure and sound speed of fluid and wall particles from their density with the fluid EOS.
  /// Solid particles keep the pressure their solid model wrote.
  void update_pressure() {
    auto& p = particles_;
    parallel_for(p.size(), [&](std::size_t i) {
      if (p.kind[i] == Kind::solid) return;
      p.pressure[i] = eos_.pressure(p.density[i]);
      p.sound_speed[i] = eos_.sound_speed(p.density[i]);
    });
  }

  /// The level-0 cell grid: cell edge the largest support radius; the particles are stored in its cell order.
  const CellList<Dim, T>& cells() const noexcept { return cells_; }
  /// The multi-level search (valid while multilevel_search()).
  const MultilevelCellList<Dim, T>& levels() const noexcept { return levels_; }

 private:
  // Filters the candidates that `candidates(i, g)` passes to g by distance and calls f(j, dx, r, h_ab). With one
  // smoothing length for all particles h_ab is a loop constant (h_ab = (h + h) / 2 = h exactly), which lets the
  // compiler hoist the kernel's h-dependent factors out of the pair loop.
  template <class F, class Candidates>
  void visit_neighbors(std::size_t i, F& f, Candidates&& candidates) const {
    const Vector xi = particles_.position[i];
    const Vector* x = particles_.position.data();
    constexpr T support = static_cast<T>(Kernel::support);
    if (uniform_h_) {
      const T h = h_uniform_;
      const T radius2 = (support * h) * (support * h);
      candidates(i, [&, h, radius2](std::size_t j) {
        const Vector dx = xi - x[j];
        const T r2 = dx.squaredNorm();
        if (r2 < radius2 && j != i) f(j, dx, std::sqrt(r2), h);
      });
    } else {
      const T hi = particles_.smoothing_length[i];
      const T* hs = particles_.smoothing_length.data();
      // Captured by value: the multi-level search calls this filter out of line, where by-reference captures
      // would be reloaded for every candidate.
      candidates(i, [xi, x, hi, hs, i, &f](std::size_t j) {
        const Vector dx = xi - x[j];
        const T r2 = dx.squaredNorm();
        const T h_ab = T(0.5) * (hi + hs[j]);
        const T radius = support * h_ab;
        if (r2 < radius * radius && j != i) f(j, dx, std::sqrt(r2), h_ab);
      });
    }
  }

  // Support radii of the smoothing lengths within the relative tolerance of h (a few ulps wider: the radii the search
  // stored were rounded).
  static std::pair<T, T> size_band(T h, T tolerance) {
    constexpr T support = static_cast<T>(Kernel::support);
    const T widen = T(8) * std::numeric_limits<T>::epsilon();
    return {support * h * (T(1) - tolerance - widen), support * h * (T(1) + tolerance + widen)};
  }

  static std::string fmt_vec(const Vector& v) {
    std::string s;
    for (int d = 0; d < Dim; ++d) s += (d ? ", " : "") + fmt::format("{:.6g}", v[d]);
    return s;
  }

  Domain<Dim, T> domain_;
  Eos eos_;
  Kernel kernel_;
  Particles particles_;
  CellList<Dim, T> cells_;
  MultilevelCellList<Dim, T> levels_;
  T h_uniform_{1};                 // the smoothing length when uniform_h_, m
  bool uniform_h_{false};          // all smoothing lengths equal at the last update_neighbors()
  bool multilevel_{false};         // the last update_neighbors() built levels_
  bool multilevel_enabled_{true};  // enable_multilevel_search()
};

}  // namespace sphfsi
