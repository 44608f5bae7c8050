// sphfsi: refined fluid regions by particle splitting and merging.
//
// A scene declares boxes where the fluid is finer: a box of level L asks for the spacing dp / 2^L of the base
// fluid spacing dp (refinement ratio 2 per level). After every complete time step a fluid particle that is
// coarser than the level asked for at its position is split, and one that is finer than the level asked for
// within a buffer around it is merged with a neighbour of its own size:
//
//   splitting (Feldman & Bonet 2007, Int. J. Numer. Meth. Engng 72:295; Vacondio et al. 2013, Comput. Methods
//   Appl. Mech. Engrg. 256:132, the square pattern without a central daughter): the parent a becomes 2^Dim
//   daughters d at x_d = x_a + eps s_a (+-1, +-1[, +-1]), s_a = (m_a / rho_a)^(1/Dim) its spacing, with
//     m_d = m_a / 2^Dim,  v_d = v_a,  rho_d = rho_a,  h_d = (h/dp) (m_d / rho_d)^(1/Dim),
//   and the parent's rates (acceleration, density rate, XSPH velocity: the symplectic scheme reuses the last
//   step's density rate) and pressure. With eps = 1/4 the daughters sit on the fine lattice that tiles the
//   parent's cell. Mass and momentum are conserved exactly (division by a power of two is exact).
//
//   binary merging (Vacondio et al. 2013, sec. 3.2): a and its nearest neighbour b of the same mass become
//     m = m_a + m_b,  x = (m_a x_a + m_b x_b) / m,  v = (m_a v_a + m_b v_b) / m,
//     rho = m / (m_a / rho_a + m_b / rho_b)  (the pair's SPH volume is kept),  h = (h/dp) (m / rho)^(1/Dim),
//   rates mass-weighted like v, pressure from the equation of state. Mass and momentum are conserved to round-off.
//   In 2D two binary merges make one coarse particle out of four fine ones (three in 3D); between them a particle
//   has an intermediate mass: a particle's level is counted in halvings of the base mass rho0 dp^Dim,
//   k = round(log2(rho0 dp^Dim / m)), a whole level every Dim halvings. An intermediate particle that needs
//   splitting splits in two along x (three axes in 3D: along the first Dim - k mod Dim axes) to the next whole level.
//
// Hysteresis: splitting happens where a particle is inside a box of a higher level than its own; merging only
// where it is farther than buffer_width from every box of its level or higher. A particle moving back and forth
// across a box edge by less than the buffer width therefore splits once and never flickers.
//
// Wall and solid particles are never touched. Particles are removed with ParticleSet::remove (ids of merged-away
// particles are retired, new daughters get new ids), and the neighbour index is rebuilt after a step that changed
// the set, so neighbour queries between steps stay valid.
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

namespace sphfsi {

/// An axis-aligned box where the fluid is refined to level `level` (spacing dp / 2^level of the base spacing dp).
template <int Dim, Real T>
struct RefinementBox {
  Vec<Dim, T> lower;  ///< m
  Vec<Dim, T> upper;  ///< m
  int level{1};       ///< refinement level, [1, max_level]
  /// Faces that lie on a wall, which no fluid crosses (a box standing on a bed): bit 2 d is the lower face along axis
  /// d, bit 2 d + 1 the upper one. contains() never moves them, so the adaptive refinement
  /// (fluid/adaptive_refinement.hpp) dithers only the other, open faces, applies its hysteresis there and takes its
  /// account band and distant particles from them alone.
  unsigned wall_faces{0};

  static constexpr int max_level = 8;

  /// Whether x lies in the box grown by `margin` (m; negative: shrunk) on every side but its wall_faces.
  bool contains(const Vec<Dim, T>& x, T margin = T(0)) const {
    for (int d = 0; d < Dim; ++d) {
      const T low = (wall_faces >> (2 * d)) & 1u ? T(0) : margin,
              high = (wall_faces >> (2 * d + 1)) & 1u ? T(0) : margin;
      if (!(x[d] >= lower[d] - low && x[d] <= upper[d] + high)) return false;
    }
    return true;
  }

  /// Whether `inner` lies entirely in this box.
  bool encloses(const RefinementBox& inner) const {
    for (int d = 0; d < Dim; ++d)
      if (inner.lower[d] < lower[d] || inner.upper[d] > upper[d]) return false;
    return true;
  }

  /// Whether the two boxes share a volume (touching faces do not count).
  bool overlaps(const RefinementBox& other) const {
    for (int d = 0; d < Dim; ++d)
      if (!(lower[d] < other.upper[d] && other.lower[d] < upper[d])) return false;
    return true;
  }
};

/// Parameters of ParticleRefinement (a small trivially copyable policy).
template <Real T>
struct RefinementParameters {
  T base_spacing{0};       ///< dp, spacing of the unrefined fluid (level 0), m
  int ratio{2};            ///< spacing ratio between two levels (only 2 is supported)
  T buffer_width{0};       ///< distance beyond a box's edge within which its particles are not merged, m
  T split_offset{0.25};    ///< eps: daughter offset from the parent along each axis / parent spacing, (0, 0.5)
  T smoothing_ratio{1.3};  ///< h / spacing of split and merged particles (the scene's h/dp), [0.5, 3]

  void validate() const {
    require_positive("RefinementParameters::base_spacing (m)", base_spacing);
    if (ratio != 2)
      throw InputError(fmt::format(
          "RefinementParameters::ratio = {} is invalid: only 2 is supported (valid range is [2, 2])", ratio));
    require_non_negative("RefinementParameters::buffer_width (m)", buffer_width);
    require_in_open_range("RefinementParameters::split_offset (eps)", split_offset, T(0), T(0.5));
    require_in_range("RefinementParameters::smoothing_ratio (h/dp)", smoothing_ratio, T(0.5), T(3));
  }
};

/// What one refinement pass did.
struct RefinementCounts {
  std::size_t splits{0};   ///< parents split
  std::size_t merges{0};   ///< pairs merged
  std::size_t created{0};  ///< particles added (daughters beyond the parent's slot)
  std::size_t removed{0};  ///< particles removed (merge partners)
};

/// Splits and merges fluid particles after each time step so that the fluid's spacing follows the refinement boxes
/// (see the header comment). A ParticleModel: it adds no forces and does not limit the time step.
template <class System>
class ParticleRefinement {
 public:
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;
  using Box = RefinementBox<Dim, T>;
  /// No state a restart needs: the particles' masses say their levels (the counts are diagnostics only).
  static constexpr bool checkpoint_stateless = true;

  /// Throws InputError for invalid parameters, a box not inside the domain or of an invalid level, and two boxes of
  /// different levels that overlap without the finer one lying inside the coarser one (nested refinement).
  ParticleRefinement(const Domain<Dim, T>& domain, std::vector<Box> boxes, const RefinementParameters<T>& params)
      : boxes_(std::move(boxes)), params_(params) {
    params_.validate();
    for (std::size_t k = 0; k < boxes_.size(); ++k) {
      const Box& b = boxes_[k];
      require_in_range(fmt::format("RefinementBox[{}].level", k), b.level, 1, Box::max_level);
      for (int d = 0; d < Dim; ++d) {
        require_finite("RefinementBox::lower (m)", b.lower[d]);
        require_finite("RefinementBox::upper (m)", b.upper[d]);
        if (!(b.upper[d] > b.lower[d]))
          throw InputError(fmt::format("RefinementBox[{}]: upper[{}] = {} m must be greater than lower[{}] = {} m", k,
                                       d, b.upper[d], d, b.lower[d]));
        if (b.lower[d] < domain.lower[d] || b.upper[d] > domain.upper[d])
          throw InputError(
              fmt::format("RefinementBox[{}] = [{}, {}] m along axis {} is outside the domain: valid range is "
                          "[{}, {}] m",
                          k, b.lower[d], b.upper[d], d, domain.lower[d], domain.upper[d]));
      }
    }
    for (std::size_t a = 0; a < boxes_.size(); ++a)
      for (std::size_t b = a + 1; b < boxes_.size(); ++b) {
        const Box &ba = boxes_[a], &bb = boxes_[b];
        if (ba.level == bb.level || !ba.overlaps(bb)) continue;
        const bool nested = ba.level < bb.level ? ba.encloses(bb) : bb.encloses(ba);
        if (!nested)
          throw InputError(fmt::format(
              "RefinementBox[{}] (level {}) and RefinementBox[{}] (level {}) overlap with conflicting levels: boxes "
              "of different levels must be disjoint or nested (the finer inside the coarser)",
              a, ba.level, b, bb.level));
      }
  }

  const std::vector<Box>& boxes() const noexcept { return boxes_; }
  const RefinementParameters<T>& parameters() const noexcept { return params_; }

  /// Refinement level asked for at x: the highest level of the boxes containing it (0 outside every box).
  int target_level(const Vector& x) const { return highest_level(x, T(0)); }

  /// Level a particle at x may keep: the highest level of the boxes within buffer_width of it.
  int retained_level(const Vector& x) const { return highest_level(x, params_.buffer_width); }

  /// A particle's level in mass halvings, k = round(log2(rho0 dp^Dim / m)) (Dim halvings a level).
  int halvings(T mass, T reference_density) const {
    const T base_mass = reference_density * std::pow(params_.base_spacing, T(Dim));
    return static_cast<int>(std::lround(std::log2(base_mass / mass)));
  }

  // ---- ParticleModel ----
  void compute_rates(System&, T) {}
  T stable_time_step(const System&) const { return std::numeric_limits<T>::infinity(); }
  /// Splits and merges after the step [t, t + dt]; rebuilds the neighbour index if the particle set changed.
  void advance(System& system, T t, T dt) {
    last_ = refine(system);
    total_.splits += last_.splits;
    total_.merges += last_.merges;
    total_.created += last_.created;
    total_.removed += last_.removed;
    if (last_.created + last_.removed > 0) system.update_neighbors(t + dt);
  }

  /// Counts of the last pass and of all passes so far.
  const RefinementCounts& last_counts() const noexcept { return last_; }
  const RefinementCounts& total_counts() const noexcept { return total_; }

  /// One refinement pass over the fluid particles. The neighbour index must be from the last evaluation (merge
  /// partners are found with it); it is stale afterwards if anything changed (advance() rebuilds it).
  RefinementCounts refine(System& system) {
    auto& p = system.particles();
    const T rho0 = system.eos().reference_density();
    RefinementCounts counts;
    const std::size_t n = p.size();
    // 1. Classify on the unchanged set: split (-1), merge candidate (+1) or keep (0).
    action_.assign(n, 0);
    level_.assign(n, 0);
    for (std::size_t a = 0; a < n; ++a) {
      if (p.kind[a] != Kind::fluid) continue;
      const int k = halvings(p.mass[a], rho0);
      level_[a] = k;
      if (k < Dim * target_level(p.position[a])) action_[a] = -1;
      else if (k > Dim * retained_level(p.position[a])) action_[a] = 1;
    }
    // 2. Pair merge candidates with their nearest unpaired candidate of the same mass level, within two spacings.
    partner_.assign(n, no_partner);
    for (std::size_t a = 0; a < n; ++a) {
      if (action_[a] != 1 || partner_[a] != no_partner) continue;
      const T reach = T(2) * spacing(p, a);
      std::size_t best = no_partner;
      T best_r = reach;
      system.for_each_neighbor(a, [&](std::size_t b, const Vector&, T r, T) {
        if (action_[b] != 1 || partner_[b] != no_partner || level_[b] != level_[a] || r >= best_r) return;
        best = b;
        best_r = r;
      });
      if (best == no_partner) continue;
      partner_[a] = best;
      partner_[best] = a;
    }
    // 3. Merge each pair into its lower slot; the partners are removed at the end.
    removals_.clear();
    for (std::size_t a = 0; a < n; ++a) {
      const std::size_t b = partner_[a];
      if (b == no_partner || b < a) continue;
      merge(system, a, b);
      removals_.push_back(b);
      ++counts.merges;
    }
    // 4. Split (appends daughters beyond n).
    for (std::size_t a = 0; a < n; ++a) {
      if (action_[a] != -1) continue;
      const int partial = ((level_[a] % Dim) + Dim) % Dim;  // halvings past the last whole level
      const int axes = partial == 0 ? Dim : Dim - partial;
      const std::size_t daughters = split(system, a, axes);
      if (daughters == 0) continue;
      ++counts.splits;
      counts.created += daughters - 1;
    }
    // 5. Remove the merged partners, highest slot first (swap-with-last keeps the lower slots valid).
    std::sort(removals_.begin(), removals_.end(), std::greater<>());
    for (std::size_t slot : removals_) p.remove(slot);
    counts.removed = removals_.size();
    return counts;
  }

 private:
  static constexpr std::size_t no_partner = std::numeric_limits<std::size_t>::max();

  int highest_level(const Vector& x, T margin) const {
    int level = 0;
    for (const Box& b : boxes_)
      if (b.level > level && b.contains(x, margin)) level = b.level;
    return level;
  }

  template <class Particles>
  static T spacing(const Particles& p, std::size_t a) {
    return std::pow(p.mass[a] / p.density[a], T(1) / T(Dim));
  }

  // Merges b into a (see the header comment); b is left for removal.
  void merge(System& system, std::size_t a, std::size_t b) const {
    auto& p = system.particles();
    const T ma = p.mass[a], mb = p.mass[b], m = ma + mb;
    const T wa = ma / m, wb = mb / m;
    const T volume = ma / p.density[a] + mb / p.density[b];
    const T rho = m / volume;
    p.position[a] = wa * p.position[a] + wb * p.position[b];
    p.velocity[a] = (ma * p.velocity[a] + mb * p.velocity[b]) / m;
    p.acceleration[a] = wa * p.acceleration[a] + wb * p.acceleration[b];
    p.xsph_velocity[a] = wa * p.xsph_velocity[a] + wb * p.xsph_velocity[b];
    p.density_rate[a] = wa * p.density_rate[a] + wb * p.density_rate[b];
    p.mass[a] = m;
    p.density[a] = rho;
    p.smoothing_length[a] = params_.smoothing_ratio * std::pow(volume, T(1) / T(Dim));
    p.pressure[a] = system.eos().pressure(rho);
    p.sound_speed[a] = system.eos().sound_speed(rho);
    p.position_old[a] = p.position[a];
    p.velocity_old[a] = p.velocity[a];
    p.density_old[a] = rho;
  }

  // Splits a into 2^axes daughters (offsets along the first `axes` axes); returns their number, 0 if a daughter
  // would fall outside the domain (the parent is then kept as it is).
  std::size_t split(System& system, std::size_t a, int axes) const {
    auto& p = system.particles();
    const std::size_t count = std::size_t(1) << axes;
    const T rho = p.density[a];
    const T m = p.mass[a] / T(count);  // exact: a power of two
    const T daughter_spacing = std::pow(m / rho, T(1) / T(Dim));
    // eps is relative to the parent's spacing for the full split, i.e. 2 eps of the daughter's spacing.
    const T offset = T(2) * params_.split_offset * daughter_spacing;
    const Vector centre = p.position[a];
    const auto daughter_position = [&](std::size_t k) {
      Vector x = centre;
      for (int d = 0; d < axes; ++d) x[d] += ((k >> d) & 1u) ? offset : -offset;
      return x;
    };
    for (std::size_t k = 0; k < count; ++k)
      if (!system.domain().contains(daughter_position(k))) return 0;
    const T h = params_.smoothing_ratio * daughter_spacing;
    const Vector velocity = p.velocity[a];  // a copy: add() reallocates the arrays
    for (std::size_t k = 1; k < count; ++k) {
      const Vector x = daughter_position(k);
      const std::size_t d = p.add(Kind::fluid, x, velocity, rho, m, h, p.body[a]);
      p.pressure[d] = p.pressure[a];
      p.sound_speed[d] = p.sound_speed[a];
      p.acceleration[d] = p.acceleration[a];
      p.density_rate[d] = p.density_rate[a];
      p.xsph_velocity[d] = p.xsph_velocity[a];
      p.normal[d] = p.normal[a];
    }
    p.position[a] = daughter_position(0);
    p.position_old[a] = p.position[a];
    p.mass[a] = m;
    p.smoothing_length[a] = h;
    return count;
  }

  std::vector<Box> boxes_;
  RefinementParameters<T> params_;
  RefinementCounts last_{}, total_{};
  std::vector<signed char> action_;   // per slot: -1 split, +1 merge candidate, 0 keep
  std::vector<int> level_;            // per slot: mass halvings
  std::vector<std::size_t> partner_;  // per slot: merge partner or no_partner
  std::vector<std::size_t> removals_;
};

}  // namespace sphfsi
