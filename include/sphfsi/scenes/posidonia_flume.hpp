// sphfsi: the Posidonia flume of the reference paper (Results section, Figure 8): a 2D wave flume of still-water
// depth 0.2 m with a piston paddle, one plant (or a meadow of N plants) clamped in the bed from x = 1.2 m on, and
// gauges at x = 0.6, 1.0, 1.3 and 1.7 m; the damping zone of waves/damping_zone.hpp absorbs the waves beyond.
//
// A plant is a single full-width blade of `blade_rows` particle rows (thickness t_m = blade_rows dp), standing
// from the bed z = 0 to the blade length l = height_ratio h, with `clamp_rows` more rows embedded below the bed:
// the total-Lagrangian solid clamps them by reflection on the bed plane (solid/total_lagrangian.hpp), so the
// blade's displacement vanishes at z = 0. All plants form ONE solid body (their reference neighbourhoods do not
// overlap: spacing - t_m > kernel support), so one coupled model serves any number of plants.
//
// The real blade (Folkard 2005, the paper's Table 3): rho = 910 kg/m^3, E = 4.7e8 Pa, t = 0.1 mm; nu = 0.30
// (from K = 3.92e8 Pa and E; Table 3's shear modulus 1.81e9 Pa is inconsistent with E and K, its "modified"
// value 1.2e6 = 1.81e8 / 150 shows 1.81e8 was meant, which also gives nu = 0.30). It is 1/150 of a 15 mm model
// blade, so the modelled blade's properties must be changed (BladeModel):
//   scaled:     the paper's choice: moduli divided by the thickness ratio t_m / t, density unchanged:
//               E_m = E t / t_m, rho_m = rho (t_m = 15 mm: E_m = 3.13e6 Pa, Table 3 "modified"). This keeps the
//               extensional stiffness E t per unit width and multiplies the bending stiffness E t^3 / 12 by
//               (t_m / t)^2 (150^2 at 15 mm) and the mass per unit length by t_m / t.
//   equivalent: E_m = E (t / t_m)^3, rho_m = rho t / t_m: bending stiffness per unit width and mass per unit
//               length of the real blade. At t_m = 15 mm E_m = 139 Pa and rho_m = 6.1 kg/m^3: the blade is
//               very light, and its Young's modulus is far below the hydrostatic pressure (about 2000 Pa at the
//               bed), so a Poisson ratio of 0.3 would let the water crush the blade; the equivalent blade therefore
//               takes its bulk modulus from `equivalent_bulk_modulus` (near incompressible), which changes
//               neither its bending stiffness (E) nor its mass. With the explicit repulsive-force coupling this
//               blade blows up within the first 0.03 s (too light: added-mass instability; too soft: G below the
//               fluid's pressure noise), measured in docs/posidonia.md.
//   rod:        the real blade itself (t = 0.1 mm, E, rho), one line of rod nodes (solid/elastic_rod.hpp) per plant
//               from the bed to l, clamped at the bed, pushed on both faces by the repulsive force
//               (scenes/meadow.hpp): bending stiffness E t^3 / 12 and mass rho t per unit width exactly (issue 5.4),
//               no fluid left out (the blade is a line between two fluid columns). At H = 0.03 m it falls over
//               after about 7 s (docs/posidonia.md).
//   drag:       the same real rods, porous (coupling/blade_drag.hpp): Posidonia grows in tufts, which a 2D model
//               cannot resolve (the paper's Results); a 2D plant stands for a row of shoots across the flume whose
//               leaves (width `leaf_width`, about 1 cm) cover its width, the water flows between them, and each rod
//               node exchanges the Morison drag (1/2) rho C_D |u_n| u_n per unit frontal area with the fluid. Plants
//               `spacing` apart are a meadow of frontal area a = 1 / spacing per unit bed area (N b = a leaves of
//               width b per m^2: scenes/meadow.hpp). C_D from the plate law for oscillatory flow at the incident
//               wave's Keulegan-Carpenter number over the blade height (Luhar & Nepf 2016), unless given. The rods
//               carry the plate's added inertia C_M rho_w pi b / 4. The default.
// In 2D scaled and equivalent are plane strain: the bending stiffness per unit width is E_m t_m^3 / (12 (1 - nu_m^2));
// the rod bends as a beam with E (a seagrass blade is narrow).
#pragma once

#include <sphfsi/analysis/vegetation_drag.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/fluid/adaptive_refinement.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/scenes/meadow.hpp>
#include <sphfsi/scenes/wave_flume.hpp>
#include <sphfsi/solid/elastic_material.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace sphfsi::scenes {

enum class BladeModel { equivalent, scaled, rod, drag };

/// Fine fluid around the plants only (issue 9 part 4): one level-1 box (spacing dp / 2) of adaptive particle
/// refinement (fluid/adaptive_refinement.hpp) from the bed up to `top`, from `margin` before the first plant to
/// `margin` after the last, its ends on the base lattice's cell edges. The bed under the box and its transition zone is
/// built again at dp / 2 beside the coarse one (each resolution sees only its own walls), and the drag blades' nodes
/// take the fine spacing and smoothing length. Only the porous drag blades (BladeModel::drag) are supported: their
/// coupling acts on the active fluid only (coupling/blade_drag.hpp); the impermeable couplings would see the fluid of
/// both resolutions.
template <Real T>
struct PlantRefinement {
  bool enabled{false};
  T margin{T(0.1)};             ///< box extent beyond the first and the last plant, m
  T top{T(0)};                  ///< box top above the bed, m (0: above the crests, the free surface inside the box)
  T transition_spacings{T(4)};  ///< width of the transition zone around the box / dp, [2, 20]
  T bunched_fraction{T(0.3)};   ///< AdaptiveRefinementParameters::bunched_fraction
  bool shifting{false};         ///< particle shifting of the fine particles (AdaptiveRefinementParameters::shifting)
  T shift_coefficient{T(2)};    ///< A of the shift (fluid/particle_shifting.hpp), (0, 10]
  bool shift_passive{true};     ///< with shifting: the passive fine particles (transition zone) are shifted too
  bool limit_fit{false};        ///< AdaptiveRefinementParameters::limit_fit (the passive fit within its data's range)
  T status_hysteresis{T(0)};    ///< AdaptiveRefinementParameters::status_hysteresis, dp, [0, transition - h/dp]
  T account_relaxation{T(0)};   ///< AdaptiveRefinementParameters::mass_account_relaxation, s, >= 0
  bool momentum_account{true};  ///< AdaptiveRefinementParameters::conserve_momentum
  bool mass_account{true};      ///< AdaptiveRefinementParameters::conserve_mass
  /// AdaptiveRefinementParameters::lagrangian_statuses: the fine patch moves with the water, no status changes
  bool lagrangian{false};
  /// AdaptiveRefinementParameters::boxes_follow_flow: the box moves along x with the fine water in it
  bool follow_flow{false};
  /// AdaptiveRefinementParameters::distant_fit_interval, s: the passive particles far from the box edges fitted at
  /// this interval only (0: at every pass)
  T distant_fit_interval{T(0)};
  /// AdaptiveRefinementParameters::edge_dither, base spacings, [0, 2]: each particle's own offset of the box edges
  T edge_dither{T(0)};
  /// Whether the box's bottom face (on the bed) and, with top = 0, its top face (above the crests) are wall faces
  /// (RefinementBox::wall_faces): no fluid crosses them, so the statuses' dither and hysteresis, the accounts' band and
  /// the distant particles are taken from the vertical faces only. false (the default, as in sessions 14-29): the bed
  /// face counts as an edge, so the accounts' band takes in the bottom transition width of the box. Measured, the
  /// wall faces do not bring the refined run closer to the fine one (docs/variable-resolution.md, session 30).
  bool wall_faces{false};
  /// AdaptiveRefinementParameters::paired_statuses: a fine particle near a box edge takes the opposite status of the
  /// nearest coarse one, so a coarse particle and the fine ones of its cell change status together
  bool paired_statuses{false};
  /// AdaptiveRefinementParameters::paired_exchange: with paired_statuses, a coarse particle and its paired fine ones
  /// exchange mass and momentum as they change status
  bool paired_exchange{false};
  /// AdaptiveRefinementParameters::activated_mass_bound: the mass account hands a pass's change first to the particles
  /// that became active in it, each within this fraction of its nominal mass, [0, 1); 0: off
  T activated_mass_bound{0};
  /// AdaptiveRefinementParameters::account_over_all_fluid: the accounts hand their changes to all active fluid
  bool account_over_all_fluid{false};
  /// AdaptiveRefinementParameters::passive_mass_from_volume: passive masses from their SPH volume (else nominal)
  bool passive_mass_from_volume{true};
  /// AdaptiveRefinementParameters::passive_mass_bound: the largest passive mass in nominal masses, [1, 2]
  T passive_mass_bound{1};
};

/// The Posidonia flume: waves, resolution, plants and blade model (lengths in m).
template <Real T>
struct PosidoniaFlume {
  // waves (the paper gives none: regular waves typical of its flume)
  T depth{T(0.2)};                                        ///< still-water depth h, m
  T wave_height{T(0.03)};                                 ///< target H, m
  T period{T(1.2)};                                       ///< T, s
  T ramp_periods{T(2)};                                   ///< paddle start-up ramp, periods
  T particles_per_depth{T(20)};                           ///< h / dp (20: dp = 10 mm; the paper's dp = 5 mm is 40)
  T sound_speed_factor{T(7)};                             ///< c0 / sqrt(g h)
  T absorber_start{T(2)};                                 ///< entrance of the damping zone, m (beyond the last gauge)
  T damping_wavelengths{T(1)};                            ///< damping zone length, wavelengths
  T damping_rate{T(10)};                                  ///< beta, 1/s
  std::vector<T> gauges{T(0.6), T(1.0), T(1.3), T(1.7)};  ///< gauge positions, m
  // plants
  int plants{1};                       ///< number of plants (0: the empty flume)
  T first_plant_x{T(1.2)};             ///< centre line of the first (upstream) plant, m
  T spacing{T(0.1)};                   ///< distance between neighbouring plants, m
  T height_ratio{T(0.4)};              ///< blade length / depth, [0.1, 0.9] (paper: 0.32 to 0.5)
  BladeModel blade{BladeModel::drag};  ///< drag: the real blade, porous (the equivalent continuum does not run)
  int blade_rows{3};                   ///< particle rows across the blade (>= 3: the normal needs them)
  int clamp_rows{3};                   ///< rows embedded below the bed (the reflection clamp's images)
  // the real blade (Table 3)
  T real_density{T(910)};             ///< kg/m^3
  T real_youngs_modulus{T(4.7e8)};    ///< Pa
  T real_thickness{T(1e-4)};          ///< m
  T poisson_ratio{T(0.3)};            ///< nu from K and E of Table 3 (scaled blade and real blade)
  T equivalent_bulk_modulus{T(1e5)};  ///< least K of the equivalent blade, Pa (50x the bed pressure rho g h)
  T rod_node_spacing{T(0.5)};         ///< rod blade: node spacing / dp
  T rod_added_mass{T(1)};             ///< rod blade: added inertia per length and width / (rho_w dp) (meadow.hpp)
  int rod_load_smoothing{2};          ///< rod blade: passes of the load filter along the blade (meadow.hpp)
  bool rod_velocity_factor{false};    ///< rod blade: eq. 23's velocity factor in the coupling
  T rod_normal_damping{T(0.5)};       ///< rod blade: beta of the coupling's normal dashpot (rate beta c0 / h)
  T rod_repulsion{T(0)};              ///< rod blade: k of eq. 19 (0: to stop 3 x the surface orbital velocity)
  T leaf_width{T(0.01)};              ///< drag blade: width b of one Posidonia leaf, m (added inertia, KC)
  T drag_coefficient{T(0)};           ///< drag blade: C_D (0: the plate law at the incident wave's KC)
  T friction_coefficient{T(0)};       ///< drag blade: C_f of the tangential skin friction
  T added_mass_coefficient{T(1)};     ///< drag blade: C_M of the plate's added inertia C_M rho_w pi b / 4
  /// drag blade: share phi of the flume's width the leaves of one plant cover (1: a full row; one shoot of n leaves
  /// in a flume of width W: n b / W), (0, 1] (coupling/blade_drag.hpp)
  T frontal_fraction{T(1)};
  /// fine fluid around the plants (off by default: the whole flume at dp)
  PlantRefinement<T> refinement{};

  void validate() const {
    require_positive("PosidoniaFlume::depth (m)", depth);
    require_in_range("PosidoniaFlume::particles_per_depth (h/dp)", particles_per_depth, T(4), T(400));
    require_in_range("PosidoniaFlume::plants", plants, 0, 200);
    require_in_range("PosidoniaFlume::height_ratio (blade length / depth)", height_ratio, T(0.1), T(0.9));
    require_in_range("PosidoniaFlume::blade_rows", blade_rows, 3, 20);
    require_in_range("PosidoniaFlume::clamp_rows", clamp_rows, 2, 8);
    require_positive("PosidoniaFlume::real_density (kg/m^3)", real_density);
    require_positive("PosidoniaFlume::real_youngs_modulus (Pa)", real_youngs_modulus);
    require_positive("PosidoniaFlume::real_thickness (m)", real_thickness);
    require_in_open_range("PosidoniaFlume::poisson_ratio", poisson_ratio, T(-1), T(0.5));
    require_positive("PosidoniaFlume::equivalent_bulk_modulus (Pa)", equivalent_bulk_modulus);
    require_positive("PosidoniaFlume::leaf_width (b, m)", leaf_width);
    require_non_negative("PosidoniaFlume::drag_coefficient (C_D; 0: from KC)", drag_coefficient);
    require_non_negative("PosidoniaFlume::friction_coefficient (C_f)", friction_coefficient);
    require_in_range("PosidoniaFlume::added_mass_coefficient (C_M)", added_mass_coefficient, T(0), T(2));
    require_in_range("PosidoniaFlume::frontal_fraction (phi)", frontal_fraction, std::numeric_limits<T>::min(), T(1));
    if (!gauges.empty())
      for (T x : gauges) require_in_range("PosidoniaFlume gauge position (m)", x, T(0), absorber_start);
    if (plants > 0) {
      if (!thin_blade() && blade_length_rows() < clamp_rows)
        throw InputError(
            fmt::format("PosidoniaFlume: the blade has {} rows above the bed (height_ratio {} at h/dp = "
                        "{}), fewer than the {} embedded rows it must mirror: raise height_ratio or h/dp",
                        blade_length_rows(), height_ratio, particles_per_depth, clamp_rows));
      require_in_range("PosidoniaFlume::first_plant_x (m)", first_plant_x, T(4) * dp(), absorber_start);
      const T last = first_plant_x + T(plants - 1) * spacing;
      if (plants > 1 && !thin_blade())
        require_in_range("PosidoniaFlume::spacing (m, plants' reference supports must not overlap)", spacing,
                         blade_thickness() + T(3) * dp(), T(10) * depth);
      if (plants > 1 && thin_blade())
        require_in_range("PosidoniaFlume::spacing (m, at least two fluid columns between thin blades)", spacing,
                         T(2) * dp(), T(10) * depth);
      require_in_range("PosidoniaFlume last plant x (m)", last, first_plant_x, absorber_start);
    }
    if (refinement.enabled) {
      if (blade != BladeModel::drag || plants < 1)
        throw InputError(
            "PosidoniaFlume::refinement needs plants with the porous drag blade (BladeModel::drag): the other "
            "couplings would see the fluid of both resolutions");
      require_in_range("PosidoniaFlume::refinement.transition_spacings (transition width / dp)",
                       refinement.transition_spacings, T(2), T(20));
      // the nodes' kernel support (2 h at dp / 2: 2 dp with the flume's h = 2 dp) and the tips' sway stay in the box
      require_in_range("PosidoniaFlume::refinement.margin (m)", refinement.margin, T(6) * dp(),
                       absorber_start - (first_plant_x + T(plants - 1) * spacing));
      require_in_range("PosidoniaFlume::refinement.margin (m, the box must start downstream of the paddle)",
                       first_plant_x - refinement.margin, (refinement.transition_spacings + T(4)) * dp(),
                       absorber_start);
      if (refinement.top != T(0))
        require_in_range("PosidoniaFlume::refinement.top (m above the bed; 0: above the crests)", refinement.top,
                         blade_length() + T(4) * dp(), depth - T(2) * dp());
    }
  }

  T dp() const { return depth / particles_per_depth; }
  /// The fluid spacing around the plants, where the blades' nodes sample the fluid: dp / 2 with refinement, else dp.
  T plant_dp() const { return refinement.enabled ? T(0.5) * dp() : dp(); }
  /// The refinement box (empty without refinement): see PlantRefinement.
  std::vector<RefinementBox<2, T>> refinement_boxes() const {
    if (!refinement.enabled) return {};
    const auto x = plant_x();
    const T d = dp();
    const T x0 = std::round((x.front() - refinement.margin) / d) * d;
    const T x1 = std::round((x.back() + refinement.margin) / d) * d;
    const T z1 = refinement.top > T(0) ? std::round(refinement.top / d) * d : flume().wall_height();
    RefinementBox<2, T> box{Vec<2, T>(x0, T(0)), Vec<2, T>(x1, z1), 1};
    if (refinement.wall_faces) box.wall_faces = refinement.top > T(0) ? 0b0100u : 0b1100u;  // bed (and top)
    return {box};
  }
  /// The adaptive refinement's parameters for refinement_boxes().
  AdaptiveRefinementParameters<T> adaptive_refinement_parameters() const {
    AdaptiveRefinementParameters<T> a;
    a.base_spacing = dp();
    a.transition_width = refinement.transition_spacings * dp();
    a.smoothing_ratio = flume().smoothing_ratio;
    a.bunched_fraction = refinement.bunched_fraction;
    a.shifting.enabled = refinement.shifting;
    a.shifting.coefficient = refinement.shift_coefficient;
    a.shifting.include_passive = refinement.shift_passive;
    a.limit_fit = refinement.limit_fit;
    a.status_hysteresis = refinement.status_hysteresis;
    a.mass_account_relaxation = refinement.account_relaxation;
    a.conserve_momentum = refinement.momentum_account;
    a.conserve_mass = refinement.mass_account;
    a.lagrangian_statuses = refinement.lagrangian;
    a.boxes_follow_flow = refinement.follow_flow;
    a.distant_fit_interval = refinement.distant_fit_interval;
    a.edge_dither = refinement.edge_dither;
    a.paired_statuses = refinement.paired_statuses;
    a.paired_exchange = refinement.paired_exchange;
    a.activated_mass_bound = refinement.activated_mass_bound;
    a.account_over_all_fluid = refinement.account_over_all_fluid;
    a.passive_mass_from_volume = refinement.passive_mass_from_volume;
    a.passive_mass_bound = refinement.passive_mass_bound;
    return a;
  }
  /// The real blade as a line of rod nodes (rod, drag), not a continuum of particle rows (scaled, equivalent).
  bool thin_blade() const { return blade == BladeModel::rod || blade == BladeModel::drag; }
  /// t_m, m (the rods: the real thickness)
  T blade_thickness() const { return thin_blade() ? real_thickness : T(blade_rows) * dp(); }
  int blade_length_rows() const { return std::max(1, int(std::lround(height_ratio * depth / dp()))); }
  T blade_length() const { return T(blade_length_rows()) * dp(); }  ///< l (rounded to whole rows), m
  /// Centre line of each plant, snapped to the fluid lattice ((i + 1/2) dp) shifted by dp/2 for even row counts;
  /// a rod blade stands on a lattice line i dp, between two fluid columns.
  std::vector<T> plant_x() const {
    std::vector<T> x;
    const T d = dp(), shift = blade_rows % 2 == 0 || thin_blade() ? T(0.5) * d : T(0);
    for (int i = 0; i < plants; ++i) {
      const T want = first_plant_x + T(i) * spacing;
      x.push_back((std::floor((want - shift) / d) + T(0.5)) * d + shift);
    }
    return x;
  }

  /// The real blade's material (plane strain in 2D would need E' = E / (1 - nu^2)).
  ElasticMaterial<T> real_material() const { return {real_density, real_youngs_modulus, poisson_ratio}; }
  /// The modelled blade's material at thickness t_m (see the header comment; the rod: the real material).
  ElasticMaterial<T> blade_material() const {
    if (thin_blade()) return real_material();
    const T ratio = real_thickness / blade_thickness();  // t / t_m
    if (blade == BladeModel::scaled) return {real_density, real_youngs_modulus * ratio, poisson_ratio};
    const T E = real_youngs_modulus * ratio * ratio * ratio;
    // nu from E and K: K = E / (3 (1 - 2 nu))
    // bulk modulus raised to at least equivalent_bulk_modulus: nu from K = E / (3 (1 - 2 nu))
    return {real_density * ratio, E, std::max(poisson_ratio, T(0.5) - E / (T(6) * equivalent_bulk_modulus))};
  }
  /// Bending stiffness per unit width of the model blade in plane strain, E_m t_m^3 / (12 (1 - nu_m^2)), N m; the
  /// rod: E t^3 / 12 (beam bending).
  T model_bending_stiffness() const {
    if (thin_blade()) return rod_blade().bending_stiffness_per_width();
    const auto m = blade_material();
    const T t = blade_thickness();
    return m.plane_strain_modulus() * t * t * t / T(12);
  }
  /// Bending stiffness per unit width of the real blade, E t^3 / 12, N m.
  T real_bending_stiffness() const {
    return real_youngs_modulus * real_thickness * real_thickness * real_thickness / T(12);
  }

  /// Keulegan-Carpenter number of the incident wave over the blade height, U_m T / b, with U_m the linear orbital
  /// velocity amplitude averaged from the bed to the blade length (waves/linear_theory.hpp) and b the leaf width.
  T keulegan_carpenter_number() const {
    const auto w = waves::linear_wave(period, depth);
    return analysis::keulegan_carpenter_number(w.canopy_orbital_velocity(wave_height, blade_length()), period,
                                               leaf_width);
  }
  /// The drag blade's C_D: drag_coefficient if given, else max(10 KC^(-1/3), 1.95) at keulegan_carpenter_number()
  /// (Luhar & Nepf 2016, analysis/vegetation_drag.hpp).
  T blade_drag_coefficient() const {
    return drag_coefficient > T(0) ? drag_coefficient
                                   : analysis::oscillatory_plate_drag_coefficient(keulegan_carpenter_number());
  }

  /// The real blade as a rod of length l (the same whole rows of dp as the continuum blades), clamped at the bed.
  ThinBlade<T> rod_blade() const {
    ThinBlade<T> b;
    b.length = blade_length();
    b.clamped_height = T(0);
    b.thickness = real_thickness;
    b.density = real_density;
    b.youngs_modulus = real_youngs_modulus;
    b.poisson_ratio = poisson_ratio;
    b.node_spacing_ratio = rod_node_spacing;
    return b;
  }

  /// The flume: piston, damping zone from absorber_start over damping_wavelengths, fluid left out of the plants.
  WaveFlumeGeometry<T> flume() const {
    WaveFlumeGeometry<T> g;
    g.wave.paddle = waves::PaddleType::piston;
    g.wave.wave_height = wave_height;
    g.wave.period = period;
    g.wave.depth = depth;
    g.wave.ramp_periods = ramp_periods;
    g.particles_per_depth = particles_per_depth;
    g.sound_speed_factor = sound_speed_factor;
    const T L = g.wavelength();
    g.length_wavelengths = absorber_start / L + damping_wavelengths;
    g.damping_wavelengths = damping_wavelengths;
    g.damping_rate = damping_rate;
    g.absorber = FlumeAbsorber::damping_zone;
    const T half = T(0.5) * blade_thickness(), top = blade_length();
    if (!thin_blade())
      for (T x : plant_x()) g.fluid_exclusions.push_back({Vec<2, T>(x - half, T(0)), Vec<2, T>(x + half, top)});
    return g;
  }
};

/// What build_posidonia_flume made.
template <Real T>
struct PosidoniaLayout {
  WaveFlumeLayout<T> flume;
  std::int32_t plant_body{WaveFlumeLayout<T>::first_free_body};
  std::vector<T> plant_x;                        ///< centre lines, m
  std::vector<std::vector<std::uint32_t>> tips;  ///< ids of each plant's top row
  std::size_t solid_particles{0};                ///< including the embedded rows
};

/// Fills `system` (empty, on wave_flume_domain(scene.flume())) with the flume and the plants (solid body
/// plant_body). The caller creates the solid model and clamps it with clamp_by_reflection(0, +z) on the bed.
/// For the rods (BladeModel::rod, drag) only the flume is built (and plant_x set): add the blades with
/// add_posidonia_rods or add_posidonia_drag_blades.
template <class System>
PosidoniaLayout<typename System::scalar_type> build_posidonia_flume(
    System& system, const PosidoniaFlume<typename System::scalar_type>& scene) {
  using T = typename System::scalar_type;
  using V = Vec<2, T>;
  scene.validate();
  const WaveFlumeGeometry<T> g = scene.flume();
  PosidoniaLayout<T> out;
  out.flume = build_wave_flume(system, g);
  out.plant_x = scene.plant_x();
  const T dp = scene.dp(), half = T(0.5) * scene.blade_thickness(), top = scene.blade_length();
  const Resolution<T> res{dp, g.smoothing_ratio};
  const auto material = scene.blade_material();
  const T mass = material.density * dp * dp;
  if (scene.refinement.enabled) {  // the bed under the box and its transition zone at the fine spacing
    const T margin = scene.refinement.transition_spacings * dp;
    const auto box = scene.refinement_boxes().front();
    add_fine_bed(system, g, box.lower[0] - margin, box.upper[0] + margin, scene.plant_dp());
  }
  if (scene.thin_blade()) return out;
  for (T xc : out.plant_x) {
    std::vector<std::uint32_t> tip;
    // the blade (z in (0, l)) and its embedded image rows (z in (-clamp_rows dp, 0)), one lattice
    for_each_lattice_point<2, T>(V(xc - half, -T(scene.clamp_rows) * dp), V(xc + half, top), dp, [&](const V& x) {
      const std::size_t slot =
          system.particles().add(Kind::solid, x, V::Zero(), material.density, mass, res.h(), out.plant_body);
      if (x[1] > top - dp) tip.push_back(system.particles().id[slot]);
      ++out.solid_particles;
    });
    out.tips.push_back(std::move(tip));
  }
  return out;
}

/// The rod plants of a flume built by build_posidonia_flume (bodies plant_body, plant_body + 1, ...), clamped at
/// the bed; `how` sets the coupling (default: RodBladeCoupling's).
template <class System>
RodBlades<System> add_posidonia_rods(System& system, const PosidoniaFlume<typename System::scalar_type>& scene,
                                     const PosidoniaLayout<typename System::scalar_type>& layout,
                                     RodBladeCoupling<typename System::scalar_type> how = {}) {
  using T = typename System::scalar_type;
  const WaveFlumeGeometry<T> g = scene.flume();
  how.added_mass_ratio = scene.rod_added_mass;
  how.load_smoothing_passes = scene.rod_load_smoothing;
  how.coupling.velocity_factor = scene.rod_velocity_factor;
  how.coupling.normal_damping = scene.rod_normal_damping;
  if (scene.rod_repulsion > T(0)) how.coupling.strength = scene.rod_repulsion;
  else how.stopping_speed = T(3) * waves::Wavemaker<T>(g.wave).wave().surface_orbital_velocity(scene.wave_height);
  if (scene.blade != BladeModel::rod)
    throw InputError("add_posidonia_rods: the scene's blade model is not BladeModel::rod");
  return add_rod_blades(system, layout.plant_x, T(0), scene.rod_blade(), scene.dp(), g.smoothing_ratio * scene.dp(),
                        layout.plant_body, how);
}

/// The porous rod plants (BladeModel::drag) of a flume built by build_posidonia_flume (bodies plant_body, ...),
/// clamped at the bed: each node exchanges its Morison drag with the fluid (coupling/blade_drag.hpp) with C_D =
/// scene.blade_drag_coefficient(), C_f and the leaf's added inertia from the scene; `how` sets the rest.
template <class System>
RodBlades<System, BladeDrag<typename System::scalar_type>> add_posidonia_drag_blades(
    System& system, const PosidoniaFlume<typename System::scalar_type>& scene,
    const PosidoniaLayout<typename System::scalar_type>& layout,
    DragBladeCoupling<typename System::scalar_type> how = {}) {
  using T = typename System::scalar_type;
  if (scene.blade != BladeModel::drag)
    throw InputError("add_posidonia_drag_blades: the scene's blade model is not BladeModel::drag");
  const WaveFlumeGeometry<T> g = scene.flume();
  how.coupling.drag_coefficient = scene.blade_drag_coefficient();
  how.coupling.friction_coefficient = scene.friction_coefficient;
  how.coupling.frontal_fraction = scene.frontal_fraction;
  how.blade_width = scene.leaf_width;
  how.added_mass_coefficient = scene.added_mass_coefficient;
  how.gravity = g.wave.gravity;
  return add_drag_blades(system, layout.plant_x, T(0), scene.rod_blade(), scene.plant_dp(),
                         g.smoothing_ratio * scene.plant_dp(), layout.plant_body, how);
}

}  // namespace sphfsi::scenes
