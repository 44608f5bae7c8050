// sphfsi: real thin blades (seagrass) standing in a 2D flume: each blade one elastic rod (solid/elastic_rod.hpp)
// with its real thickness, density and bending stiffness, clamped in the bed and coupled to the fluid by the
// two-faced repulsive force (coupling/repulsive_force.hpp, the reference paper's eqs 17-23) or, as porous blades,
// by their Morison drag (coupling/blade_drag.hpp). Used by
// examples/posidonia_flume (--blade rod) and examples/meadow_decay.
//
// The 2D equivalent of a meadow. A 3D meadow of N blades per m^2, each of width b and length l, presents the
// frontal area a = N b l per unit bed area (the quantity the wave-decay formula of Dalrymple et al. 1984 and the
// drag per unit bed area depend on: F = (1/2) rho C_D a |u| u per unit volume of canopy, through a = N b). In 2D a
// blade is full width (one blade per unit depth), so its frontal area per unit bed area is l / dx_b for blades
// dx_b apart: the same a needs
//     dx_b = 1 / (N b).
// The blade keeps its real bending stiffness and mass PER UNIT WIDTH, E t^3 / 12 and rho t, so its deflection under
// a given drag per unit width (and its Cauchy number rho C_D U^2 l^3 / (E t^3 / 12)) is that of the real blade. A
// blade given by its flexural rigidity EI (N m^2) and width b has E = 12 EI / (b t^3). The rod uses E, not the
// plane-strain E / (1 - nu^2): a seagrass blade is narrow (b / l ~ 0.02-0.1) and bends as a beam, not as a plate.
// What the 2D equivalent cannot keep: the flow around a 3D blade's edges (a full-width blade lets water past only
// over its tip) and the blade's width relative to its spacing (b N^{-1/2} ~ 0.25 for the Luhar meadow).
//
// Added inertia. A real blade is hundreds of times lighter than the water it moves (2D added mass of a blade of
// length l moving normal to itself: rho_w pi l^2 / 4 per unit width, against rho t l), and its nodes are
// 50-300 times lighter than the fluid particles that push them; the explicit coupling (fluid force held over the
// fluid step while the rod sub-cycles) is then unstable: the bare blade collapses within 0.03 s in still water
// (docs/posidonia.md). The rods therefore carry an added inertia m_a = c rho_w dp per unit length and width
// (added_mass_ratio c, default 1), a fraction 4 c dp / (pi l) of the blade's physical added mass that vanishes
// as dp -> 0: the real blade is the limit of fine resolution; forces (elastic, buoyancy, fluid) are unchanged.
//
// Repulsion strength. The paper's k = 0.01 (eq. 19) makes each fluid particle next to the blade push it with
// about 7 g (A = k c0^2 / h at the rest gap dp / 2); a wall or a thick solid carries that, but the real blade's
// bending stiffness is 4-5 orders of magnitude below the noise of that push between its two faces, and the blade
// fell over in still water within 0.4 s even with 1000 times its stiffness (docs/posidonia.md). Nothing hydrostatic
// has to be carried by the repulsion here (the fluid on the two faces is one fluid in the SPH sums), only crossing
// must be prevented: the repulsion is set to the weakest that stops a particle approaching at `stopping_speed`
// (the drivers take 3 x the surface orbital velocity), k = (3/16) (u / c0)^2, about 2.5e-4 in the flumes here.
//
// Each blade is its own body: nodes from the bed (z = bed) to z = bed + l, clamped at the base, or over a
// rigid part of height `clamped_height` (the sheath of a seagrass shoot); the bed is a contact plane (a blade that
// folds over rests one gap above it). RodBlades<System> holds one CoupledBody<RepulsiveForce, ElasticRod> per
// blade and is one ParticleModel for the Simulation.
//
// Porous blades (add_drag_blades, RodBlades<System, BladeDrag<T>>): in the 3D meadow the water flows between the
// blades, so a 2D stand-in for a row of them should not block the 2D fluid. With coupling/blade_drag.hpp each node
// exchanges its Morison drag with the fluid around it, the fluid passes through, and the rods carry the physical
// added inertia C_M rho_w pi b / 4 of a plate of width b (no numerical added inertia and no repulsion are needed:
// nothing pushes on the blade but its drag). examples/meadow_decay uses them by default (docs/meadow.md).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/coupling/blade_drag.hpp>
#include <sphfsi/coupling/coupled_body.hpp>
#include <sphfsi/coupling/repulsive_force.hpp>
#include <sphfsi/fluid/thin_structure_guard.hpp>
#include <sphfsi/solid/elastic_rod.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace sphfsi::scenes {

/// Young's modulus of a blade of flexural rigidity EI (N m^2), width b and thickness t (m): E = 12 EI / (b t^3), Pa.
template <Real T>
T youngs_modulus_from_rigidity(T flexural_rigidity, T width, T thickness) {
  require_positive("youngs_modulus_from_rigidity: flexural rigidity EI (N m^2)", flexural_rigidity);
  require_positive("youngs_modulus_from_rigidity: width b (m)", width);
  require_positive("youngs_modulus_from_rigidity: thickness t (m)", thickness);
  return T(12) * flexural_rigidity / (width * thickness * thickness * thickness);
}

/// Spacing of 2D full-width blades with the frontal area per bed area of N blades of width b per m^2:
/// dx_b = 1 / (N b), m.
template <Real T>
T equivalent_blade_spacing(T blades_per_square_metre, T width) {
  require_positive("equivalent_blade_spacing: blade density N (1/m^2)", blades_per_square_metre);
  require_positive("equivalent_blade_spacing: blade width b (m)", width);
  return T(1) / (blades_per_square_metre * width);
}

/// Weakest repulsion strength k (eq. 19, A = k c0^2 / h) that stops a fluid particle approaching a blade at normal
/// speed u: the work of R = A (1 - q) / sqrt(q) from q = 1 to the blade, A 2h int_0^1 (1 - q) q^(-1/2) dq =
/// (4/3) A 2h = (8/3) k c0^2, equals u^2 / 2: k = (3/16) (u / c0)^2.
template <Real T>
T repulsion_strength_to_stop(T speed, T sound_speed) {
  require_positive("repulsion_strength_to_stop: speed u (m/s)", speed);
  require_positive("repulsion_strength_to_stop: sound speed c0 (m/s)", sound_speed);
  return T(3) / T(16) * (speed / sound_speed) * (speed / sound_speed);
}

/// One real blade (defaults: LDPE model blade of Luhar et al. 2017, on its 0.01 m sheath).
template <Real T>
struct ThinBlade {
  T length{T(0.14)};             ///< from the bed to the tip (sheath included), m
  T clamped_height{T(0.01)};     ///< rigid lowest part (sheath), m; 0: clamped at the bed only
  T thickness{T(1e-4)};          ///< t, m
  T density{T(920)};             ///< rho_s, kg/m^3
  T youngs_modulus{T(3e8)};      ///< E, Pa (LDPE: 12 EI / (b t^3) with EI = 7.5e-8 N m^2, b = 3 mm)
  T poisson_ratio{T(0.3)};       ///< nu (the rod uses E; nu only for the material record)
  T node_spacing_ratio{T(0.5)};  ///< rod node spacing / fluid particle spacing

  void validate() const {
    require_positive("ThinBlade::length (m)", length);
    require_in_range("ThinBlade::clamped_height (m)", clamped_height, T(0), T(0.5) * length);
    require_positive("ThinBlade::thickness (t, m)", thickness);
    require_positive("ThinBlade::density (kg/m^3)", density);
    require_positive("ThinBlade::youngs_modulus (E, Pa)", youngs_modulus);
    require_in_open_range("ThinBlade::poisson_ratio", poisson_ratio, T(-1), T(0.5));
    require_in_range("ThinBlade::node_spacing_ratio (ds / dp)", node_spacing_ratio, T(0.1), T(2));
  }
  /// Bending stiffness per unit width E t^3 / 12, N m.
  T bending_stiffness_per_width() const { return youngs_modulus * thickness * thickness * thickness / T(12); }
  /// Mass per unit length and unit width rho t, kg/m^2.
  T mass_per_area() const { return density * thickness; }
  ElasticMaterial<T> material() const { return {density, youngs_modulus, poisson_ratio}; }
  /// Node count for fluid spacing dp: edges of about node_spacing_ratio dp.
  int node_count(T dp) const { return 1 + std::max(2, int(std::lround(length / (node_spacing_ratio * dp)))); }
};

/// How the blades meet the fluid and the bed.
template <Real T>
struct RodBladeCoupling {
  RepulsiveForce<T> coupling{};  ///< eps(z) off and eps(u) off by default (see below); k see stopping_speed
  /// > 0: the repulsion strength k of eq. 19 is set to the weakest that stops a fluid particle approaching the
  /// blade at this speed (m/s), k = (3/16) (u / c0)^2 (see the header comment); 0: coupling.strength is used.
  T stopping_speed{T(0)};
  T ambient_density{T(1000)};  ///< rho_w for the blade's buoyancy (1 - rho_w / rho) g, kg/m^3
  T gravity{T(9.81)};          ///< m/s^2
  T contact_gap_ratio{T(1)};   ///< the bed contact plane's gap over dp (blade_in_current: dp)
  T stretch_limit{T(1.5)};     ///< BlowUpError above this edge stretch
  /// Added inertia of each blade per unit length and width, in units of rho_w dp (kg/m^2): a part of the fluid's
  /// added mass that stabilises the explicit coupling (see the header comment); 0: the blade's own mass only.
  T added_mass_ratio{T(1)};
  /// Passes of the 1/4-1/2-1/4 filter applied to the fluid load along each blade (force conserved): the SPH
  /// fluid resolves its load only over a kernel radius, and load differences between neighbouring nodes excite
  /// the blade's node-scale zigzag, which the real bending stiffness (EI k^4 at k = pi / ds) cannot hold.
  int load_smoothing_passes{2};

  RodBladeCoupling() {
    // a thin blade is pushed from both faces: the depth factor eps(z) of eq. 22 (which balances the hydrostatic
    // load on a wall) would weaken the push near the surface, and eq. 23's velocity factor rectifies a light
    // blade's jitter (docs/thin-blades.md)
    coupling.velocity_factor = false;
    // the normal dashpot locks the blade's normal velocity to the adjacent fluid's (impermeability): without it the
    // blade has almost no restoring force against the noise of the repulsion on its two faces (the fluid is one
    // fluid across it in the SPH sums, and E t^3 / 12 is tiny) and drifts over in still water (docs/posidonia.md)
    coupling.normal_damping = T(0.5);
  }
};

/// How porous blades (a 2D stand-in for a 3D canopy: coupling/blade_drag.hpp) meet the fluid and the bed.
template <Real T>
struct DragBladeCoupling {
  BladeDrag<T> coupling{};  ///< Morison drag on the blade-normal (C_D) and tangential (C_f) relative velocity
  /// Width b of one real blade, m: the rod's added inertia is the physical C_M rho_w pi b / 4 per unit length and
  /// width (a flat plate of width b moving normal to itself; Luhar & Nepf 2016), > 0.
  T blade_width{T(3e-3)};
  T added_mass_coefficient{T(1)};  ///< C_M, [0, 2]
  T ambient_density{T(1000)};      ///< rho_w for the blade's buoyancy and added inertia, kg/m^3
  T gravity{T(9.81)};              ///< m/s^2
  /// The bed contact plane's gap over dp. 0 (the bed itself): the porous blade traps no fluid under it, and a gap g
  /// would hold the lowest g of the blade upright (ElasticRod::set_contact_plane), >= 0.
  T contact_gap_ratio{T(0)};
  T stretch_limit{T(1.5)};       ///< BlowUpError above this edge stretch
  int load_smoothing_passes{0};  ///< passes of RodBlades' load filter (the interpolated drag is smooth: none)
  /// Every node clamped: a rigid canopy, whose wave damping Dalrymple et al.'s (1984) formula gives from C_D alone
  /// (the check of the drag's energy budget in the flume, docs/meadow.md).
  bool rigid{false};

  void validate() const {
    coupling.validate();
    require_positive("DragBladeCoupling::blade_width (b, m)", blade_width);
    require_in_range("DragBladeCoupling::added_mass_coefficient (C_M)", added_mass_coefficient, T(0), T(2));
    require_positive("DragBladeCoupling::ambient_density (kg/m^3)", ambient_density);
    require_non_negative("DragBladeCoupling::gravity (m/s^2)", gravity);
    require_non_negative("DragBladeCoupling::contact_gap_ratio", contact_gap_ratio);
    require_in_range("DragBladeCoupling::stretch_limit", stretch_limit, T(1), T(10));
  }
  /// Added inertia per unit length and width, C_M rho_w pi b / 4, kg/m^2.
  T added_mass_per_area() const {
    return plate_added_mass_per_area(ambient_density, blade_width, added_mass_coefficient);
  }
};

/// The blades of a flume: one coupled elastic rod per blade, one ParticleModel. Coupling: RepulsiveForce (a blade
/// the fluid cannot cross, add_rod_blades) or BladeDrag (a porous stand-in for a 3D canopy, add_drag_blades).
template <class System, class Coupling = RepulsiveForce<typename System::scalar_type>>
class RodBlades {
 public:
  using T = typename System::scalar_type;
  using Vector = Vec<2, T>;
  using Rod = ElasticRod<System>;
  using Blade = CoupledBody<Coupling, Rod>;

  explicit RodBlades(std::vector<Blade> blades, int load_smoothing_passes = 0)
      : blades_(std::move(blades)), passes_(load_smoothing_passes) {
    require_in_range("RodBlades load_smoothing_passes", passes_, 0, 100);
  }

  void compute_rates(System& system, T time) {
    for (auto& b : blades_) {
      b.compute_rates(system, time);
      smooth_load(system.particles(), b.solid().particle_ids());
    }
  }
  T stable_time_step(const System& system) const {
    T dt = std::numeric_limits<T>::infinity();
    for (const auto& b : blades_) dt = std::min(dt, b.stable_time_step(system));
    return dt;
  }
  void advance(System& system, T time, T dt) {
    for (auto& b : blades_) b.advance(system, time, dt);
  }

  /// Every blade's edges (Simulation hides fluid pairs across them).
  void structure_edges(std::vector<StructureEdge>& edges) const {
    for (const auto& b : blades_) b.structure_edges(edges);
  }

  std::size_t size() const noexcept { return blades_.size(); }
  const Rod& rod(std::size_t k) const { return blades_.at(k).solid(); }
  /// The coupled body of blade k (its coupling and rod).
  const Blade& blade(std::size_t k) const { return blades_.at(k); }
  /// Rod sub-steps summed over the blades.
  std::size_t sub_step_total() const {
    std::size_t n = 0;
    for (const auto& b : blades_) n += b.solid().sub_step_total();
    return n;
  }
  /// Largest edge stretch of any blade.
  T max_stretch() const {
    T s = T(1);
    for (const auto& b : blades_) s = std::max(s, b.solid().max_stretch());
    return s;
  }
  /// Lowest tip elevation above `bed` over all blades, m (a blade that fell over has its tip near the bed).
  T lowest_tip(T bed) const {
    T z = std::numeric_limits<T>::infinity();
    for (const auto& b : blades_) z = std::min(z, b.solid().tip_position()[1] - bed);
    return z;
  }
  /// Lowest node elevation of the free (not clamped) nodes above `bed`, m, over all blades.
  T lowest_free_node(T bed, T clamped_height) const {
    T z = std::numeric_limits<T>::infinity();
    for (const auto& b : blades_) {
      const auto& X = b.solid().reference_positions();
      const auto& x = b.solid().positions();
      for (std::size_t k = 0; k < x.size(); ++k)
        if (X[k][1] - bed > clamped_height + T(1e-9)) z = std::min(z, x[k][1] - bed);
    }
    return z;
  }

 private:
  /// The filter f_i <- f_i / 2 + (f_{i-1} + f_{i+1}) / 4 on the node forces m_i a_i (an end keeps the quarter it
  /// would pass outward), passes_ times; written back as force per unit mass. Conserves the total force.
  void smooth_load(ParticleSet<2, T>& p, const std::vector<std::uint32_t>& ids) {
    if (passes_ == 0) return;
    const std::size_t n = ids.size();
    force_.resize(n);
    next_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t s = p.slot_of_id(ids[k]);
      force_[k] = p.mass[s] * p.acceleration[s];
    }
    for (int pass = 0; pass < passes_; ++pass) {
      for (std::size_t k = 0; k < n; ++k) {
        const Vector left = k > 0 ? force_[k - 1] : force_[k], right = k + 1 < n ? force_[k + 1] : force_[k];
        next_[k] = T(0.5) * force_[k] + T(0.25) * (left + right);
      }
      std::swap(force_, next_);
    }
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t s = p.slot_of_id(ids[k]);
      p.acceleration[s] = force_[k] / p.mass[s];
    }
  }

  std::vector<Blade> blades_;
  int passes_{0};
  std::vector<Vector> force_, next_;
};

namespace detail {
/// The rods of blades standing at base_x on the bed z = bed (bodies first_body, first_body + 1, ...; nodes every
/// about node_spacing_ratio dp), clamped over clamped_height (at least the base node and its tangent), with the bed
/// as contact plane one gap above it.
template <class System>
std::vector<ElasticRod<System>> blade_rods(System& system, const std::vector<typename System::scalar_type>& base_x,
                                           typename System::scalar_type bed,
                                           const ThinBlade<typename System::scalar_type>& blade,
                                           typename System::scalar_type dp,
                                           typename System::scalar_type smoothing_length, std::int32_t first_body,
                                           const typename ElasticRod<System>::Parameters& params,
                                           typename System::scalar_type contact_gap, const char* caller) {
  using T = typename System::scalar_type;
  using V = Vec<2, T>;
  using Rod = ElasticRod<System>;
  if (base_x.empty()) throw InputError(fmt::format("{}: no blade positions given (valid: at least one)", caller));
  const int nodes = blade.node_count(dp);
  for (std::size_t k = 0; k < base_x.size(); ++k)
    add_elastic_rod(system, V(base_x[k], bed), V(0, 1), blade.length, nodes, blade.material(),
                    RodSection<T>{.thickness = blade.thickness, .width = T(1)}, smoothing_length,
                    first_body + std::int32_t(k));
  std::vector<Rod> rods;
  rods.reserve(base_x.size());
  const T top_of_clamp = bed + blade.clamped_height + T(1e-6) * dp;
  for (std::size_t k = 0; k < base_x.size(); ++k) {
    Rod rod(system, first_body + std::int32_t(k), blade.material(), params);
    rod.clamp_base();
    if (blade.clamped_height > T(0)) rod.clamp_where([&](const V& x) { return x[1] <= top_of_clamp; });
    rod.set_contact_plane(V(0, bed), V(0, 1), contact_gap);
    rods.push_back(std::move(rod));
  }
  return rods;
}

/// Rod parameters of a full-width 2D blade (section per unit width) with buoyancy and added inertia.
template <class System>
typename ElasticRod<System>::Parameters blade_rod_parameters(const ThinBlade<typename System::scalar_type>& blade,
                                                             typename System::scalar_type gravity,
                                                             typename System::scalar_type ambient_density,
                                                             typename System::scalar_type stretch_limit,
                                                             typename System::scalar_type added_mass_per_area) {
  using T = typename System::scalar_type;
  typename ElasticRod<System>::Parameters params;
  params.section = {.thickness = blade.thickness, .width = T(1)};  // per unit width (full-width 2D blade)
  params.gravity = Vec<2, T>(0, -gravity);
  params.ambient_density = ambient_density;
  params.stretch_limit = stretch_limit;
  params.added_mass_per_area = added_mass_per_area;
  return params;
}
}  // namespace detail

/// Adds one blade per base position x (m, on the bed z = bed) to `system` as solid bodies first_body, first_body
/// + 1, ... (rod nodes every about node_spacing_ratio dp), and returns the coupled rods, clamped over
/// clamped_height (at least the base node and its tangent), with the bed as contact plane. The repulsive coupling:
/// the fluid does not cross the blades.
template <class System>
RodBlades<System> add_rod_blades(System& system, const std::vector<typename System::scalar_type>& base_x,
                                 typename System::scalar_type bed, const ThinBlade<typename System::scalar_type>& blade,
                                 typename System::scalar_type dp, typename System::scalar_type smoothing_length,
                                 std::int32_t first_body, const RodBladeCoupling<typename System::scalar_type>& how) {
  using T = typename System::scalar_type;
  blade.validate();
  require_positive("add_rod_blades: dp (m)", dp);
  require_positive("add_rod_blades: ambient density (kg/m^3)", how.ambient_density);
  require_non_negative("add_rod_blades: gravity (m/s^2)", how.gravity);
  how.coupling.validate();
  require_non_negative("add_rod_blades: stopping_speed (m/s)", how.stopping_speed);
  RepulsiveForce<T> coupling = how.coupling;
  if (how.stopping_speed > T(0)) {
    const T c0 = coupling.sound_speed > T(0) ? coupling.sound_speed : system.eos().reference_sound_speed();
    coupling.strength = repulsion_strength_to_stop(how.stopping_speed, c0);
  }
  require_non_negative("add_rod_blades: added_mass_ratio (m_a / (rho_w dp))", how.added_mass_ratio);
  const auto params = detail::blade_rod_parameters<System>(blade, how.gravity, how.ambient_density, how.stretch_limit,
                                                           how.added_mass_ratio * how.ambient_density * dp);
  auto rods = detail::blade_rods(system, base_x, bed, blade, dp, smoothing_length, first_body, params,
                                 how.contact_gap_ratio * dp, "add_rod_blades");
  std::vector<typename RodBlades<System>::Blade> blades;
  blades.reserve(rods.size());
  for (auto& rod : rods) blades.emplace_back(coupling, std::move(rod));
  return RodBlades<System>(std::move(blades), how.load_smoothing_passes);
}

/// The same blades with the porous Morison-drag coupling (coupling/blade_drag.hpp): the fluid passes through them
/// and each exchanges its drag with it; the rods carry the physical added inertia C_M rho_w pi b / 4.
template <class System>
RodBlades<System, BladeDrag<typename System::scalar_type>> add_drag_blades(
    System& system, const std::vector<typename System::scalar_type>& base_x, typename System::scalar_type bed,
    const ThinBlade<typename System::scalar_type>& blade, typename System::scalar_type dp,
    typename System::scalar_type smoothing_length, std::int32_t first_body,
    const DragBladeCoupling<typename System::scalar_type>& how) {
  using Blades = RodBlades<System, BladeDrag<typename System::scalar_type>>;
  blade.validate();
  require_positive("add_drag_blades: dp (m)", dp);
  how.validate();
  const auto params = detail::blade_rod_parameters<System>(blade, how.gravity, how.ambient_density, how.stretch_limit,
                                                           how.added_mass_per_area());
  auto rods = detail::blade_rods(system, base_x, bed, blade, dp, smoothing_length, first_body, params,
                                 how.contact_gap_ratio * dp, "add_drag_blades");
  std::vector<typename Blades::Blade> blades;
  blades.reserve(rods.size());
  for (auto& rod : rods) {
    if (how.rigid) rod.clamp_where([](const Vec<2, typename System::scalar_type>&) { return true; });
    blades.emplace_back(how.coupling, std::move(rod));
  }
  return Blades(std::move(blades), how.load_smoothing_passes);
}

/// Counts fluid particles that crossed a blade between two calls: a particle within `reach` of a blade's bounding
/// box at both calls whose path (its two positions) met one of the blade's edges (its nodes' two positions), all
/// taken to move linearly in between (ThinStructureGuard::crossing, the guard's own swept test). Water going round
/// the tip never meets an edge. Call it every step: between calls far apart the motion is not linear. In 3D the
/// blades are ribbons (solid/elastic_rod.hpp): the test runs in their x-z plane for the fluid particles that lie within
/// the strip's width at both calls (water going round the strip's side edges is not counted).
template <class System>
class BladeCrossingCounter {
 public:
  using T = typename System::scalar_type;
  using Vector = Vec<2, T>;
  static constexpr int Dim = System::dimension;

  explicit BladeCrossingCounter(T reach) : reach_(reach) { require_positive("BladeCrossingCounter reach (m)", reach); }

  /// Updates the positions from the current state; returns the crossings found since the last call.
  template <class Blades>
  std::size_t update(const System& system, const Blades& blades) {
    const auto& p = system.particles();
    std::size_t crossed = 0;
    if (nodes_.size() != blades.size()) nodes_.assign(blades.size(), {}), near_.assign(blades.size(), {});
    for (std::size_t b = 0; b < blades.size(); ++b) {
      const auto& x = blades.rod(b).positions();
      std::unordered_map<std::uint32_t, Vector> now;
      if (x.empty()) continue;
      Vector lo = x[0], hi = x[0];
      for (const auto& v : x) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      lo.array() -= reach_, hi.array() += reach_;
      std::pair<T, T> strip{T(0), T(0)};
      if constexpr (Dim == 3) strip = blades.rod(b).lateral_extent();
      const auto& before = nodes_[b];
      for (std::size_t f = 0; f < p.size(); ++f) {
        if (p.kind[f] != Kind::fluid) continue;
        if constexpr (Dim == 3) {
          if (p.position[f][1] < strip.first || p.position[f][1] > strip.second) continue;
        }
        const Vector y = bending_plane(p.position[f]);
        if (y[0] < lo[0] || y[0] > hi[0] || y[1] < lo[1] || y[1] > hi[1]) continue;
        now.emplace(p.id[f], y);
        const auto it = near_[b].find(p.id[f]);
        if (it == near_[b].end() || before.size() != x.size()) continue;
        for (std::size_t j = 0; j + 1 < x.size(); ++j)
          if (ThinStructureGuard<T>::crossing(it->second, y, before[j], x[j], before[j + 1], x[j + 1]).time > T(0)) {
            ++crossed;
            break;
          }
      }
      nodes_[b] = x;
      near_[b] = std::move(now);
    }
    total_ += crossed;
    return crossed;
  }
  std::size_t total() const noexcept { return total_; }

 private:
  T reach_;
  std::vector<std::vector<Vector>> nodes_;                       // per blade: node positions at the last call
  std::vector<std::unordered_map<std::uint32_t, Vector>> near_;  // per blade: fluid near it at the last call, by id
  std::size_t total_{0};
};

/// The water beside a point (a blade's tip): the fluid particles within `radius` of `centre` when constructed,
/// followed by id (active ones only: a passive particle stands for water another resolution carries).
/// mean_displacement() is their mean displacement since then, over those not removed since (a refined particle that
/// left its region): a passive blade cannot move further than the water around it.
template <class System>
class FluidTracers {
 public:
  using T = typename System::scalar_type;
  using Vector = Vec<System::dimension, T>;

  FluidTracers(const System& system, const Vector& centre, T radius) {
    require_positive("FluidTracers radius (m)", radius);
    const auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid && !p.passive[i] && (p.position[i] - centre).norm() < radius) {
        ids_.push_back(p.id[i]);
        start_.push_back(p.position[i]);
      }
  }

  std::size_t size() const noexcept { return ids_.size(); }
  /// Mean displacement of the tracers from their positions at construction (zero without tracers), m.
  Vector mean_displacement(const System& system) const {
    const auto& p = system.particles();
    Vector d = Vector::Zero();
    std::size_t n = 0;
    for (std::size_t k = 0; k < ids_.size(); ++k) {
      const auto slot = p.slot_of_id(ids_[k]);
      if (slot == System::Particles::no_slot) continue;  // removed (left a refined region)
      d += p.position[slot] - start_[k];
      ++n;
    }
    return n == 0 ? d : Vector(d / T(n));
  }

 private:
  std::vector<std::uint32_t> ids_;
  std::vector<Vector> start_;
};

}  // namespace sphfsi::scenes
