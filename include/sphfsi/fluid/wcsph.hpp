// sphfsi: weakly-compressible SPH fluid (Monaghan 1994, J. Comput. Phys. 110:399) with walls.
//
// For a fluid particle a and its neighbours b (x_ab = x_a - x_b, v_ab = v_a - v_b, grad = grad_a W(r, h_ab)):
//   continuity     drho_a/dt = sum_b m_b v_ab . grad                                        (Monaghan 1992, 2.13)
//   momentum       dv_a/dt   = -sum_b m_b (p_a/rho_a^2 + p_b/rho_b^2 + Pi_ab) grad + g        (Monaghan 1992, 3.3)
//   art. viscosity Pi_ab = -alpha c_ab mu_ab / rho_ab,  mu_ab = h v_ab.x_ab / (r^2 + 0.01 h^2), v_ab.x_ab < 0
//                                                                                            (Monaghan 1992, 4.1)
//                  (FluidParameters::receding_pair_viscosity: every pair, the delta-SPH viscous term of Antuono et al.
//                   2010)
//                  with FluidParameters::viscosity_reference_smoothing_length h_ref > 0: alpha h_ref / h in place of
//                  alpha (mu_ab with h_ref), so that nu ~ alpha h c0 is the same at every resolution of a scene
//   laminar visc.  dv_a/dt += sum_b m_b nu (rho_a + rho_b)/(rho_a rho_b) x_ab.grad/(r^2 + eta^2) v_ab
//                                                                            (Morris, Fox & Zhu 1997, eq. 8)
//   delta-SPH      drho_a/dt += delta h c0 sum_b V_b 2 (rho_ab - rho_ab^H) x_ab.grad / (r^2 + eta^2)
//                  (Molteni & Colagrossi 2009, Comput. Phys. Commun. 180:861, with the hydrostatic correction
//                   rho_ab^H = rho0 g.x_ab / c0^2 of Fourtakas et al. 2019, Comput. Fluids 190:346, linearised;
//                   fluid-fluid pairs only)
//   XSPH           dx_a/dt = v_a + eps sum_b (m_b / rho_ab) (v_b - v_a) W_ab             (Monaghan 1989)
//   corrected pressure gradient (optional, FluidParameters::gradient_correction): for the selected fluid
//   particles a the momentum sum is split into the pressure-difference part and the zeroth-order part,
//     dv_a/dt = -sum_b m_b [(P_b - P_a) L_a + 2 P_a I] grad - sum_b m_b Pi_ab grad + g,   P = p / rho^2,
//     L_a = (sum_b V_b (x_b - x_a) (x) grad_a W_ab)^-1     (Bonet & Lok 1999, Comput. Methods Appl. Mech. Eng.
//                                                           180:97, eq. 43: kernel-gradient correction)
//   With L_a the difference part is exact for a linear field on any particle set, also where the kernel is cut
//   by a repulsive wall or the set is disordered; the zeroth-order part 2 P_a sum_b m_b grad is the symmetric
//   form's own (on a full, ordered support it vanishes; next to a wall it presses the fluid onto the wall, the
//   push the repulsive force balances). L_a = I gives the symmetric form back.
// Walls:
//   dynamic boundary particles (Crespo, Gomez-Gesteira & Dalrymple 2007, CMC 5:173; the SPHysics default):
//     wall particles obey the continuity equation with their fluid neighbours and enter the fluid's
//     pressure and viscosity sums; their density is kept >= rho0 so walls never attract fluid.
//   extrapolated walls (Adami, Hu & Adams 2012, J. Comput. Phys. 231:7057, eq. 27): the same wall particles in the
//   same sums, but at every evaluation each takes the pressure of the fluid it sees, extrapolated to its place,
//     p_w = (sum_f p_f W_wf + (g - a_w) . sum_f rho_f (x_w - x_f) W_wf) / sum_f W_wf,
//   and the density rho_w = rho(p_w) of the equation of state. A dynamic wall particle carries the density its own
//   continuity equation gave it, which lags: a bed that a towed blade has passed keeps the blade's stagnation
//   pressure (docs/thin-blades.md, session 32). Here a_w = 0: walls at rest or moving steadily (an accelerating
//   wavemaker keeps dynamic walls). Pairs hidden by a thin structure are left out of the sums, so a wall particle
//   under a blade's face takes that face's pressure. p_w + p_bg >= 0: a wall never pulls the fluid.
//   repulsive walls (Monaghan & Kos 1999, with Rogers & Dalrymple 2008): see boundary/repulsive_force.hpp;
//     wall particles only push the fluid along their normal and take no part in the SPH sums.
// Thin structures (one line of nodes, e.g. solid/elastic_rod.hpp) publish their edges (Simulation collects them from
// its models); with FluidParameters::thin_structure_visibility, fluid and wall pairs whose segment crosses an edge
// do not interact (fluid/thin_structure_visibility.hpp), so the fluid on one face does not feel the other face
// through the SPH sums. 2D only.
// Solid particles are skipped here: a coupling policy owns fluid-solid pairs. Contract with the solid models:
// compute_rates() zeroes the acceleration of solid particles; couplings (ParticleModels evaluated after the
// fluid) add the fluid-on-solid force per unit mass there; the solid model adds its internal forces and gravity
// when it advances its particles (possibly in several sub-steps).
#pragma once

#include <sphfsi/boundary/repulsive_force.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/fluid/thin_structure_guard.hpp>
#include <sphfsi/fluid/thin_structure_visibility.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace sphfsi {

/// How wall particles act on the fluid.
enum class WallModel {
  dynamic,    ///< dynamic boundary particles (SPHysics default)
  repulsive,  ///< Monaghan-Kos repulsive force
  /// Wall particles whose pressure is extrapolated from the fluid beside them at every evaluation (Adami, Hu & Adams
  /// 2012): no density of their own to lag behind the fluid's
  extrapolated,
};

/// Which fluid particles get the kernel-gradient-corrected pressure gradient (Bonet & Lok 1999; see the header).
enum class GradientCorrection {
  none,                  ///< Monaghan's symmetric form everywhere (momentum conserved pair by pair)
  near_repulsive_walls,  ///< fluid particles with a repulsive wall particle within their support (cut kernels)
  everywhere,            ///< every fluid particle
  /// Fluid particles with a neighbour of another smoothing length (a resolution jump, fluid/particle_refinement.hpp)
  /// get the corrected gradient in difference form, -(1/rho_a) sum_b V_b (p_b - p_a) L_a grad_a W_ab: it vanishes
  /// for a uniform pressure on any particle set, where the symmetric form's 2 p_a / rho_a sum_b V_b grad_a W_ab
  /// (not zero across a jump of h) pushes with about 2 p / rho times 0.2 / h (measured: the refined still tank
  /// mixes within 0.1 s). Momentum is then not exchanged pair-wise at those particles.
  resolution_jumps,
};

template <int Dim, Real T>
struct FluidParameters {
  Vec<Dim, T> gravity = standard_gravity<Dim, T>();  ///< m/s^2
  T artificial_viscosity{T(0.01)};                   ///< alpha of Monaghan's artificial viscosity, [0, 1]
  /// Smoothing length h_ref (m) at which `artificial_viscosity` applies when particles of several sizes share a scene
  /// (0: alpha at every h). A pair of smoothing length h then uses alpha h_ref / h, so the effective viscosity
  /// nu, proportional to alpha h c0, is the same at every resolution: coarse fluid no longer damps a wave twice as fast
  /// as the fine fluid it surrounds (docs/variable-resolution.md, session 20).
  T viscosity_reference_smoothing_length{T(0)};
  /// Artificial viscosity on receding pairs too (v_ab.x_ab > 0), not only on approaching ones: the viscous term of
  /// the delta-SPH scheme (Antuono, Colagrossi, Marrone & Molteni 2010, Comput. Phys. Commun. 181:532;
  /// Marrone et al. 2011), a consistent viscous operator that damps shear whichever way a pair moves. false: Monaghan's
  /// switch, which leaves the receding half of every shear flow undamped.
  bool receding_pair_viscosity{false};
  T density_diffusion{T(0.1)};  ///< delta of delta-SPH, [0, 1] (0 switches it off)
  T xsph{T(0)};                 ///< epsilon of XSPH, [0, 1)
  T kinematic_viscosity{T(0)};  ///< laminar viscosity nu, m^2/s (0: none)
  WallModel walls{WallModel::dynamic};
  RepulsiveForceParameters<T> repulsive{};  ///< used when walls == repulsive
  /// Artificial viscosity between fluid and dynamic wall particles too (true, the usual DBC practice: a no-slip-like
  /// viscous wall); false: fluid-fluid pairs only, so the walls act on the fluid by pressure alone (a wave flume's
  /// bed then has no viscous Stokes layer of the artificial viscosity nu = alpha h c0 / 8; docs/flume.md).
  bool wall_artificial_viscosity{true};
  /// Kernel-gradient correction of the pressure gradient (none: the symmetric, momentum-conserving form).
  GradientCorrection gradient_correction{GradientCorrection::none};
  /// Fluid pressure floor, Pa (-inf: none). 0 stops spray clusters from collapsing under negative pressure
  /// (tensile instability, Swegle et al. 1995): water in a thin jet cannot sustain tension.
  T minimum_pressure{-std::numeric_limits<T>::infinity()};
  /// Background pressure p_bg, Pa, finite and >= 0 (0: none): added to every fluid
  /// and wall pressure in the symmetric pressure gradient, sum_b m_b ((p_a + p_bg) / rho_a^2 + (p_b + p_bg) / rho_b^2)
  /// grad W (Morris, Fox & Zhu 1997; Adami, Hu & Adams 2013). In a full support it adds no force (to the lattice's
  /// round-off); where a support is cut, at the faces of a thin structure under the visibility criterion, it pushes
  /// the fluid against the structure as the ambient pressure of a real flow does. A repulsive face can only push:
  /// without it the fluid in a wake, below the reference pressure, leaves the lee face (a confined flow with g = 0 has
  /// no hydrostatic pressure to hold it there; docs/thin-blades.md). For confined flows: at a free surface it would
  /// push the surface particles out. The corrected-gradient forms use pressure differences and do not see it.
  T background_pressure{0};
  /// Pairs whose segment crosses an edge of a thin structure (WcsphFluid::set_structure_edges) do not interact
  /// (true); false: the published edges are ignored and the fluid interacts through the structure in its sums.
  bool thin_structure_visibility{false};
  /// A fluid particle that stepped through a thin structure within a step is put back on the face it started on
  /// (fluid/thin_structure_guard.hpp; the Simulation applies it after each step), with or without the visibility
  /// criterion. Structures of permeable couplings (porous blades) publish no edges, so it does not apply to them.
  bool thin_structure_guard{true};
  /// Fluid-fluid and fluid-wall pairs interact only between particles of the same smoothing length (within 0.1 %):
  /// each resolution of an adaptive particle refinement is a complete SPH discretisation of its own, with its own
  /// walls, and the resolutions meet only through passive particles (fluid/adaptive_refinement.hpp; Chiron et al.
  /// 2018). false: every pair interacts with the averaged smoothing length (splitting and merging,
  /// fluid/particle_refinement.hpp). Fluid-solid pairs belong to the couplings either way.
  bool same_resolution_pairs{false};

  void validate() const {
    for (int d = 0; d < Dim; ++d) require_finite("FluidParameters::gravity", gravity[d]);
    require_in_range("FluidParameters::artificial_viscosity (alpha)", artificial_viscosity, T(0), T(1));
    require_non_negative("FluidParameters::viscosity_reference_smoothing_length (m)",
                         viscosity_reference_smoothing_length);
    require_in_range("FluidParameters::density_diffusion (delta)", density_diffusion, T(0), T(1));
    require_in_range("FluidParameters::xsph (epsilon)", xsph, T(0), T(0.999));
    require_non_negative("FluidParameters::kinematic_viscosity (m^2/s)", kinematic_viscosity);
    if (!(minimum_pressure <= T(0)))
      throw InputError(fmt::format("FluidParameters::minimum_pressure = {} Pa is invalid: valid range is [-inf, 0]",
                                   minimum_pressure));
    require_non_negative("FluidParameters::background_pressure (Pa)", background_pressure);
    require_finite("FluidParameters::background_pressure (Pa)", background_pressure);
    if (walls == WallModel::repulsive)
      require_positive("FluidParameters::repulsive.boundary_spacing (m)", repulsive.boundary_spacing);
  }
};

/// Computes the fluid and wall rates of a ParticleSystem and the fluid's stable time step.
template <class System>
class WcsphFluid {
 public:
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;

  explicit WcsphFluid(const FluidParameters<Dim, T>& params) : params_(params) { params_.validate(); }

  const FluidParameters<Dim, T>& parameters() const noexcept { return params_; }

  /// Per-slot signal speed max_b |mu_ab| of the last evaluation (part of the time-step state; checkpoints save it).
  const std::vector<T>& signal_speeds() const noexcept { return signal_speed_; }
  /// Restores the signal speeds saved with signal_speeds() (io/checkpoint.hpp).
  void restore_signal_speeds(std::vector<T> speeds) { signal_speed_ = std::move(speeds); }

  /// Edges of thin structures (pairs of node ids) that hide fluid and wall pairs from each other (see the header
  /// comment and FluidParameters::thin_structure_visibility); in 3D with each edge's lateral band (a ribbon's strip
  /// element, fluid/thin_structure_visibility.hpp). An empty list removes them.
  void set_structure_edges(std::vector<StructureEdge> edges, std::vector<std::array<T, 2>> bands = {}) {
    visibility_.set_edges(std::move(edges), std::move(bands));
  }
  const ThinStructureVisibility<T, Dim>& structure_visibility() const noexcept { return visibility_; }

  /// After a step (positions at its start in position_old): puts back the fluid particles that stepped through a
  /// thin structure (FluidParameters::thin_structure_guard); returns how many. Needs this step's compute_rates and a
  /// neighbour index that fits the particles as they are now.
  std::size_t keep_fluid_beside_structures(System& system) {
    if (!guarded_) return 0;
    // A model may have split, merged or re-sorted particles since the evaluation (it then rebuilt the neighbour
    // index): the candidate lists are rebuilt for the particles as they are now.
    if (!visibility_.matches(system.particles())) visibility_.update(system);
    return guard_.restore(system.particles(), visibility_);
  }
  /// Fluid particles put back by keep_fluid_beside_structures since construction.
  std::size_t structure_crossings_prevented() const noexcept { return guard_.crossings_prevented(); }
  /// The guard itself (its counts).
  const ThinStructureGuard<T, Dim>& structure_guard() const noexcept { return guard_; }

  /// Overwrites acceleration, density_rate and xsph_velocity of fluid and wall particles
  /// (pressure and sound speed must be current: System::update_pressure(), neighbours too:
  /// System::update_neighbors()).
  ///
  /// Each neighbour pair is evaluated once (ParticleSystem::for_each_neighbor_once) and applied to both particles:
  /// W, grad W and the pair terms are symmetric (grad_b W = -grad_a W), so the pair's contributions to a and b
  /// differ only by the partner's mass and sign. Threads take contiguous slot ranges; what a pair adds to a slot
  /// beyond its range goes to that range's spill buffer, added after the parallel loop. A pair of two passive fluid
  /// particles (fluid/adaptive_refinement.hpp) adds only to their signal speeds: their rates are zeroed anyway.
  ///
  /// `frozen` (one flag per slot, or null): local time stepping (integrators/local_time_stepping.hpp) evaluates only
  /// the particles that take a step now; a frozen slot keeps the rates it has, and its pairs are skipped. It needs
  /// FluidParameters::same_resolution_pairs with the frozen particles one resolution (no pair joins a frozen
  /// particle to one that is not); the signal speed of a frozen slot is left at zero. `mixed`: a frozen particle may
  /// have stepping neighbours of its own resolution (the fine-step regions of Simulation); such a pair adds its
  /// share to the stepping particle only, read from the frozen one's current state.
  void compute_rates(System& system, const std::vector<std::uint8_t>* frozen = nullptr, bool mixed = false) {
    auto& p = system.particles();
    const std::size_t n = p.size();
    if (frozen && frozen->size() != n)
      throw InputError(fmt::format(
          "WcsphFluid::compute_rates: frozen has {} flags for {} particles (valid: one per slot)", frozen->size(), n));
    if (frozen && !params_.same_resolution_pairs)
      throw InputError(
          "WcsphFluid::compute_rates: frozen particles need FluidParameters::same_resolution_pairs = true (valid: the "
          "resolutions interact only through passive particles, so no pair joins a frozen particle to a stepping one)");
    frozen_ = frozen ? frozen->data() : nullptr;
    frozen_mixed_ = frozen && mixed;
    signal_speed_.assign(n, T(0));
    pressure_term_.resize(n);
    volume_.resize(n);
    const T background = params_.background_pressure;
    parallel_for(n, [&](std::size_t a) {
      pressure_term_[a] = (p.pressure[a] + background) / (p.density[a] * p.density[a]);  // p / rho^2, Pa m^6/kg^2
      volume_[a] = p.mass[a] / p.density[a];                                             // m^3 (m^2 in 2D)
      if (frozen_ && frozen_[a]) return;
      p.acceleration[a] = Vector::Zero();
      p.density_rate[a] = T(0);
      p.xsph_velocity[a] = Vector::Zero();
    });
    occluded_ = params_.thin_structure_visibility && visibility_.active();
    guarded_ = params_.thin_structure_guard && visibility_.active();
    if (occluded_ || guarded_) visibility_.update(system);  // the guard uses the same candidate edges
    if (params_.walls == WallModel::extrapolated) extrapolate_wall_pressure(system);
    if (params_.gradient_correction != GradientCorrection::none) update_gradient_correction(system);
    // A few slot ranges per thread, handed out dynamically: wall particles cost less than fluid ones, and on a
    // shared machine a thread may be descheduled for a while.
    const std::size_t threads = static_cast<std::size_t>(std::max(1, thread_count()));
    const std::size_t chunks = threads == 1 ? 1 : std::min<std::size_t>(4 * threads, std::max<std::size_t>(1, n / 128));
    if (spills_.size() < chunks) spills_.resize(chunks);
    parallel_chunks(n, chunks, [&](std::size_t begin, std::size_t end, std::size_t chunk) {
      accumulate_pairs(system, begin, end, spills_[chunk]);
    });
    for (Spill& spill : spills_) {
      for (std::size_t k = 0; k < spill.density_rate.size(); ++k) {
        const std::size_t b = spill.begin + k;
        p.acceleration[b] += spill.acceleration[k];
        p.density_rate[b] += spill.density_rate[k];
        p.xsph_velocity[b] += spill.xsph_velocity[k];
        signal_speed_[b] = std::max(signal_speed_[b], spill.signal_speed[k]);
      }
      spill.resize(0);
    }
    const Vector g = params_.gravity;
    parallel_for(n, [&](std::size_t a) {
      if (p.kind[a] != Kind::fluid || (frozen_ && frozen_[a])) return;
      if (p.passive[a]) {  // carried with the velocity its model interpolates; it only serves as a neighbour
        p.acceleration[a] = Vector::Zero();
        p.density_rate[a] = T(0);
        p.xsph_velocity[a] = Vector::Zero();
      } else {
        p.acceleration[a] += g;
      }
    });
    frozen_ = nullptr;
    frozen_mixed_ = false;
  }

  /// Stable time step of the last evaluated rates (Monaghan & Kos 1999; SPHysics): min of
  ///   force      sqrt(h / |a|),   acoustic/viscous   h / (c + max_b |mu_ab|),   laminar   h^2 / (8 nu),
  /// without the CFL factor (the integrator applies it).
  T stable_time_step(const System& system) const {
    return stable_time_step(system, [](std::size_t) { return true; });
  }
  /// The same over the fluid particles a for which selected(a) holds (a time level of local time stepping).
  template <class Selected>
  T stable_time_step(const System& system, Selected&& selected) const {
    const auto& p = system.particles();
    const T inf = std::numeric_limits<T>::max();
    const T nu = params_.kinematic_viscosity;
    return parallel_min(p.size(), inf, [&](std::size_t a) {
      if (p.kind[a] != Kind::fluid || !selected(a)) return inf;
      const T h = p.smoothing_length[a];
      const T f = p.acceleration[a].norm();
      T dt = f > T(0) ? std::sqrt(h / f) : inf;
      dt = std::min(dt, h / (p.sound_speed[a] + (a < signal_speed_.size() ? signal_speed_[a] : T(0))));
      if (nu > T(0)) dt = std::min(dt, T(0.125) * h * h / nu);
      return dt;
    });
  }

 private:
  // Smallest det(M_a) for which L_a = M_a^-1 is used (a full support has M_a = I, det 1; a particle at a flat
  // free surface about 0.5): below it (a particle with few neighbours, a splash) M_a is too close to singular for
  // its inverse to be trusted, and L_a = I.
  static constexpr T min_moment_determinant = T(0.1);

  // Largest h |sum_b V_b grad_a W_ab| (the part not along a repulsive wall's normal) of a corrected particle. The
  // vector vanishes on a full support and points into the fluid where the support is cut (Marrone et al. 2010,
  // J. Comput. Phys. 229:3652, use it as the free-surface normal): h |.| is 0.59 and 0.07 for the first and second
  // row under a flat free surface (square lattice, cubic spline, h = 1.3 dp) and 0 from the third row down. So
  // particles within two rows of a free surface keep the symmetric form: its missing support above them is what
  // holds them to the surface (measured: corrected surface particles fly off within 0.2 s), and a corrected
  // gradient is blind to it.
  static constexpr T max_free_surface_moment = T(0.05);

  // Smallest kernel sum sum_b V_b W_ab (self included) of a particle corrected at a resolution jump: 1 inside the
  // fluid to the kernel's lattice error (1 % uniform, 7.6 % at a 2:1 jump, docs/variable-resolution.md), about
  // 0.5 at a free surface.
  static constexpr T min_interior_colour = T(0.85);

  // Relative difference of smoothing lengths below which two particles count as one resolution
  // (FluidParameters::same_resolution_pairs).
  static constexpr T same_h_tolerance = T(1e-3);

  // L_a for the fluid particles selected by gradient_correction (corrected_[a] = 1), from the moment matrix
  //   M_a = sum_b V_b (x_b - x_a) (x) grad_a W_ab = -sum_b V_b (dW/dr / r) dx dx^T   (dx = x_a - x_b)
  // over the neighbours that enter a's pressure sum (fluid, and dynamic wall particles). On a full lattice support
  // M_a = I to the kernel's discretisation error.
  void update_gradient_correction(const System& system) {
    const auto& p = system.particles();
    const std::size_t n = p.size();
    correction_.resize(n);
    const bool walls_in_sums = params_.walls != WallModel::repulsive;  // walls in the pressure sums
    const bool everywhere = params_.gradient_correction == GradientCorrection::everywhere;
    // Candidates: every fluid particle, or those within the support of a repulsive wall particle (found from the
    // wall side: walls are few).
    corrected_.assign(n, 0);
    if (everywhere) {
      for (std::size_t a = 0; a < n; ++a) corrected_[a] = p.kind[a] == Kind::fluid;
    } else if (params_.gradient_correction == GradientCorrection::resolution_jumps) {
      if (system.uniform_smoothing_length()) return;
      parallel_for(n, [&](std::size_t a) {
        if (p.kind[a] != Kind::fluid) return;
        const T ha = p.smoothing_length[a];
        bool jump = false;
        system.for_each_neighbor(a, [&](std::size_t b, const Vector&, T, T) {
          jump = jump || (p.kind[b] != Kind::solid && std::abs(p.smoothing_length[b] - ha) > T(1e-3) * ha);
        });
        corrected_[a] = jump;
      });
    } else if (!walls_in_sums) {
      for (std::size_t w = 0; w < n; ++w) {
        if (p.kind[w] != Kind::wall) continue;
        system.for_each_neighbor(w, [&](std::size_t b, const Vector&, T, T) {
          if (p.kind[b] == Kind::fluid) corrected_[b] = 1;
        });
      }
    }
    const auto& kernel = system.kernel();
    parallel_for(n, [&](std::size_t a) {
      if (!corrected_[a]) return;
      corrected_[a] = 0;  // until L_a is known
      Mat<Dim, T> moment = Mat<Dim, T>::Zero();
      Vector gamma = Vector::Zero();        // sum_b V_b grad_a W_ab, 1/m
      Vector wall_normal = Vector::Zero();  // sum of the normals of the repulsive wall particles within the support
      T colour = volume_[a] * kernel.value(T(0), p.smoothing_length[a]);  // sum_b V_b W_ab, self included
      system.for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T h) {
        const Kind kb = p.kind[b];
        if (kb == Kind::solid) return;
        if (kb == Kind::wall && !walls_in_sums) {
          wall_normal += p.normal[b];
          return;
        }
        const T grad_factor = r > T(0) ? kernel.derivative(r, h) / r : T(0);
        moment.noalias() -= (volume_[b] * grad_factor) * (dx * dx.transpose());
        gamma += (volume_[b] * grad_factor) * dx;
        colour += volume_[b] * kernel.value(r, h);
      });
      if (!(moment.determinant() >= min_moment_determinant)) return;
      // Resolution jumps: particles within about h of a free surface (colour below min_interior_colour) keep the
      // symmetric form, whose missing support holds them to the surface; their pressure, and so the symmetric
      // form's error at the jump, is small there.
      if (params_.gradient_correction == GradientCorrection::resolution_jumps && colour < min_interior_colour) return;
      // Free-surface test: the part of gamma not along the wall normal comes from a support cut by something else
      // than the wall, a free surface; there the correction would remove the surface's restoring force.
      const T wall_norm = wall_normal.norm();
      if (wall_norm > T(0)) gamma -= gamma.dot(wall_normal) / (wall_norm * wall_norm) * wall_normal;
      // (At a resolution jump gamma is not zero inside the fluid either: there the test would reject every particle.)
      if (params_.gradient_correction != GradientCorrection::resolution_jumps &&
          gamma.norm() * p.smoothing_length[a] > max_free_surface_moment)
        return;
      correction_[a] = moment.inverse();
      corrected_[a] = 1;
    });
  }

  // Whether a thin structure hides the pair (a, b) from each other in this evaluation (the visibility criterion).
  bool hidden_by_structure(std::size_t a, std::size_t b, const Vector& xa, const Vector& xb) const noexcept {
    return occluded_ && (visibility_.near(a) || visibility_.near(b)) && visibility_.blocks(a, b, xa, xb);
  }

  // Extrapolated walls (see the header): each wall particle's pressure, density, sound speed, p / rho^2 and volume
  // from the fluid it sees. Reads fluid slots only and writes wall slots only, so the wall particles run in parallel.
  // A frozen wall particle (local time stepping) keeps its values; with same_resolution_pairs a wall particle sees
  // the fluid of its own size.
  void extrapolate_wall_pressure(System& system) {
    auto& p = system.particles();
    const auto& kernel = system.kernel();
    const auto& eos = system.eos();
    const Vector g = params_.gravity;
    const T background = params_.background_pressure;
    const bool same_resolution = params_.same_resolution_pairs;
    constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
    std::atomic<std::size_t> failed{none};  // a wall particle whose pressure has no density (below -stiffness)
    parallel_for(p.size(), [&](std::size_t w) {
      if (p.kind[w] != Kind::wall || (frozen_ && frozen_[w])) return;
      const T h_w = p.smoothing_length[w];
      const Vector x_w = p.position[w];
      T weight = T(0), pressure_sum = T(0);
      Vector density_moment = Vector::Zero();  // sum_f rho_f (x_w - x_f) W_wf
      system.for_each_neighbor(w, [&](std::size_t f, const Vector& dx, T r, T h) {
        if (p.kind[f] != Kind::fluid) return;
        if (same_resolution && std::abs(p.smoothing_length[f] - h_w) > same_h_tolerance * h_w) return;
        if (hidden_by_structure(w, f, x_w, p.position[f])) return;
        const T w_wf = kernel.value(r, h);
        weight += w_wf;
        pressure_sum += p.pressure[f] * w_wf;
        density_moment += (p.density[f] * w_wf) * dx;
      });
      // eq. 27 with a_w = 0; a wall particle out of every fluid particle's reach keeps the reference state
      const T pressure = std::max(weight > T(0) ? (pressure_sum + g.dot(density_moment)) / weight : T(0), -background);
      const T density = eos.density(pressure);
      if (!(density > T(0) && std::isfinite(density))) failed = w;
      p.pressure[w] = pressure;
      p.density[w] = density;
      p.sound_speed[w] = eos.sound_speed(density);
      pressure_term_[w] = (pressure + background) / (density * density);
      volume_[w] = p.mass[w] / density;
    });
    if (const std::size_t w = failed; w != none)
      throw BlowUpError(fmt::format(
          "extrapolated walls: wall particle id {} (x = {:.6g} m, vertical {:.6g} m) takes the pressure {:.6g} Pa from "
          "the fluid it sees, which the equation of state maps to no density (a tension beyond the liquid's "
          "stiffness)",
          p.id[w], p.position[w][0], p.position[w][Dim - 1], p.pressure[w]));
  }

  // What the pairs of one slot range add to slots beyond it (other ranges): slot begin + k at index k.
  struct Spill {
    std::size_t begin = 0;
    std::vector<Vector> acceleration, xsph_velocity;
    std::vector<T> density_rate, signal_speed;
    void resize(std::size_t count) {  // and zero; capacity is kept, so the time loop does not allocate
      acceleration.assign(count, Vector::Zero());
      xsph_velocity.assign(count, Vector::Zero());
      density_rate.assign(count, T(0));
      signal_speed.assign(count, T(0));
    }
  };

  // Where the partner's share of a pair goes: straight into the particle arrays, or, with `spilling`, into the
  // spill buffer for partners at or beyond `limit` (another range's slots).
  template <bool spilling>
  struct PartnerSink {
    Vector* acceleration;
    T* density_rate;
    Vector* xsph_velocity;
    T* signal_speed;
    Spill* spill;
    std::size_t limit;

    void add_acceleration(std::size_t b, const Vector& v) const {
      if (spilling && b >= limit) spill->acceleration[b - limit] += v;
      else acceleration[b] += v;
    }
    void add_density_rate(std::size_t b, T v) const {
      if (spilling && b >= limit) spill->density_rate[b - limit] += v;
      else density_rate[b] += v;
    }
    void add_xsph(std::size_t b, const Vector& v) const {
      if (spilling && b >= limit) spill->xsph_velocity[b - limit] += v;
      else xsph_velocity[b] += v;
    }
    void raise_signal_speed(std::size_t b, T v) const {
      T& s = (spilling && b >= limit) ? spill->signal_speed[b - limit] : signal_speed[b];
      s = std::max(s, v);
    }
  };

  // Pairs (a, b > a) for the slots a in [begin, end) of one range.
  void accumulate_pairs(System& system, std::size_t begin, std::size_t end, Spill& spill) {
    auto& p = system.particles();
    std::size_t reach = end;
    for (std::size_t a = begin; a < end; ++a) reach = std::max(reach, system.neighbor_once_end(a));
    spill.begin = end;
    spill.resize(reach - end);
    const PartnerSink<false> direct{
        p.acceleration.data(), p.density_rate.data(), p.xsph_velocity.data(), signal_speed_.data(), &spill, end};
    const PartnerSink<true> spilling{
        p.acceleration.data(), p.density_rate.data(), p.xsph_velocity.data(), signal_speed_.data(), &spill, end};
    for (std::size_t a = begin; a < end; ++a) {
      if (system.neighbor_once_end(a) <= end) accumulate_particle(system, a, direct);
      else accumulate_particle(system, a, spilling);
    }
  }

  // All pairs (a, b) with b > a in a's half stencil: a's share is summed locally, b's share goes to `partner`.
  template <class Sink>
  void accumulate_particle(System& system, std::size_t a, const Sink& partner) {
    auto& p = system.particles();
    const Kind ka = p.kind[a];
    if (ka == Kind::solid) return;  // solids: fluid-solid pairs belong to the coupling policies
    // Local time stepping: a frozen slot keeps its rates; its pairs give only their stepping partner's share
    // (with fine-step regions a frozen particle may have stepping neighbours of its own resolution).
    const bool frozen_a = frozen_ && frozen_[a];
    if (frozen_a && !frozen_mixed_) return;  // its pairs are all frozen too
    const auto& kernel = system.kernel();
    const T rho0 = system.eos().reference_density();
    const T c0 = system.eos().reference_sound_speed();
    const Vector g = params_.gravity;
    const T alpha = params_.artificial_viscosity;
    const T h_viscosity = params_.viscosity_reference_smoothing_length;  // 0: the pair's own h
    const bool receding_viscosity = params_.receding_pair_viscosity;
    const T delta = params_.density_diffusion;
    const T eps_xsph = params_.xsph;
    const T nu = params_.kinematic_viscosity;
    const bool walls_in_sums = params_.walls != WallModel::repulsive;  // walls in the pressure sums
    const bool corrected = params_.gradient_correction != GradientCorrection::none;
    const bool difference_form = params_.gradient_correction == GradientCorrection::resolution_jumps;
    const T* pressure = p.pressure.data();
    const int up = params_.repulsive.vertical_axis;
    const T water_level = params_.repulsive.water_level;
    const Kind* kind = p.kind.data();
    const Vector* x = p.position.data();
    const Vector* v = p.velocity.data();
    const T* mass = p.mass.data();
    const T* rho = p.density.data();
    const T* c = p.sound_speed.data();
    const T* pressure_term = pressure_term_.data();
    const T* volume = volume_.data();

    const bool fluid_a = ka == Kind::fluid;
    const bool passive_a = fluid_a && p.passive[a];
    const bool same_resolution = params_.same_resolution_pairs;
    const T h_a = p.smoothing_length[a];
    const Vector xa = x[a], va = v[a];
    const T rho_a = rho[a], ca = c[a], ma = mass[a], pa = pressure_term[a], vol_a = volume[a];
    Vector acc = Vector::Zero(), xsph = Vector::Zero();
    T drho = T(0), mu_max = T(0);

    const auto interact = [&](std::size_t b, const Vector& dx, T r, T h) {
      const Kind kb = kind[b];
      const bool fluid_b = kb == Kind::fluid;
      if (kb == Kind::solid || !(fluid_a || fluid_b)) return;  // wall-wall pairs do not interact
      const bool stepping_b = !(frozen_ && frozen_[b]);
      if (frozen_a && !stepping_b) return;
      if (same_resolution && std::abs(h_a - p.smoothing_length[b]) > same_h_tolerance * h_a) return;
      // hidden from each other by a thin structure
      if (hidden_by_structure(a, b, xa, x[b])) return;
      const Vector vab = va - v[b];
      if (passive_a && fluid_b && p.passive[b]) {  // both carried (their rates are zeroed): only the time step's
        const T mu = h * vab.dot(dx) * (T(1) / (r * r + T(0.01) * h * h));  // signal speed, as below
        mu_max = std::max(mu_max, std::abs(mu));
        if (stepping_b) partner.raise_signal_speed(b, std::abs(mu));
        return;
      }
      if (!walls_in_sums && !(fluid_a && fluid_b)) {  // repulsive wall: pushes the fluid particle only
        if (fluid_a)
          acc += repulsive_force<Dim, T>(dx, vab, p.normal[b], h, c0, xa[up] - water_level, params_.repulsive);
        else if (stepping_b)
          partner.add_acceleration(b, repulsive_force<Dim, T>(Vector(-dx), Vector(-vab), p.normal[a], h, c0,
                                                              x[b][up] - water_level, params_.repulsive));
        return;
      }
      // grad_a W = dx dW/dr / r, so v_ab . grad_a W = (dW/dr / r) v_ab . dx and dx . grad_a W = (dW/dr / r) r^2.
      const T grad_factor = r > T(0) ? kernel.derivative(r, h) / r : T(0);  // 1/m^(Dim+2)
      const Vector grad = grad_factor * dx;
      const T vr = vab.dot(dx);
      const T r2 = r * r;
      const T inverse_distance2 = T(1) / (r2 + T(0.01) * h * h);  // 1 / (r^2 + eta^2)
      const T mu = h * vr * inverse_distance2;
      const T continuity = grad_factor * vr;  // v_ab . grad_a W
      drho += mass[b] * continuity;
      T drho_b = ma * continuity;
      const T rho_b = rho[b];
      const bool viscous_pair = (fluid_a && fluid_b) || params_.wall_artificial_viscosity;
      // Pi_ab with alpha h_ref / h in place of alpha when a reference smoothing length is set: the same nu everywhere
      const T mu_viscous = h_viscosity > T(0) ? h_viscosity * vr * inverse_distance2 : mu;
      const T pi_ab = (vr < T(0) || receding_viscosity) && viscous_pair
                          ? -alpha * (ca + c[b]) * mu_viscous / (rho_a + rho_b)
                          : T(0);
      const T pb = pressure_term[b];
      const T force = pa + pb + pi_ab;
      const T laminar =
          nu > T(0) ? nu * (rho_a + rho_b) / (rho_a * rho_b) * grad_factor * r2 * inverse_distance2 : T(0);
      if (fluid_a) {
        if (difference_form && corrected_[a])  // -(V_b / rho_a) (p_b - p_a) L_a grad - m_b Pi_ab grad
          acc -= (volume[b] * (pressure[b] - pressure[a]) / rho_a) * (correction_[a] * grad) + (mass[b] * pi_ab) * grad;
        else if (corrected && corrected_[a])  // -m_b [(P_b - P_a) L_a + (2 P_a + Pi_ab) I] grad
          acc -= mass[b] * ((pb - pa) * (correction_[a] * grad) + (T(2) * pa + pi_ab) * grad);
        else acc -= (mass[b] * force) * grad;
        if (nu > T(0)) acc += (mass[b] * laminar) * vab;
        mu_max = std::max(mu_max, std::abs(mu));
      }
      if (fluid_b && stepping_b) {
        Vector acc_b =
            difference_form && corrected_[b]
                ? Vector((vol_a * (pressure[a] - pressure[b]) / rho_b) * (correction_[b] * grad) + (ma * pi_ab) * grad)
            : corrected && corrected_[b]  // grad_b W = -grad
                ? Vector(ma * ((pa - pb) * (correction_[b] * grad) + (T(2) * pb + pi_ab) * grad))
                : Vector((ma * force) * grad);
        if (nu > T(0)) acc_b -= (ma * laminar) * vab;
        partner.add_acceleration(b, acc_b);
        partner.raise_signal_speed(b, std::abs(mu));
      }
      if (fluid_a && fluid_b) {
        if (delta > T(0)) {
          const T hydrostatic = rho0 * g.dot(dx) / (c0 * c0);
          const T diffusion =
              delta * h * c0 * T(2) * ((rho_a - rho_b) - hydrostatic) * grad_factor * r2 * inverse_distance2;
          drho += volume[b] * diffusion;
          drho_b -= vol_a * diffusion;
        }
        if (eps_xsph > T(0)) {
          const T w = eps_xsph * kernel.value(r, h) / (T(0.5) * (rho_a + rho_b));
          xsph -= (mass[b] * w) * vab;
          if (stepping_b) partner.add_xsph(b, (ma * w) * vab);
        }
      }
      if (stepping_b) partner.add_density_rate(b, drho_b);
    };
    // One resolution per pair: the multi-level search skips the cells of the other sizes.
    if (same_resolution) system.for_each_neighbor_once_of_size(a, h_a, same_h_tolerance, interact);
    else system.for_each_neighbor_once(a, interact);
    if (frozen_a) return;
    p.acceleration[a] += acc;
    p.density_rate[a] += drho;
    p.xsph_velocity[a] += xsph;
    signal_speed_[a] = std::max(signal_speed_[a], mu_max);
  }

  FluidParameters<Dim, T> params_;
  std::vector<T> signal_speed_;
  std::vector<T> pressure_term_;                // p / rho^2 per slot, Pa m^6/kg^2
  std::vector<T> volume_;                       // m / rho per slot
  std::vector<Spill> spills_;                   // one per slot range
  std::vector<Mat<Dim, T>> correction_;         // L_a per slot (valid where corrected_[a])
  std::vector<unsigned char> corrected_;        // 1: slot a uses the corrected pressure gradient
  ThinStructureVisibility<T, Dim> visibility_;  // edges of thin structures
  ThinStructureGuard<T, Dim> guard_;            // keeps the fluid on its face of them
  bool occluded_{false};                        // this evaluation applies the visibility criterion
  bool guarded_{false};                         // this evaluation prepared the thin-structure guard
  const std::uint8_t* frozen_{nullptr};         // during compute_rates: slots that keep their rates (or null)
  bool frozen_mixed_{false};                    // during compute_rates: a frozen slot may pair with a stepping one
};

}  // namespace sphfsi
