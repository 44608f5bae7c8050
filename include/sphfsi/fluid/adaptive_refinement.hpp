// sphfsi: refined fluid regions by adaptive particle refinement with overlapping resolutions (APR).
//
// After Barcarolo, Le Touze, Oger & de Vuyst 2014 (J. Comput. Phys. 273:640) and Chiron, Oger, de Leffe & Le Touze
// 2018 (J. Comput. Phys. 354:552). Each resolution is a complete SPH discretisation of its own region, with its own
// walls: with FluidParameters::same_resolution_pairs a particle interacts only with particles of its own smoothing
// length, so no pair spans a jump of h. (The splitting-and-merging scheme of fluid/particle_refinement.hpp lets
// coarse and fine particles interact directly, and fails where the jump meets a wall or a free surface:
// docs/variable-resolution.md.) The resolutions meet through passive particles:
//
//   A box of level L asks for the spacing dp / 2^L. A fluid particle of level k (from its smoothing length,
//   h = (h/dp) dp / 2^k) at x, with L_in the highest level of the boxes containing x and L_near that of the boxes
//   within transition_width of x, is
//     active     if k == L_in                    (integrated: the resolution of the region it is in),
//     passive    if k < L_in                     (a coarser particle inside a finer box, kept for when it leaves),
//                or L_in < k <= L_near           (a finer particle in the transition zone around its box),
//     removed    if k > L_near                   (a finer particle that left the transition zone).
//   Passive particles get no rates from the fluid (WcsphFluid zeroes them: they move with their velocity) and serve
//   as neighbours of their resolution's active particles, so an active particle at a box edge has a full kernel
//   support of its own size. After every step their velocity and density are set from the active fluid particles of
//   every level within their pair support (h_ab = (h_a + h_b) / 2; their own level's too, so that the stencil is
//   two-sided at a box edge, where the other level is active on one side only) by the linear moving-least-squares
//   fit, weights V_b W(r_ab, h_ab): f_a = c_0 of the least-squares fit f_b ~ c_0 + c . (x_b - x_a), exact for linear
//   fields even where the stencil is one-sided (a free surface); with limit_fit, held per component within the range
//   of the values it is fitted from (Barth & Jespersen 1989's min-max principle: no overshoot where the fit
//   extrapolates, still exact inside the stencil's hull). Where the fit's moment matrix is degenerate, and
//   with linear_interpolation = false, the Shepard mean f_a = sum_b V_b f_b W_ab / sum_b V_b W_ab
//   (interpolate_from_own_level = false: from the other levels only, the scheme of Chiron et al.; measured worse).
//   and their mass is their SPH volume times their density, m_a = rho_a / sum_b W(r_ab, h_a) over the particles of
//   their level, at most passive_mass_bound (default 1) times the nominal mass rho0 (dp / 2^k)^Dim (with a bound above
//   1 the walls of their resolution count in the sum too): passive particles follow an interpolated velocity,
//   not their own pressure, and may bunch up; so bunched, they do not weigh more in their active neighbours' sums
//   than the fluid they stand for. A particle that becomes active keeps that mass.
//   Children: an active particle of level k in the transition zone of a finer box (k < L_near) has the 2^Dim
//   children of the square pattern x + eps s (+-1, +-1[, +-1]) (s its spacing, eps = 1/4: the fine lattice that tiles
//   its cell), each of mass m_a / 2^Dim and smoothing length h / 2. A child is created, passive, where its position
//   lies in the transition zone (not in the box: a box fills from its transition zone only) and no particle of level
//   k + 1 lies within occupied_fraction of the child spacing. The transition zone therefore stays filled with
//   children moving with the coarse flow, which become active as they enter the box.
//   populate() creates the children of every particle in and around the boxes once, at the start (those in the box
//   active, their parents passive).
//
// Lagrangian statuses (lagrangian_statuses): after populate() the statuses stay with the particles; a pass only fits
// the passive values. The refined region is then a patch of water that moves with the flow, with no status changes,
// children or removals, for oscillatory flows whose particles come back (waves).
//
// Dithered edges (edge_dither): each particle sees the box edges moved by its own fixed offset (a hash of its id), so
// that a column of particles crossing an edge together (a lattice; the water column of a wave's orbital motion)
// changes status particle by particle, not all at once.
//
// Paired statuses (paired_statuses): near a box edge a finer particle is active exactly when the nearest particle of
// the next coarser level is passive, so a coarse particle and the fine particles of its cell change status together
// and the water changes hands cell by cell, not column by column. With paired_exchange the group of a coarse particle
// and its paired fine ones that change status the other way also hand over their mass and momentum (the coarse one
// takes the fine ones' mass and mean velocity, or they are scaled to its mass and shifted to its velocity), so a
// status change is no local source of either and the accounts keep only what unpaired changes leave.
//
// Boxes that follow the flow (boxes_follow_flow): the boxes move along x with the mean velocity of the finest active
// fluid in them, so that a wave's orbital motion carries the edges with the water.
//
// Conservation: the coarse particles are never created or removed (inside a box they are passive). Mass and
// momentum are not exchanged pair-wise between resolutions: a particle that becomes active brings the mass it had as
// a passive one, one that becomes passive or is removed takes its mass away. The mass account (conserve_mass) hands
// the active mass a pass changed back to the active particles within transition_width of a box edge, each scaled by
// 1 + dM / M_edge, so the active fluid mass is conserved to round-off over every pass; the largest |dM / M_edge| is
// reported (AdaptiveRefinementCounts::mass_correction). The momentum account (conserve_momentum) then hands the
// active momentum the pass changed (the status changes and the mass account's rescaling carry momentum) back to the
// same particles as one velocity shift dP / M_edge, so the active momentum is conserved to round-off too; the largest
// shift is reported (AdaptiveRefinementCounts::momentum_correction). With mass_account_relaxation tau > 0 the mass
// account hands back a pending mass gradually (the share 1 - exp(-dt / tau) per pass), so that the active mass plus
// the pending mass is conserved to round-off: an immediate rescale at fixed density is a source of volume at the
// moments statuses change, which a wave's motion paces. The only state a restart needs beyond the particle fields
// (levels are smoothing lengths, passive flags and masses are particle fields) is that pending mass. Time step: one
// global step set by the finest particles (SymplecticVerlet), or the coarse levels at twice the finest level's step
// (LocalSymplecticVerlet, integrators/local_time_stepping.hpp; the pass then runs after each of the finest level's two
// sub-steps).
//
// Walls: a box that comes within a kernel support of a wall needs wall particles at its own spacing there (the scene
// adds them beside the coarse ones; each resolution sees only its own); populate() checks it. Couplings: the porous
// blade drag (coupling/blade_drag.hpp) acts on the active fluid only, so its blades may stand inside a box (away from
// its edges: scenes::PlantRefinement); the impermeable couplings and continuum solids are not supported inside the
// boxes or their transition zones (they would see the fluid of both resolutions).
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/fluid/particle_refinement.hpp>
#include <sphfsi/fluid/particle_shifting.hpp>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

namespace sphfsi {

/// Parameters of AdaptiveRefinement (a small trivially copyable policy).
template <Real T>
struct AdaptiveRefinementParameters {
  T base_spacing{0};       ///< dp, spacing of the unrefined fluid (level 0), m
  T transition_width{0};   ///< width of the zone around a box where its particles live on as passive ones, m
  T split_offset{0.25};    ///< eps: child offset from the parent along each axis / parent spacing, (0, 0.5)
  T smoothing_ratio{1.3};  ///< h / spacing of the scene (used for the transition-width check), [0.5, 3]
  /// A child is not placed where a refined particle that stays lies within this fraction of the child spacing of
  /// its position (the place is taken), [0.25, 1].
  T occupied_fraction{0.75};
  /// A passive particle of a transition zone closer than this fraction of its spacing to another of its level is
  /// removed (bunched up), [0.1, occupied_fraction).
  T bunched_fraction{0.5};
  /// Whether each pass hands the active mass it changed back to the active particles near the box edges (the mass
  /// account of the header comment), so that the active mass is conserved to round-off.
  bool conserve_mass{true};
  /// Whether each pass also hands the active momentum it changed back to the active particles near the box edges,
  /// as one velocity shift dP / M_edge, so that the active momentum is conserved to round-off too.
  bool conserve_momentum{true};
  /// Whether the accounts hand the mass and momentum a pass changed to every active fluid particle (one relative mass
  /// change and one velocity shift for all) instead of those near the box edges. A mass rescale at fixed density
  /// changes a particle's volume: near the edges it is a local source of volume, timed by the status changes, that a
  /// wave's own motion paces; spread over all the fluid it raises the level uniformly.
  bool account_over_all_fluid{false};
  /// Relaxation time tau of the mass account, s, >= 0. 0: each pass hands back at once the mass it changed. > 0: the
  /// changes go to a pending mass, of which each pass hands back the share 1 - exp(-dt / tau) (dt since the last
  /// pass), so the active mass plus the pending mass is conserved to round-off and the pending mass stays of the
  /// order of the changes over tau. A status change comes at a phase of a wave's orbital motion (with
  /// status_hysteresis, once per excursion), so an immediate rescale is a volume source paced by the wave;
  /// relaxed over several periods it is not (docs/variable-resolution.md, session 24).
  T mass_account_relaxation{0};
  /// Whether a passive particle is interpolated from the active particles of its own level too (h_ab = h_a), not
  /// only from those of the other levels: near a box edge the other level is active on one side only, its own on the
  /// other, so the stencil is two-sided.
  bool interpolate_from_own_level{true};
  /// Whether passive values come from a first-order (linear) moving-least-squares fit instead of the Shepard mean:
  /// exact for linear fields, also where the stencil is one-sided (a free surface, a box edge); Shepard where the
  /// fit's moment matrix is degenerate.
  bool linear_interpolation{true};
  /// Whether the linear fit is limited to the range of the values it is fitted from (per component, the smallest and
  /// largest density and velocity of the accepted neighbours; Barth & Jespersen 1989's min-max principle): where the
  /// stencil is one-sided (a free surface) the fit extrapolates and may overshoot; inside the neighbours' hull a linear
  /// field lies within their range, so the limit leaves the fit exact there.
  bool limit_fit{false};
  /// Whether a passive particle's mass is its SPH volume times its density (at most passive_mass_bound nominal
  /// masses), else the nominal mass rho0 s^Dim.
  bool passive_mass_from_volume{true};
  /// With passive_mass_from_volume: the largest passive mass, in nominal masses of its level, [1, 2]. At 1 (the
  /// default) passive particles that spread apart keep the nominal mass, so they stand for less water than their
  /// place holds; a status change then brings in less active mass than the other resolution gives up, which the mass
  /// account has to hand back (the loop through the box's top face of docs/variable-resolution.md, session 34). Above 1
  /// the mass follows the volume up to the bound, and the number density also counts the wall particles of the
  /// particle's own resolution, so that a particle next to a wall does not see a one-sided support as spread water.
  T passive_mass_bound{1};
  /// Hysteresis of the active / passive status at a box edge, in base spacings, [0, transition_width / base_spacing -
  /// smoothing_ratio] (a fine particle kept active outside its box keeps its support inside the transition zone):
  /// within this distance of an edge (on either side) a particle keeps its status, so one that oscillates across the
  /// edge by less (the orbital motion of a wave, the jitter of the particles) does not change it at every pass; it
  /// changes once the particle is this far past the edge. 0: the status follows the position exactly.
  T status_hysteresis{0};
  /// Dither of the box edges for the statuses, in base spacings, [0, 2]: each fluid particle sees every box edge moved
  /// outwards by its own fixed offset, uniform in [-edge_dither / 2, edge_dither / 2) base spacings (a hash of its id,
  /// so the same in every run, thread count and restart). On an abrupt edge a lattice column (or a whole water column
  /// in a wave's horizontal orbital motion) changes status at once: the active mass then swings by up to half a
  /// coarse column per edge as the columns of the two levels cross it in turn (a sawtooth in the displacement, paced by
  /// the wave). Dithered over a whole base spacing, a column changes status particle by particle and the expected
  /// active mass no longer depends on where the lattice stands against the edge (dithering, as in signal
  /// quantisation). 0: the edges are where the boxes say.
  T edge_dither{0};
  /// Whether a refined particle near a box edge takes its status from the coarser particle that stands for the same
  /// water (paired statuses): a particle of level k >= 1 within transition_width of an edge, not inside a box finer
  /// than k, is active exactly when the nearest particle of level k - 1 is passive, and that one's status follows
  /// its position (with status_hysteresis and edge_dither). The fine particles nearest a coarse one are its own
  /// children's places (2^Dim of them on the split lattice), so when a coarse particle changes status the fine
  /// particles of its cell change the other way in the same pass and the water changes hands in one piece: the
  /// active mass no longer swings by whole columns of one level (docs/variable-resolution.md, session 33). Statuses
  /// are decided level by level, coarse first. 0 / false: every particle's status follows its own position.
  bool paired_statuses{false};
  /// With paired_statuses: whether a coarse particle and the finer particles paired with it that change status the
  /// other way in the same pass exchange their mass and momentum (paired exchange): a coarse particle that becomes
  /// active takes the mass and mean velocity of its paired fine particles that become passive; fine particles that
  /// become active as their coarse one becomes passive are scaled to its mass and shifted to its velocity. The water
  /// then changes hands without a local source of mass or momentum; the accounts take only what unpaired changes left.
  /// A group whose fine mass is outside [1/2, 2] times the coarse one's is left to the accounts. Measured in the
  /// refined Posidonia flume it makes the box much worse (a blow-up; H off by up to 20 %): a coarse particle's cell
  /// holds 0.5-2 times its share of fine particles where the passive coarse ones have drifted, so the mass it takes
  /// does not fit its place (docs/variable-resolution.md, session 34). Kept, off by default, for that measurement.
  bool paired_exchange{false};
  /// Bound r of the activated account, [0, 1): with r > 0 the mass account hands the mass a pass changed first to the
  /// particles that became active in it (the water that changed hands: a status change that loses active mass is a
  /// coarse particle taking over, with its capped passive mass, the water its fine ones leave), in proportion to
  /// their masses, each held within [1 - r, 1 + r] times the nominal mass of its level (a mass that is already
  /// outside is not moved further out); only what does not fit goes to the particles near the box edges. Session 29's
  /// account to every active particle within a kernel support blew up (heavy and light particles at the edge); here
  /// the mass goes only to the particles that take over the water, and stays tied to their nominal volume. Measured in
  /// the refined Posidonia flume with r = 0.2 it is much worse than the band (tip +116 / +166 %, circulation cells of
  /// +-30 mm/s): heavier activated particles push the water at the face apart and make more status changes
  /// (docs/variable-resolution.md, session 35). Kept, off by default, for that measurement. 0: off.
  T activated_mass_bound{0};
  /// Whether the statuses populate() gave are carried by the particles from then on (Lagrangian statuses): after
  /// populate() a pass changes no status, creates no child and removes no particle; it only fits the passive
  /// particles' values. The refined region is then a patch of water that moves with the flow (the particles of each
  /// resolution stay where they started, as the fixed-mass particles of Omidvar, Stansby & Rogers 2012, Int. J.
  /// Numer. Meth. Fluids 68:686, stay around a body in waves), and the resolutions exchange nothing but the passive
  /// fits: the active mass is constant exactly and the accounts have nothing to do. For oscillatory flows (waves),
  /// whose particles come back to where they were; the patch drifts with the mean flow (Stokes drift, streaming),
  /// which must stay well below the distance from the box edges to what needs the fine fluid. Measured in a wave flume:
  /// nothing keeps the passive layers ordered, the resolutions mix at the patch edge within a few periods, and the
  /// wave loses 4-9 % behind the patch (docs/variable-resolution.md, session 26).
  bool lagrangian_statuses{false};
  /// Interval, s, >= 0, at which the distant passive particles are fitted: those farther than two kernel supports
  /// (plus status_hysteresis) from every region where their level is active. No integrated particle has them as a
  /// neighbour, nor a wall particle next to one; they only need values fresh enough to drift with the water until
  /// they come near a box edge, where every pass fits them again. A pass fits them where it crosses a multiple of
  /// the interval. 0: every passive particle at every pass. With local time stepping (two passes per coarse step) an
  /// interval of about the coarse step fits them about once per coarse step: measured, 15 % less wall time in the
  /// refined Posidonia flume (docs/variable-resolution.md, session 29). Not with lagrangian_statuses (the statuses do
  /// not follow the boxes there) or boxes_follow_flow.
  T distant_fit_interval{0};
  /// Whether the boxes move with the water along the first axis (x, a flume's direction of propagation): before each
  /// pass every box is shifted by dt times the mass-weighted mean x-velocity of the active particles of the finest
  /// level inside the boxes of that level, so that a wave's orbital motion carries the box edges with the water and
  /// fewer particles cross them. The total shift is held within +-(transition_width - the finest level's kernel
  /// support): a scene builds its fine walls under a box and its transition zone, so the active fine fluid keeps its
  /// walls. Along x only, so a box standing on a bed stays on it. Measured: a box top in a wave's vertical orbital
  /// motion still exchanges four fifths of the particles a fixed box does (docs/variable-resolution.md, session 26).
  bool boxes_follow_flow{false};
  /// Particle shifting (fluid/particle_shifting.hpp) of the active particles before each pass; off by default. With
  /// shift_refined_only, on the refined levels only (its max_smoothing_length is then set between levels 0 and 1),
  /// so the base fluid stays that of the uniform scene.
  ParticleShiftingParameters<T> shifting{};
  bool shift_refined_only{true};

  void validate() const {
    shifting.validate();
    require_positive("AdaptiveRefinementParameters::base_spacing (m)", base_spacing);
    require_positive("AdaptiveRefinementParameters::transition_width (m)", transition_width);
    require_in_open_range("AdaptiveRefinementParameters::split_offset (eps)", split_offset, T(0), T(0.5));
    require_in_range("AdaptiveRefinementParameters::smoothing_ratio (h/dp)", smoothing_ratio, T(0.5), T(3));
    require_in_range("AdaptiveRefinementParameters::occupied_fraction", occupied_fraction, T(0.25), T(1));
    // a fine particle kept active up to the hysteresis outside its box needs its whole support of fine particles
    // (2 h of level 1 = smoothing_ratio base spacings) inside the transition zone
    require_in_range("AdaptiveRefinementParameters::edge_dither (base spacings)", edge_dither, T(0), T(2));
    // paired statuses: a fine particle follows the nearest coarse one, up to half a coarse diagonal farther out
    require_in_range(
        "AdaptiveRefinementParameters::status_hysteresis (base spacings; at most transition_width / "
        "base_spacing - smoothing_ratio - edge_dither / 2, less 1 with paired_statuses)",
        status_hysteresis, T(0),
        std::max(T(0), transition_width / base_spacing - smoothing_ratio - T(0.5) * edge_dither -
                           (paired_statuses ? T(1) : T(0))));
    require_in_range("AdaptiveRefinementParameters::mass_account_relaxation (tau, s)", mass_account_relaxation, T(0),
                     T(1e6));
    require_in_range("AdaptiveRefinementParameters::distant_fit_interval (s)", distant_fit_interval, T(0), T(1));
    require_in_range("AdaptiveRefinementParameters::passive_mass_bound (nominal masses)", passive_mass_bound, T(1),
                     T(2));
    if (!(activated_mass_bound >= T(0) && activated_mass_bound < T(1)))
      throw InputError(
          fmt::format("AdaptiveRefinementParameters::activated_mass_bound = {} is invalid: valid range is "
                      "[0, 1) (a fraction of the nominal mass; 0: off)",
                      activated_mass_bound));
    if (activated_mass_bound > T(0) && !conserve_mass)
      throw InputError(
          "AdaptiveRefinementParameters::activated_mass_bound > 0 needs conserve_mass = true (it is a form of the "
          "mass account)");
    if (paired_exchange && !paired_statuses)
      throw InputError(
          "AdaptiveRefinementParameters::paired_exchange = true needs paired_statuses = true (the exchange is between "
          "a coarse particle and the fine particles paired with it)");
    if (distant_fit_interval > T(0) && (lagrangian_statuses || boxes_follow_flow))
      throw InputError(
          "AdaptiveRefinementParameters::distant_fit_interval > 0 needs fixed boxes and statuses that follow them "
          "(valid: lagrangian_statuses = false and boxes_follow_flow = false, or distant_fit_interval = 0)");
    if (!(bunched_fraction >= T(0.1) && bunched_fraction < occupied_fraction))
      throw InputError(
          fmt::format("AdaptiveRefinementParameters::bunched_fraction = {} is invalid: valid range is [0.1, {}) (below "
                      "occupied_fraction, or children would be removed as soon as they are made)",
                      bunched_fraction, occupied_fraction));
  }
};

/// What one adaptive refinement pass did.
struct AdaptiveRefinementCounts {
  std::size_t created{0};         ///< refined particles created (a coarser particle's pattern entered a finer box)
  std::size_t removed{0};         ///< refined particles removed (they left their box)
  std::size_t activated{0};       ///< passive particles that became active
  std::size_t deactivated{0};     ///< active particles that became passive
  std::size_t uninterpolated{0};  ///< passive particles without an active neighbour of another level (kept as is)
  /// Largest relative mass change of the mass account: the active mass the statuses changed over the active mass of
  /// the particles near the box edges that took it back (0 without conserve_mass).
  double mass_correction{0};
  /// Largest velocity shift of the momentum account, |dP| / M_edge, m/s (0 without conserve_momentum).
  double momentum_correction{0};
  /// Largest pending mass of a relaxed mass account (mass_account_relaxation > 0) over the active mass, after the
  /// pass (0 without it).
  double pending_mass{0};
  /// Active mass the status changes of each level k (index k, up to RefinementBox::max_level) brought in (+, the
  /// particles that became active with their masses) and took out (-, those that became passive), before the
  /// accounts; the totals sum over the passes. status_nominal_mass: the same with each particle counted at its
  /// nominal mass rho0 (dp / 2^k)^Dim, so the difference of the two is the masses' deviation and the nominal sum the
  /// count's (diagnostics of where the active mass moves, docs/variable-resolution.md, session 30).
  std::array<double, 9> status_mass{};
  std::array<double, 9> status_nominal_mass{};
  /// Paired exchange (AdaptiveRefinementParameters::paired_exchange): coarse particles that exchanged mass and momentum
  /// with their paired fine particles in the pass, and the groups left to the accounts (fine mass outside [1/2, 2] of
  /// the coarse one's).
  std::size_t exchanged{0};
  std::size_t exchange_skipped{0};
  /// Largest mass of a passive fluid particle over its level's nominal mass, after the pass (with
  /// passive_mass_from_volume at most passive_mass_bound; 0 without passive particles).
  double passive_mass_highest{0};
};

/// Adaptive particle refinement with overlapping resolutions (see the header comment). A ParticleModel: it adds no
/// forces and does not limit the time step; its advance() runs after each step. Use it with
/// FluidParameters::same_resolution_pairs = true.
template <class System>
class AdaptiveRefinement {
 public:
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;
  using Box = RefinementBox<Dim, T>;

  /// Throws InputError for invalid parameters, a box outside the domain or of an invalid level, boxes of different
  /// levels that overlap without nesting, and a transition zone narrower than the kernel support of the finest
  /// level's particles (their active neighbours at a box edge would lack part of their support).
  AdaptiveRefinement(const Domain<Dim, T>& domain, std::vector<Box> boxes,
                     const AdaptiveRefinementParameters<T>& params)
      : boxes_(std::move(boxes)), params_(params), shifter_(shifting_parameters(params)) {
    params_.validate();
    RefinementParameters<T> check;  // the box checks are those of the splitting scheme
    check.base_spacing = params_.base_spacing;
    check.smoothing_ratio = params_.smoothing_ratio;
    ParticleRefinement<System> boxes_checked(domain, boxes_, check);
    const int finest = max_box_level();
    if (finest == 0) return;
    const T support = finest_support();
    if (params_.transition_width < support)
      throw InputError(fmt::format(
          "AdaptiveRefinementParameters::transition_width = {} m is too narrow: valid range is >= {} m (the kernel "
          "support of the level-{} particles)",
          params_.transition_width, support, finest));
  }

  const std::vector<Box>& boxes() const noexcept { return boxes_; }
  const AdaptiveRefinementParameters<T>& parameters() const noexcept { return params_; }

  /// Highest level of the boxes containing x (0 outside every box).
  int level_inside(const Vector& x) const { return highest_level(x, T(0)); }
  /// Highest level of the boxes within transition_width of x.
  int level_near(const Vector& x) const { return highest_level(x, params_.transition_width); }
  /// A fluid particle's level from its smoothing length h: round(log2(smoothing_ratio dp / h)).
  int level_of(T smoothing_length) const {
    return static_cast<int>(std::lround(std::log2(params_.smoothing_ratio * params_.base_spacing / smoothing_length)));
  }

  // ---- ParticleModel ----
  void compute_rates(System&, T) {}
  T stable_time_step(const System&) const { return std::numeric_limits<T>::infinity(); }
  /// One pass after the step [t, t + dt]; rebuilds the neighbour index if the particle set changed.
  void advance(System& system, T t, T dt) {
    if (params_.boxes_follow_flow) move_boxes(system, dt);
    if (params_.shifting.enabled) shifter_.shift(system, dt);
    last_ = pass(system, -1, t + dt);
    accumulate(last_);
  }

  /// Creates the refined particles in every box and its transition zone (recursively for nested levels), sets the
  /// passive flags and rebuilds the neighbour index. Call once on the initial particles, before the first step. Throws
  /// InputError where an active refined particle lies within its kernel support of a wall that has no wall particles of
  /// its own spacing there.
  void populate(System& system) {
    lattice_number_density_ = lattice_number_density(system.kernel());
    system.update_neighbors(T(0));
    for (int level = 0; level < Box::max_level; ++level) {
      const AdaptiveRefinementCounts c = pass(system, level, T(0));
      accumulate(c);
      if (c.created == 0 && level >= max_box_level()) break;
    }
    if (params_.paired_statuses) {  // the first pass's statuses already, so that it hands nothing over
      auto& p = system.particles();
      level_.assign(p.size(), 0);
      leaving_.assign(p.size(), 0);
      status_.assign(p.passive.begin(), p.passive.end());
      for (std::size_t a = 0; a < p.size(); ++a)
        if (p.kind[a] == Kind::fluid) level_[a] = level_of_particle(p, a);
      pair_statuses(system);
      for (std::size_t a = 0; a < p.size(); ++a)
        if (p.kind[a] == Kind::fluid) p.passive[a] = status_[a];
    }
    check_walls(system);
  }

  /// How far the boxes have moved along x with the water (boxes_follow_flow), m.
  T box_displacement() const noexcept { return box_displacement_; }

  /// The mass a relaxed mass account has still to hand back (mass_account_relaxation > 0), kg (per unit depth in 2D).
  T pending_mass() const noexcept { return pending_mass_; }

  // ---- checkpoint (io/checkpoint.hpp): the relaxed mass account's pending mass and the time of the last pass ----
  template <class Writer>
  void save_checkpoint(Writer& w) const {
    w.write("adaptive_refinement.pending_mass", pending_mass_);
    w.write("adaptive_refinement.last_pass_time", last_pass_time_);
    w.write("adaptive_refinement.box_displacement", box_displacement_);
  }
  template <class Reader>
  void load_checkpoint(Reader& r) {
    r.read("adaptive_refinement.pending_mass", pending_mass_);
    r.read("adaptive_refinement.last_pass_time", last_pass_time_);
    T displacement = T(0);
    r.read("adaptive_refinement.box_displacement", displacement);
    shift_boxes(displacement - box_displacement_);  // the boxes as they were when the checkpoint was written
    box_displacement_ = displacement;
  }

  const AdaptiveRefinementCounts& last_counts() const noexcept { return last_; }
  /// What the last particle shift did (AdaptiveRefinementParameters::shifting).
  const ParticleShiftingCounts& last_shift_counts() const noexcept { return shifter_.last_counts(); }
  const AdaptiveRefinementCounts& total_counts() const noexcept { return total_; }

  /// Mass and momentum of the active fluid particles (the fluid the equations integrate).
  std::pair<T, Vector> active_mass_momentum(const System& system) const {
    const auto& p = system.particles();
    T m = T(0);
    Vector q = Vector::Zero();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::fluid || p.passive[i]) continue;
      m += p.mass[i];
      q += p.mass[i] * p.velocity[i];
    }
    return {m, q};
  }

 private:
  static ParticleShiftingParameters<T> shifting_parameters(const AdaptiveRefinementParameters<T>& params) {
    params.validate();  // first: its messages name the refinement parameters
    ParticleShiftingParameters<T> s = params.shifting;
    if (params.shift_refined_only) s.max_smoothing_length = T(0.75) * params.smoothing_ratio * params.base_spacing;
    return s;
  }

  // Relative spread of smoothing lengths within one level (levels are a factor 2 apart): the neighbour loops that
  // look at one level only ask the search for that size band.
  static constexpr T level_tolerance = T(0.25);

  // sum_b W(|x_a - x_b|, h) s^Dim over a square lattice of spacing s with h = smoothing_ratio s (1 to the kernel's
  // lattice error): the number density of a full, ordered support in units of 1 / s^Dim.
  template <class Kernel>
  T lattice_number_density(const Kernel& kernel) const {
    const T h = params_.smoothing_ratio;  // s = 1
    const int reach = static_cast<int>(std::ceil(T(Kernel::support) * h));
    T sum = T(0);
    int index[3] = {-reach, -reach, -reach};
    const int count = static_cast<int>(std::pow(2 * reach + 1, Dim));
    for (int c = 0; c < count; ++c) {
      int rest = c;
      T r2 = T(0);
      for (int d = 0; d < Dim; ++d) {
        index[d] = rest % (2 * reach + 1) - reach;
        rest /= 2 * reach + 1;
        r2 += T(index[d] * index[d]);
      }
      sum += kernel.value(std::sqrt(r2), h);
    }
    return sum;
  }

  // Kernel support of the finest level's particles, m.
  T finest_support() const {
    return T(System::kernel_type::support) * params_.smoothing_ratio * params_.base_spacing /
           std::pow(T(2), T(max_box_level()));
  }

  void shift_boxes(T shift) {
    for (Box& b : boxes_) {
      b.lower[0] += shift;
      b.upper[0] += shift;
    }
  }

  // boxes_follow_flow: every box moves along x by dt times the mass-weighted mean x-velocity of the active particles
  // of the finest level inside the boxes of that level (one shift for all, so nested boxes stay nested), the total
  // held within +-(transition_width - finest_support()).
  void move_boxes(const System& system, T dt) {
    const auto& p = system.particles();
    const int finest = max_box_level();
    T mass = T(0), momentum = T(0);
    for (std::size_t a = 0; a < p.size(); ++a) {
      if (p.kind[a] != Kind::fluid || p.passive[a] || level_of_particle(p, a) != finest) continue;
      if (level_inside(p.position[a]) != finest) continue;
      mass += p.mass[a];
      momentum += p.mass[a] * p.velocity[a][0];
    }
    if (!(mass > T(0))) return;
    const T limit = std::max(T(0), params_.transition_width - finest_support());
    const T displacement = std::clamp(box_displacement_ + dt * momentum / mass, -limit, limit);
    shift_boxes(displacement - box_displacement_);
    box_displacement_ = displacement;
  }

  int max_box_level() const {
    int level = 0;
    for (const Box& b : boxes_) level = std::max(level, b.level);
    return level;
  }

  // Highest level of the boxes containing x when their faces move out by margin (in if negative), wall faces kept.
  int highest_level(const Vector& x, T margin) const {
    int level = 0;
    for (const Box& b : boxes_)
      if (b.level > level && b.contains(x, margin)) level = b.level;
    return level;
  }

  // The particle's own offset of the box edges (edge_dither), m: uniform in [-1/2, 1/2) edge_dither base spacings,
  // from the splitmix64 finaliser of its id (Steele, Lea & Flood 2014).
  T dither_offset(std::uint32_t id) const {
    if (!(params_.edge_dither > T(0))) return T(0);
    std::uint64_t z = std::uint64_t(id) + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    const T unit = T(z >> 11) * T(1.0 / 9007199254740992.0);  // [0, 1), 53 bits
    return (unit - T(0.5)) * params_.edge_dither * params_.base_spacing;
  }

  void accumulate(const AdaptiveRefinementCounts& c) {
    total_.created += c.created;
    total_.removed += c.removed;
    total_.activated += c.activated;
    total_.deactivated += c.deactivated;
    total_.uninterpolated += c.uninterpolated;
    total_.exchanged += c.exchanged;
    total_.exchange_skipped += c.exchange_skipped;
    total_.mass_correction = std::max(total_.mass_correction, c.mass_correction);
    total_.momentum_correction = std::max(total_.momentum_correction, c.momentum_correction);
    total_.pending_mass = std::max(total_.pending_mass, c.pending_mass);
    total_.passive_mass_highest = std::max(total_.passive_mass_highest, c.passive_mass_highest);
    for (std::size_t k = 0; k < c.status_mass.size(); ++k) {
      total_.status_mass[k] += c.status_mass[k];
      total_.status_nominal_mass[k] += c.status_nominal_mass[k];
    }
  }

  // Whether x lies within transition_width of a box edge (on either side): the band where statuses change.
  bool near_box_edge(const Vector& x) const {
    return highest_level(x, params_.transition_width) != highest_level(x, -params_.transition_width);
  }

  // The mass and momentum accounts: the active mass (with conserve_mass) and momentum (with conserve_momentum) a pass
  // changed, the particles that became passive or active carrying them, go back to the active particles near the
  // box edges (all active fluid with account_over_all_fluid): each mass scaled by 1 + dM / M_edge, then one velocity
  // shift dP / M_edge for the momentum still missing (the changes' and the rescaling's). With mass_account_relaxation,
  // dM is the share of the pending mass handed back in this pass.
  void balance(System& system, const std::pair<T, Vector>& before, T time, AdaptiveRefinementCounts& counts) {
    auto& p = system.particles();
    const auto [mass, momentum] = active_mass_momentum(system);
    T mass_change = params_.conserve_mass ? before.first - mass : T(0);
    if (params_.conserve_mass && params_.mass_account_relaxation > T(0)) {
      // relaxed: this pass's change joins the pending mass, of which the share 1 - exp(-dt / tau) is handed back
      pending_mass_ += mass_change;
      const T dt = std::max(time - last_pass_time_, T(0));
      mass_change = pending_mass_ * -std::expm1(-dt / params_.mass_account_relaxation);
      pending_mass_ -= mass_change;
      counts.pending_mass = std::abs(static_cast<double>(pending_mass_ / mass));
    }
    Vector momentum_change = before.second - momentum;
    if (mass_change != T(0) && params_.activated_mass_bound > T(0))
      mass_change = account_to_activated(system, mass_change, momentum_change);
    if (mass_change == T(0) && (!params_.conserve_momentum || momentum_change.squaredNorm() == T(0))) return;
    edge_.clear();
    T band = T(0);
    for (std::size_t a = 0; a < p.size(); ++a) {
      if (p.kind[a] != Kind::fluid || p.passive[a]) continue;
      if (!params_.account_over_all_fluid && !near_box_edge(p.position[a])) continue;
      edge_.push_back(a);
      band += p.mass[a];
    }
    if (!(band > T(0))) {
      if (params_.mass_account_relaxation > T(0)) pending_mass_ += mass_change;  // kept for a later pass
      return;
    }
    if (mass_change != T(0)) {
      const T correction = mass_change / band;
      for (std::size_t a : edge_) {
        momentum_change -= correction * p.mass[a] * p.velocity[a];  // the rescaling's momentum
        p.mass[a] *= T(1) + correction;
      }
      band += mass_change;
      counts.mass_correction = std::abs(static_cast<double>(correction));
    }
    if (!params_.conserve_momentum || momentum_change.squaredNorm() == T(0)) return;
    const Vector shift = momentum_change / band;
    for (std::size_t a : edge_) p.velocity[a] += shift;
    counts.momentum_correction = static_cast<double>(shift.norm());
  }

  // The activated account (AdaptiveRefinementParameters::activated_mass_bound = r): the mass change dM goes to the
  // particles that became active in this pass (activated_id_), shares m_a dM / M_activated, each new mass held within
  // [min(m_a, (1 - r) m_nom), max(m_a, (1 + r) m_nom)] (m_nom the nominal mass of its level); the momentum the
  // rescaling carries is taken off momentum_change. Returns the part of dM that did not fit.
  T account_to_activated(System& system, T mass_change, Vector& momentum_change) {
    auto& p = system.particles();
    if (activated_id_.empty()) return mass_change;
    std::sort(activated_id_.begin(), activated_id_.end());
    activated_.clear();
    T activated_mass = T(0);
    for (std::size_t a = 0; a < p.size(); ++a) {
      if (p.kind[a] != Kind::fluid || p.passive[a]) continue;
      if (!std::binary_search(activated_id_.begin(), activated_id_.end(), p.id[a])) continue;
      activated_.push_back(a);
      activated_mass += p.mass[a];
    }
    if (!(activated_mass > T(0))) return mass_change;
    const T share = mass_change / activated_mass, rho0 = system.eos().reference_density();
    T handed = T(0);
    for (std::size_t a : activated_) {
      const T nominal = nominal_mass(level_of_particle(p, a), rho0);
      const T lowest = std::min(p.mass[a], (T(1) - params_.activated_mass_bound) * nominal);
      const T highest = std::max(p.mass[a], (T(1) + params_.activated_mass_bound) * nominal);
      const T change = std::clamp(p.mass[a] * (T(1) + share), lowest, highest) - p.mass[a];
      momentum_change -= change * p.velocity[a];  // the rescaling's momentum
      p.mass[a] += change;
      handed += change;
    }
    return mass_change - handed;
  }

  // Paired statuses (AdaptiveRefinementParameters::paired_statuses): level by level from the coarsest refined one,
  // each particle of level k >= 1 near a box edge and not inside a finer box takes the opposite of the status of the
  // nearest particle of level k - 1 (whose status is final by then). Reads status_ of level k - 1, writes level k.
  void pair_statuses(System& system) {
    const auto& p = system.particles();
    const int top = max_box_level();
    partner_.assign(p.size(), p.size());
    for (int k = 1; k <= top; ++k) {
      parallel_for(p.size(), [&](std::size_t a) {
        if (p.kind[a] != Kind::fluid || leaving_[a] || level_[a] != k || !near_box_edge(p.position[a])) return;
        if (highest_level(p.position[a], dither_offset(p.id[a])) > k) return;
        T nearest = std::numeric_limits<T>::infinity();
        std::size_t coarse = p.size();
        system.for_each_neighbor_of_size(a, T(2) * p.smoothing_length[a], level_tolerance,
                                         [&](std::size_t b, const Vector&, T r, T) {
                                           if (p.kind[b] == Kind::fluid && !leaving_[b] && level_[b] == k - 1 &&
                                               (r < nearest || (r == nearest && b < coarse))) {
                                             nearest = r;
                                             coarse = b;
                                           }
                                         });
        if (coarse < p.size()) status_[a] = status_[coarse] ? 0 : 1;
        partner_[a] = coarse;
      });
    }
  }

  // Paired exchange (AdaptiveRefinementParameters::paired_exchange), before the new statuses are applied: each coarse
  // particle c whose status changes and the particles paired with it (partner_) whose status changes the other way
  // form a group. c becoming active takes the group's fine mass and mean velocity; c becoming passive scales its
  // fine particles to its mass and shifts them to its velocity. Mass and momentum of the active fluid then do not
  // change with the group's statuses (to round-off). Groups with a fine mass outside [1/2, 2] m_c are left as they are.
  void exchange_paired(System& system, AdaptiveRefinementCounts& counts) {
    auto& p = system.particles();
    const std::size_t n = p.size();
    auto flips = [&](std::size_t a) { return p.kind[a] == Kind::fluid && !leaving_[a] && status_[a] != p.passive[a]; };
    auto member = [&](std::size_t a) {
      const std::size_t c = partner_[a];
      return c < n && flips(a) && flips(c) && status_[a] != status_[c];
    };
    group_mass_.assign(n, T(0));
    group_momentum_.assign(n, Vector::Zero());
    for (std::size_t a = 0; a < n; ++a) {
      if (!member(a)) continue;
      group_mass_[partner_[a]] += p.mass[a];
      group_momentum_[partner_[a]] += p.mass[a] * p.velocity[a];
    }
    for (std::size_t c = 0; c < n; ++c) {
      const T fine = group_mass_[c];
      if (!(fine > T(0))) continue;
      if (!(fine >= T(0.5) * p.mass[c] && fine <= T(2) * p.mass[c])) {
        group_mass_[c] = T(0);  // left to the accounts
        ++counts.exchange_skipped;
        continue;
      }
      ++counts.exchanged;
      const Vector mean_velocity = group_momentum_[c] / fine;
      if (status_[c] == 0) {  // c becomes active, its fine particles passive
        p.mass[c] = fine;
        p.velocity[c] = mean_velocity;
        group_mass_[c] = T(0);
      } else {  // c becomes passive, its fine particles active: scale factor and velocity shift for them
        group_mass_[c] = p.mass[c] / fine;
        group_momentum_[c] = p.velocity[c] - mean_velocity;
      }
    }
    for (std::size_t a = 0; a < n; ++a) {
      if (!member(a) || !(group_mass_[partner_[a]] > T(0))) continue;
      p.mass[a] *= group_mass_[partner_[a]];
      p.velocity[a] += group_momentum_[partner_[a]];
    }
  }

  // Mass of a particle of level k: rho0 (dp / 2^k)^Dim (the scene's base particles have rho0 dp^Dim).
  T nominal_mass(int k, T rho0) const { return rho0 * cell_volume(spacing_of(k)); }
  // Spacing of level k, dp / 2^k, m, and the volume s^Dim of a lattice cell of spacing s (per-particle hot paths: no
  // std::pow).
  T spacing_of(int k) const { return std::ldexp(params_.base_spacing, -k); }
  static T cell_volume(T s) {
    T v = s;
    for (int d = 1; d < Dim; ++d) v *= s;
    return v;
  }

  // One pass (the header comment): statuses, children in the transition zones where their place is free, the
  // particles that left their transition zone removed, the neighbour index rebuilt, the passive particles
  // interpolated. initial_level >= 0 (populate): the particles of that level make their children, in the boxes too.
  AdaptiveRefinementCounts pass(System& system, int initial_level, T time) {
    auto& p = system.particles();
    const std::size_t n = p.size();
    AdaptiveRefinementCounts counts;
    if (params_.lagrangian_statuses && initial_level < 0) {  // the statuses move with the particles: fits only
      interpolate_passive(system, counts, true);
      last_pass_time_ = time;
      return counts;
    }
    const bool account = initial_level < 0 && (params_.conserve_mass || params_.conserve_momentum);
    const auto before = account ? active_mass_momentum(system) : std::pair{T(0), Vector::Zero().eval()};
    // 1. Statuses; particles finer than every box within transition_width of them are removed.
    const T hysteresis = params_.status_hysteresis * params_.base_spacing;
    level_.assign(n, 0);
    leaving_.assign(n, 0);
    status_.assign(n, 0);
    removals_.clear();
    activated_id_.clear();
    for (std::size_t a = 0; a < n; ++a) {
      if (p.kind[a] != Kind::fluid) continue;
      const int k = level_of_particle(p, a);
      level_[a] = k;
      const T dither = dither_offset(p.id[a]);
      const int inside = highest_level(p.position[a], dither);
      if (k > inside && k > level_near(p.position[a])) {
        removals_.push_back(a);
        leaving_[a] = 1;
        continue;
      }
      std::uint8_t passive = k != inside ? 1 : 0;
      if (hysteresis > T(0) && initial_level < 0) {
        // within `hysteresis` of an edge where k is the active level on one side: keep the status
        const int strict = highest_level(p.position[a], dither - hysteresis),
                  loose = highest_level(p.position[a], dither + hysteresis);
        if (strict != loose && (k == strict || k == loose)) passive = p.passive[a];
      }
      status_[a] = passive;
    }
    if (params_.paired_statuses && initial_level < 0) pair_statuses(system);
    if (params_.paired_exchange && initial_level < 0) exchange_paired(system, counts);
    for (std::size_t a = 0; a < n; ++a) {
      if (p.kind[a] != Kind::fluid || leaving_[a]) continue;
      const int k = level_[a];
      const std::uint8_t passive = status_[a];
      if (passive != p.passive[a]) {
        ++(passive ? counts.deactivated : counts.activated);
        if (!passive && params_.activated_mass_bound > T(0)) activated_id_.push_back(p.id[a]);
        const double sign = passive ? -1.0 : 1.0;
        const auto level = static_cast<std::size_t>(std::clamp(k, 0, Box::max_level));
        counts.status_mass[level] += sign * static_cast<double>(p.mass[a]);
        counts.status_nominal_mass[level] +=
            sign * static_cast<double>(nominal_mass(k, system.eos().reference_density()));
      }
      p.passive[a] = passive;
    }
    // Passive particles of a transition zone that bunched up (closer than bunched_fraction of their spacing to a
    // particle of their level that stays: an active one, or a passive one in a lower slot) are removed too. In slot
    // order, since a removal frees the particles above; the neighbours are first screened in parallel against the
    // removals so far (a superset of the particles that stay), so only the few with a close passive one in a lower
    // slot are looked at again in order.
    constexpr unsigned close_active = 1u, close_lower_passive = 2u;  // flags of close_
    close_.assign(n, 0);
    auto bunched_candidate = [&](std::size_t a) {
      return p.kind[a] == Kind::fluid && !leaving_[a] && p.passive[a] &&
             level_[a] > highest_level(p.position[a], dither_offset(p.id[a]));
    };
    auto close_distance = [&](std::size_t a) { return params_.bunched_fraction * spacing_of(level_[a]); };
    parallel_for(n, [&](std::size_t a) {
      if (!bunched_candidate(a)) return;
      const T close = close_distance(a);
      unsigned found = 0u;
      system.for_each_neighbor_of_size(
          a, p.smoothing_length[a], level_tolerance, [&](std::size_t b, const Vector&, T r, T) {
            if (r < close && p.kind[b] == Kind::fluid && !leaving_[b] && level_[b] == level_[a])
              found |= !p.passive[b] ? close_active : b < a ? close_lower_passive : 0u;
          });
      close_[a] = static_cast<std::uint8_t>(found);
    });
    for (std::size_t a = 0; a < n; ++a) {
      if (close_[a] == 0) continue;
      bool bunched = (close_[a] & close_active) != 0;
      if (!bunched) {  // a close passive one in a lower slot: bunched if it was not removed itself
        const T close = close_distance(a);
        system.for_each_neighbor_of_size(
            a, p.smoothing_length[a], level_tolerance, [&](std::size_t b, const Vector&, T r, T) {
              bunched = bunched || (r < close && p.kind[b] == Kind::fluid && !leaving_[b] && level_[b] == level_[a] &&
                                    p.passive[b] && b < a);
            });
      }
      if (!bunched) continue;
      removals_.push_back(a);
      leaving_[a] = 1;
    }
    // 2. Children of the active particles in a finer box's transition zone, where no particle of their level that
    // stays lies within occupied_fraction of their spacing (the box fills from its transition zone only). Each
    // parent's free child places are found in parallel (bit c of free_children_), then created in slot order.
    const std::size_t children = std::size_t(1) << Dim;
    auto child_position = [&](std::size_t a, std::size_t c, T spacing) {
      Vector x = p.position[a];
      for (int d = 0; d < Dim; ++d)
        x[d] += ((c >> d) & 1u) ? T(2) * params_.split_offset * spacing : -T(2) * params_.split_offset * spacing;
      return x;
    };
    auto child_spacing = [&](int k) { return spacing_of(k + 1); };
    free_children_.assign(n, 0);
    parallel_for(n, [&](std::size_t a) {
      if (p.kind[a] != Kind::fluid || leaving_[a]) return;
      const int k = level_[a];
      if (initial_level >= 0 ? k != initial_level : (p.passive[a] || k >= level_near(p.position[a]))) return;
      const T spacing = child_spacing(k);
      const T gap2 = params_.occupied_fraction * spacing * (params_.occupied_fraction * spacing);
      Vector place[std::size_t(1) << Dim];
      unsigned wanted = 0u;
      for (std::size_t c = 0; c < children; ++c) {
        place[c] = child_position(a, c, spacing);
        if (!system.domain().contains(place[c]) || level_near(place[c]) <= k) continue;
        if (level_inside(place[c]) > k && initial_level < 0) continue;
        wanted |= 1u << c;
      }
      if (wanted == 0u) return;
      unsigned taken = 0u;
      system.for_each_neighbor_of_size(a, T(0.5) * p.smoothing_length[a], level_tolerance,
                                       [&](std::size_t b, const Vector&, T, T) {
                                         if (p.kind[b] != Kind::fluid || leaving_[b] || level_[b] != k + 1) return;
                                         for (std::size_t c = 0; c < children; ++c)
                                           if ((p.position[b] - place[c]).squaredNorm() < gap2) taken |= 1u << c;
                                       });
      free_children_[a] = static_cast<std::uint8_t>(wanted & ~taken);
    });
    created_.clear();
    for (std::size_t a = 0; a < n; ++a) {
      if (free_children_[a] == 0) continue;
      const T spacing = child_spacing(level_[a]);
      for (std::size_t c = 0; c < children; ++c) {
        if (!((free_children_[a] >> c) & 1u)) continue;
        const Vector x = child_position(a, c, spacing);
        created_.push_back({a, x, level_inside(x) > level_[a]});
      }
    }
    const auto first_child_id = p.id_capacity();
    for (const Child& c : created_) {
      const std::size_t a = c.parent;
      const Vector velocity = p.velocity[a];  // copies: add() may reallocate the arrays
      const T rho = p.density[a];
      const std::size_t d = p.add(Kind::fluid, c.position, velocity, rho, p.mass[a] / T(children),
                                  T(0.5) * p.smoothing_length[a], p.body[a]);
      p.pressure[d] = p.pressure[a];
      p.sound_speed[d] = p.sound_speed[a];
      p.passive[d] = c.in_box ? 0 : 1;
    }
    counts.created = created_.size();
    // 3. Removal, highest slot first (swap-with-last keeps the lower slots valid; children were appended beyond n).
    std::sort(removals_.begin(), removals_.end(), std::greater<>());
    for (std::size_t slot : removals_) p.remove(slot);
    counts.removed = removals_.size();
    // 4. Values of the passive particles from the active ones, on the new index.
    if (counts.created + counts.removed > 0 || initial_level >= 0) system.update_neighbors(time);
    if (initial_level >= 0 && params_.linear_interpolation) {
      // populate: the children's density and velocity fitted from their parents' level (not copied from the parent,
      // which would give the children of one parent one density where the field has a gradient).
      // (Slots moved in the removal: the children are told by their ids, the parents by their smoothing lengths.)
      parallel_for(p.size(), [&](std::size_t a) {
        if (p.kind[a] != Kind::fluid || p.id[a] < first_child_id) return;
        fit(system, a, [&](std::size_t b) {
          return p.kind[b] == Kind::fluid && p.id[b] < first_child_id && level_of_particle(p, b) == initial_level;
        });
      });
    }
    const T interval = params_.distant_fit_interval;
    interpolate_passive(system, counts,
                        initial_level >= 0 || !(interval > T(0)) ||
                            std::floor(time / interval) != std::floor(last_pass_time_ / interval));
    if (account) balance(system, before, time, counts);
    last_pass_time_ = time;
    return counts;
  }

  // Sets velocity and density of particle a from the neighbours b with accept(b): the Shepard mean, or with
  // linear_interpolation the linear moving-least-squares fit where its moment matrix is far from singular. Reads the
  // accepted neighbours only and writes a only. False where no neighbour is accepted. each(b, r) sees every
  // neighbour in the same traversal (interpolate_passive's number density).
  template <class Accept>
  bool fit(System& system, std::size_t a, Accept&& accept) {
    return fit(system, a, std::forward<Accept>(accept), [](std::size_t, T) {});
  }
  template <class Accept, class Each>
  bool fit(System& system, std::size_t a, Accept&& accept, Each&& each) {
    using Moment = Eigen::Matrix<T, Dim + 1, Dim + 1>;
    using Column = Eigen::Matrix<T, Dim + 1, 1>;
    using Values = Eigen::Matrix<T, Dim + 1, Dim + 1>;  // columns: density, velocity components
    auto& p = system.particles();
    const auto& kernel = system.kernel();
    // Row 0 of the moment matrix and of the right-hand side are the Shepard sums (sum w, sum w rho, sum w v); only
    // the linear fit needs the other rows.
    const bool linear = params_.linear_interpolation;
    Moment moment = Moment::Zero();
    Values rhs = Values::Zero();
    const T scale = T(1) / p.smoothing_length[a];
    Column lowest = Column::Constant(std::numeric_limits<T>::infinity()), highest = -lowest;
    system.for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T h) {
      each(b, r);
      if (!accept(b)) return;
      const T w = p.mass[b] / p.density[b] * kernel.value(r, h);
      Column f;
      f[0] = p.density[b];
      f.template tail<Dim>() = p.velocity[b];
      if (w > T(0)) {
        lowest = lowest.cwiseMin(f);
        highest = highest.cwiseMax(f);
      }
      if (linear) {
        Column q;
        q[0] = T(1);
        q.template tail<Dim>() = -dx * scale;  // (x_b - x_a) / h_a
        moment.noalias() += w * q * q.transpose();
        rhs.noalias() += w * q * f.transpose();
      } else {
        moment(0, 0) += w;
        rhs.row(0) += w * f.transpose();
      }
    });
    const T weight = moment(0, 0);
    if (!(weight > T(0))) return false;
    p.density[a] = rhs(0, 0) / weight;
    p.velocity[a] = rhs.row(0).template tail<Dim>().transpose() / weight;
    if (linear) {
      const Moment normalised = moment / weight;
      if (normalised.determinant() > T(1e-4)) {
        const Values c = normalised.ldlt().solve(rhs / weight);
        Column value = c.row(0).transpose();
        if (params_.limit_fit) value = value.cwiseMax(lowest).cwiseMin(highest);
        p.density[a] = value[0];
        p.velocity[a] = value.template tail<Dim>();
      }
    }
    p.pressure[a] = system.eos().pressure(p.density[a]);
    p.sound_speed[a] = system.eos().sound_speed(p.density[a]);
    return true;
  }

  // Velocity and density of the passive particles fitted from the active fluid particles within their pair support
  // (fit(); the other levels', and with interpolate_from_own_level their own level's too: the header comment), then
  // their masses. Reads active particles only and writes passive ones only, so the slots can be processed in
  // parallel in place.
  void interpolate_passive(System& system, AdaptiveRefinementCounts& counts, bool fit_distant) {
    auto& p = system.particles();
    const auto& kernel = system.kernel();
    const std::size_t n = p.size();
    const T rho0 = system.eos().reference_density();
    level_.assign(n, 0);
    for (std::size_t a = 0; a < n; ++a)
      if (p.kind[a] == Kind::fluid) level_[a] = level_of_particle(p, a);
    missing_.assign(n, 0);
    // Passive masses: rho_a / sum_b W_ab over the particles of its level (its SPH volume), at most passive_mass_bound
    // nominal masses, so passive particles that bunched up (they follow an interpolated velocity, not their own
    // pressure) do not weigh more in their active neighbours' sums than the fluid they stand for. The number density
    // is summed in the fit's traversal; above a bound of 1 it counts the walls of the particle's resolution as well.
    const bool from_volume = params_.passive_mass_from_volume;
    const T mass_bound = params_.passive_mass_bound;
    const bool count_walls = mass_bound > T(1);
    parallel_for(n, [&](std::size_t a) {
      if (p.kind[a] != Kind::fluid || !p.passive[a]) return;
      if (!fit_distant && distant(p.position[a], level_[a])) return;
      const T h = p.smoothing_length[a];
      T number_density = kernel.value(T(0), h);
      const bool found = fit(
          system, a,
          [&](std::size_t b) {
            return p.kind[b] == Kind::fluid && !p.passive[b] &&
                   (level_[b] != level_[a] || params_.interpolate_from_own_level);
          },
          [&](std::size_t b, T r) {
            if (!from_volume) return;
            const bool own_resolution = p.kind[b] == Kind::fluid
                                            ? level_[b] == level_[a]
                                            : count_walls && p.kind[b] == Kind::wall &&
                                                  std::abs(p.smoothing_length[b] - h) < level_tolerance * h;
            if (own_resolution) number_density += kernel.value(r, h);
          });
      if (!found) missing_[a] = 1;
      if (!from_volume) {
        p.mass[a] = nominal_mass(level_[a], rho0);
        return;
      }
      p.mass[a] = nominal_mass(level_[a], rho0) *
                  std::min(mass_bound, lattice_number_density_ / (number_density * cell_volume(spacing_of(level_[a]))));
    });
    for (std::uint8_t m : missing_) counts.uninterpolated += m;
    for (std::size_t a = 0; a < n; ++a)
      if (p.kind[a] == Kind::fluid && p.passive[a])
        counts.passive_mass_highest =
            std::max(counts.passive_mass_highest, static_cast<double>(p.mass[a] / nominal_mass(level_[a], rho0)));
  }

  // Whether a passive particle of level k at x lies farther than two kernel supports of its level (plus the status
  // hysteresis) from every region where level k is active (AdaptiveRefinementParameters::distant_fit_interval):
  // a finer particle outside the boxes of its level by more than that, or a coarser one deeper than that inside a
  // finer box.
  bool distant(const Vector& x, int k) const {
    const T reach =
        T(2 * System::kernel_type::support) * params_.smoothing_ratio * spacing_of(k) +
        (params_.status_hysteresis + T(0.5) * params_.edge_dither + (params_.paired_statuses ? T(1) : T(0))) *
            params_.base_spacing;
    const int inside = level_inside(x);
    if (k > inside) return highest_level(x, reach) < k;
    if (k < inside) return highest_level(x, -reach) > k;
    return false;
  }

  void check_walls(const System& system) const {
    const auto& p = system.particles();
    const T support = T(System::kernel_type::support);
    for (std::size_t a = 0; a < p.size(); ++a) {
      if (p.kind[a] != Kind::fluid || p.passive[a]) continue;
      const T ha = p.smoothing_length[a];
      T own = std::numeric_limits<T>::infinity(), other = own;
      system.for_each_neighbor(a, [&](std::size_t b, const Vector&, T r, T) {
        if (p.kind[b] != Kind::wall) return;
        T& nearest = std::abs(p.smoothing_length[b] - ha) <= T(1e-3) * ha ? own : other;
        nearest = std::min(nearest, r);
      });
      if (other < support * ha && own > support * ha)
        throw InputError(fmt::format(
            "AdaptiveRefinement: the fluid particle at x = {} m, y = {} m with h = {} m lies {} m from a wall that "
            "has no wall particles of its spacing (valid: wall particles of every refinement level within {} m of "
            "the fluid of that level; add them where a refinement box reaches a wall)",
            p.position[a][0], p.position[a][1], ha, other, support * ha));
    }
  }

  struct Child {
    std::size_t parent;  // slot
    Vector position;
    bool in_box;  // an active child (populate), else a passive one in a transition zone
  };

  template <class Particles>
  int level_of_particle(const Particles& p, std::size_t a) const {
    return level_of(p.smoothing_length[a]);
  }

  std::vector<Box> boxes_;
  AdaptiveRefinementParameters<T> params_;
  ParticleShifting<System> shifter_;
  AdaptiveRefinementCounts last_{}, total_{};
  T pending_mass_{0};                        // the relaxed mass account's mass still to hand back
  std::vector<std::uint32_t> activated_id_;  // ids of the particles a pass made active (activated_mass_bound > 0)
  std::vector<std::size_t> activated_;       // their slots after the pass
  T last_pass_time_{0};                      // time of the last pass (the relaxed mass account's dt, distant fits)
  T box_displacement_{0};                    // how far the boxes moved along x (boxes_follow_flow), m
  std::vector<int> level_;                   // per slot of the pass: level
  std::vector<std::uint8_t> missing_;        // per slot: passive without an active neighbour of another level
  std::vector<std::uint8_t> leaving_;        // per slot of the pass: 1 if removed in it
  std::vector<std::uint8_t> status_;         // per slot of the pass: the new passive flag
  std::vector<std::size_t> partner_;         // per slot (paired statuses): the coarser particle paired with it, or n
  std::vector<T> group_mass_;                // per slot (paired exchange): fine mass of its group, then a scale
  std::vector<Vector> group_momentum_;       // per slot (paired exchange): fine momentum of its group, then a shift
  T lattice_number_density_{1};              // lattice_number_density() of the kernel (populate)
  std::vector<std::size_t> removals_;        // slots to remove
  std::vector<Child> created_;               // children to create
  std::vector<std::uint8_t> close_;          // per slot of the pass: flags of the bunched test
  std::vector<std::uint8_t> free_children_;  // per slot of the pass: bit c set if child c is created
  std::vector<std::size_t> edge_;            // slots of the active particles near a box edge (the accounts)
};

}  // namespace sphfsi
