// sphfsi: a thin elastic blade as one line of nodes: the planar discrete elastic rod (issue 6).
//
// A seagrass blade (Posidonia: t = 0.1 mm, reference paper Table 3) is far thinner than a fluid particle, so it is
// modelled as a geometrically exact planar Kirchhoff rod (unshearable, extensible; the elastica: Audoly & Pomeau
// 2010, Elasticity and Geometry, ch. 3) discretised as the discrete elastic rod of Bergou, Wardetzky, Robinson,
// Audoly & Grinspun (2008, ACM Trans. Graph. 27(3):63, sec. 4: curvature of a vertex from the turning angle between
// its edges over the vertex's Voronoi length) restricted to a plane, where there is no twist and no material frame.
//
// Nodes x_i, i = 0 (base) .. n-1 (tip), in increasing particle id; edges e_j = x_{j+1} - x_j, length l_j, rest
// length L_j; Voronoi lengths D_i = (L_{i-1} + L_i)/2, D_0 = L_0/2, D_{n-1} = L_{n-2}/2. Section of thickness t and
// width b: A = b t, I = b t^3 / 12; E_r = E, or E / (1 - nu^2) for a blade in plane strain (cylindrical bending).
//   node mass            m_i = rho A D_i                                       (lumped, trapezoidal)
//   axial force          N_j = E_r A (l_j / L_j - 1)                           (tension positive), N
//   turning angle        phi_i = atan2(e_{i-1} x e_i, e_{i-1} . e_i),   i = 1 .. n-2
//                        at a clamped end, the angle between the held tangent and the end edge (half cell D_0)
//   bending moment       M_i = E_r I (phi_i - phi0_i) / D_i                    (phi0: rest shape), N m
//   stored energy        U = sum_j E_r A (l_j - L_j)^2 / (2 L_j) + sum_i E_r I (phi_i - phi0_i)^2 / (2 D_i)
// With the edge angle theta_j, d theta_j / d x_{j+1} = -d theta_j / d x_j = e_j^perp / l_j^2 (e^perp = (-e_y, e_x)),
// dU/d theta_j = tau_j = M_j - M_{j+1} (M = 0 at a free end), so the internal forces f = -dU/dx are, per edge,
//   f_j += N_j e_j / l_j + tau_j e_j^perp / l_j^2,   f_{j+1} -= the same,
// and the equation of motion is
//   m_i dv_i/dt = f_i + m_i [(1 - rho_w / rho) g + a_ext,i] - c_d m_i v_i
// (buoyancy of the surrounding fluid of density rho_w; a_ext from the couplings; c_d optional, for static runs);
// with an added inertia m_a per unit area (ElasticRodParameters::added_mass_per_area) the left side is
// (m_i + m_a b D_i) dv_i/dt, the forces unchanged (the step bound above stays valid: the frequencies only drop).
// Every edge force is an equal and opposite pair and sum_j tau_j telescopes to M_0 - M_{n-1} = 0 for free ends: a
// free rod conserves linear and angular momentum, and U is invariant under rigid motions (no internal force).
// The clamp half cell D_0 = L_0/2 makes the static tip deflection under a tip load the trapezoidal rule of
// int (L-s)^2 ds: relative error +1/(2 n_e^2) with n_e = n-1 edges (docs/thin-blades.md).
//
// Time stepping: velocity Verlet (kick-drift-kick, symplectic) sub-cycled inside the outer (fluid) step with the
// external acceleration held constant. Stability of Verlet needs omega_max dt < 2; Gershgorin bounds on the
// linearised chain give omega_axial <= 2 c / L_min (c = sqrt(E_r / rho)) and omega_bend <= 4 sqrt(E_r I / (rho A))
// / L_min^2 (4th-difference stencil, row sum 16), and by Weyl's inequality omega_max^2 <= omega_axial^2 +
// omega_bend^2. The rod's step is dt = cfl 2 / omega_max (and <= cfl 2 / c_d with damping).
//
// The nodes are particles of Kind::solid in the shared ParticleSet: the neighbour search and the couplings see
// them. In 2D the set holds masses per unit depth (kg/m): a node's particle mass is rho t D_i (its mass over the
// width b), so the force per unit mass that a 2D coupling writes applies unchanged to the real blade. After every
// step each node carries p.normal, the unit normal of the blade (left of the base-to-tip tangent); the other face
// has -p.normal.
//
// In 3D the same rod is a ribbon (add_elastic_ribbon): a strip of width b along the lateral axis y whose bending stays
// in the x-z plane (the plane of the current and the vertical; by symmetry a strip towed or held normal to a current
// bends only in that plane; Luhar & Nepf 2011 model it so). Each node is a row of w particles across the width at the
// node's (x, z), each with mass rho t D_i b / w; the rod's node sees the mass-weighted mean of their accelerations
// (the total fluid force on the row over the row's mass), and every particle of the row moves with the node.
// Forces along y on the row are taken by the strip's in-plane stiffness (its bending about the thin axis is b^2 / t^2
// times stiffer) and passed to its clamp.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_set.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/solid/body.hpp>
#include <sphfsi/solid/elastic_material.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace sphfsi {

/// Rectangular cross-section of a blade.
template <Real T>
struct RodSection {
  T thickness{T(1e-4)};  ///< t, m
  T width{T(8e-3)};      ///< b, m

  void validate() const {
    require_positive("RodSection::thickness (t, m)", thickness);
    require_positive("RodSection::width (b, m)", width);
  }
  T area() const { return width * thickness; }                                           ///< A = b t, m^2
  T second_moment() const { return width * thickness * thickness * thickness / T(12); }  ///< I = b t^3/12, m^4
};

/// Parameters of an ElasticRod (designated initialisers; validated by the model's constructor).
template <Real T>
struct ElasticRodParameters {
  RodSection<T> section{};                       ///< thickness and width
  Vec<2, T> gravity = standard_gravity<2, T>();  ///< m/s^2
  T ambient_density{T(0)};                       ///< rho_w of the surrounding fluid (buoyancy), kg/m^3, >= 0
  bool plane_strain{false};                      ///< E / (1 - nu^2) instead of E (a blade much wider than thick)
  T cfl{T(0.8)};                                 ///< dt = cfl 2 / omega_max (Verlet limit at 1), (0, 1]
  bool sub_cycle{true};                          ///< true: advance() sub-cycles, no limit on the outer step
  T damping{T(0)};                               ///< c_d, mass-proportional damping, 1/s, >= 0 (0: dynamics)
  /// Whether the damping acts on the velocity relative to the held nodes' motion (set_clamp_motion) instead of the
  /// absolute velocity: a towed blade is then damped relative to its carriage, so a steady tow adds no damping force
  /// and the static posture is the undamped one; only the motion about it (flutter) is damped.
  bool damping_relative_to_clamp{false};
  T stretch_limit{T(0)};  ///< BlowUpError above this edge stretch (0: off), else > 1
  /// Extra inertia per unit length and width m_a (kg/m^2, like rho t), e.g. part of the surrounding fluid's added
  /// mass: node i moves with m_i + m_a b D_i under the forces on m_i (elastic, body force, couplings). It
  /// stabilises the explicit coupling of a blade far lighter than the fluid particles it displaces
  /// (scenes/meadow.hpp). >= 0; 0: the blade's own mass only.
  T added_mass_per_area{T(0)};

  void validate() const {
    section.validate();
    for (int d = 0; d < 2; ++d) require_finite("ElasticRodParameters::gravity (m/s^2)", gravity[d]);
    require_non_negative("ElasticRodParameters::ambient_density (rho_w, kg/m^3)", ambient_density);
    require_in_range("ElasticRodParameters::cfl", cfl, T(1e-6), T(1));
    require_non_negative("ElasticRodParameters::damping (c_d, 1/s)", damping);
    require_non_negative("ElasticRodParameters::added_mass_per_area (m_a, kg/m^2)", added_mass_per_area);
    if (stretch_limit != T(0))
      require_in_open_range("ElasticRodParameters::stretch_limit", stretch_limit, T(1), std::numeric_limits<T>::max());
  }
};

namespace detail {
/// A straight blade's nodes (2D) or rows (3D, `width_particles` across the width): see add_elastic_rod and
/// add_elastic_ribbon. `who` names the caller in the error messages.
template <class System>
std::vector<std::uint32_t> add_straight_blade(System& system, const Vec<2, typename System::scalar_type>& base,
                                              const Vec<2, typename System::scalar_type>& direction,
                                              typename System::scalar_type length, int node_count, int width_particles,
                                              typename System::scalar_type lateral_centre,
                                              const ElasticMaterial<typename System::scalar_type>& material,
                                              const RodSection<typename System::scalar_type>& section,
                                              typename System::scalar_type smoothing_length, std::int32_t body,
                                              const char* who) {
  using T = typename System::scalar_type;
  constexpr int Dim = System::dimension;
  material.validate();
  section.validate();
  require_positive(fmt::format("{}: length (m)", who), length);
  require_in_range(fmt::format("{}: node_count", who), node_count, 3, 1 << 24);
  require_in_range(fmt::format("{}: width_particles", who), width_particles, 1, Dim == 2 ? 1 : 1 << 12);
  require_positive(fmt::format("{}: smoothing_length (m)", who), smoothing_length);
  require_positive(fmt::format("{}: |direction|", who), direction.norm());
  require_finite(fmt::format("{}: lateral_centre (m)", who), lateral_centre);
  for (int d = 0; d < 2; ++d) require_finite(fmt::format("{}: base (m)", who), base[d]);
  const Vec<2, T> e = direction.normalized();
  const T ds = length / T(node_count - 1), db = section.width / T(width_particles);
  std::vector<std::uint32_t> ids;
  auto& p = system.particles();
  for (int i = 0; i < node_count; ++i) {
    const T voronoi = (i == 0 || i == node_count - 1) ? T(0.5) * ds : ds;
    const Vec<2, T> x = base + (T(i) * ds) * e;
    for (int j = 0; j < width_particles; ++j) {
      std::size_t slot;
      if constexpr (Dim == 2) {  // masses per unit depth: rho t D_i
        slot = p.add(Kind::solid, x, Vec<2, T>::Zero(), material.density,
                     material.density * section.thickness * voronoi, smoothing_length, body);
      } else {  // each particle stands for b / w of the width
        const T y = lateral_centre + (T(j) + T(0.5) - T(0.5) * T(width_particles)) * db;
        slot = p.add(Kind::solid, Vec<3, T>(x[0], y, x[1]), Vec<3, T>::Zero(), material.density,
                     material.density * section.thickness * voronoi * db, smoothing_length, body);
      }
      ids.push_back(p.id[slot]);
    }
  }
  return ids;
}
}  // namespace detail

/// Adds a straight blade of `node_count` equally spaced nodes (Kind::solid, body `body`) from `base` along
/// `direction` over `length` to the system, base first (increasing ids), with particle masses per unit depth
/// rho t D_i and smoothing length `smoothing_length` (for the fluid's neighbour search). Returns their ids.
template <class System>
std::vector<std::uint32_t> add_elastic_rod(System& system, const Vec<2, typename System::scalar_type>& base,
                                           const Vec<2, typename System::scalar_type>& direction,
                                           typename System::scalar_type length, int node_count,
                                           const ElasticMaterial<typename System::scalar_type>& material,
                                           const RodSection<typename System::scalar_type>& section,
                                           typename System::scalar_type smoothing_length, std::int32_t body) {
  static_assert(System::dimension == 2, "add_elastic_rod: the elastic rod is planar (add_elastic_ribbon in 3D)");
  return detail::add_straight_blade(system, base, direction, length, node_count, 1, typename System::scalar_type(0),
                                    material, section, smoothing_length, body, "add_elastic_rod");
}

/// Adds a straight ribbon to a 3D system (see the header comment): `node_count` equally spaced nodes from `base`
/// along `direction` over `length`, both in the x-z plane ((x, z) pairs), each node a row of `width_particles`
/// particles across the section's width b, centred on y = `lateral_centre` at y = centre + (j + 1/2 - w/2) b / w
/// (each stands for b / w of the width), base first (increasing ids), with masses rho t D_i b / w and smoothing length
/// `smoothing_length`. Returns their ids. The ElasticRod built on this body is the ribbon.
template <class System>
std::vector<std::uint32_t> add_elastic_ribbon(System& system, const Vec<2, typename System::scalar_type>& base,
                                              const Vec<2, typename System::scalar_type>& direction,
                                              typename System::scalar_type length, int node_count, int width_particles,
                                              typename System::scalar_type lateral_centre,
                                              const ElasticMaterial<typename System::scalar_type>& material,
                                              const RodSection<typename System::scalar_type>& section,
                                              typename System::scalar_type smoothing_length, std::int32_t body) {
  static_assert(System::dimension == 3, "add_elastic_ribbon: a ribbon needs a 3D system (add_elastic_rod in 2D)");
  return detail::add_straight_blade(system, base, direction, length, node_count, width_particles, lateral_centre,
                                    material, section, smoothing_length, body, "add_elastic_ribbon");
}

/// Planar discrete elastic rod owning the solid particles of one body (a ParticleModel and a SolidModel); in a 3D
/// system a ribbon bending in the x-z plane (see the header comment).
template <class System>
class ElasticRod {
 public:
  static constexpr int Dim = System::dimension;
  static_assert(Dim == 2 || Dim == 3, "ElasticRod: a 2D rod or a 3D ribbon");
  /// A line of nodes with no interior: couplings take the normal each node publishes and push on both faces
  /// (coupling/repulsive_force.hpp) instead of finding a surface by the colour gradient.
  static constexpr bool thin_structure = true;
  using T = typename System::scalar_type;
  using Vector = Vec<2, T>;  ///< in the rod's plane: (x, vertical)
  using SpaceVector = Vec<Dim, T>;
  using Matrix = Mat<Dim, T>;
  using Parameters = ElasticRodParameters<T>;

  /// Takes the solid particles of `body` as nodes, base to tip in increasing id; their current positions are
  /// the rest shape (straight or curved). In 3D consecutive ids at the same (x, z) are one node's row across the
  /// width (add_elastic_ribbon). Throws InputError for invalid parameters, fewer than 3 nodes, coincident nodes or
  /// rows of unequal size.
  ElasticRod(const System& system, std::int32_t body, const ElasticMaterial<T>& material, const Parameters& params = {})
      : material_((material.validate(), material)), params_((params.validate(), params)), body_(body) {
    const auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::solid && p.body[i] == body) ids_.push_back(p.id[i]);
    std::sort(ids_.begin(), ids_.end());
    if constexpr (Dim == 3) {  // the row of the first node: the leading particles at its (x, z)
      while (per_node_ < ids_.size() && bending_plane(p.position[p.slot_of_id(ids_[per_node_])]) ==
                                            bending_plane(p.position[p.slot_of_id(ids_[0])]))
        ++per_node_;
    }
    if (ids_.size() % per_node_ != 0)
      throw InputError(
          fmt::format("ElasticRod: body {} has {} particles, not a whole number of rows of {} (valid: "
                      "add the ribbon with add_elastic_ribbon)",
                      body, ids_.size(), per_node_));
    const std::size_t n = ids_.size() / per_node_;
    if (n < 3)
      throw InputError(
          fmt::format("ElasticRod: body {} has {} nodes: valid range is [3, inf) (add the nodes with "
                      "add_elastic_rod before creating the model)",
                      body, n));
    local_of_id_.assign(p.id_capacity(), -1);  // indexed by id: ids of removed particles stay unused
    x_.resize(n);
    v_.resize(n);
    lateral_.resize(ids_.size());
    for (std::size_t i = 0; i < ids_.size(); ++i) {
      const std::size_t k = i / per_node_, s = p.slot_of_id(ids_[i]);
      local_of_id_[ids_[i]] = static_cast<std::int64_t>(k);
      if (i % per_node_ == 0) {
        x_[k] = bending_plane(p.position[s]);
        v_[k] = bending_plane(p.velocity[s]);
      } else if (bending_plane(p.position[s]) != x_[k]) {
        throw InputError(
            fmt::format("ElasticRod: particle id {} of body {} is not at the (x, z) of its row's first "
                        "particle (rows of {} across the width; valid: add_elastic_ribbon)",
                        ids_[i], body, per_node_));
      }
      if (Dim == 3 && (bending_plane(p.velocity[s]) != v_[k] || p.velocity[s][Dim - 2] != T(0)))
        throw InputError(
            fmt::format("ElasticRod: particle id {} of body {} does not move with its row (valid: the "
                        "row's particles share one velocity in the x-z plane, zero along y)",
                        ids_[i], body));
      lateral_[i] = Dim == 3 ? p.position[s][1] : T(0);
    }
    X_ = x_;
    rest_length_.resize(n - 1);
    for (std::size_t j = 0; j + 1 < n; ++j) {
      rest_length_[j] = (X_[j + 1] - X_[j]).norm();
      if (!(rest_length_[j] > T(0)))
        throw InputError(
            fmt::format("ElasticRod: nodes {} and {} of body {} coincide (edge rest length {} m): valid "
                        "range is (0, inf)",
                        ids_[j * per_node_], ids_[(j + 1) * per_node_], body, rest_length_[j]));
    }
    voronoi_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const T left = i > 0 ? rest_length_[i - 1] : T(0);
      const T right = i + 1 < n ? rest_length_[i] : T(0);
      voronoi_[i] = T(0.5) * (left + right);
    }
    const T rho_a = material_.density * params_.section.area();
    mass_.resize(n);
    for (std::size_t i = 0; i < n; ++i) mass_[i] = rho_a * voronoi_[i];
    inertia_ratio_.assign(ids_.size(), rho_a / (rho_a + params_.added_mass_per_area * params_.section.width));
    rest_angle_.assign(n, T(0));
    for (std::size_t i = 1; i + 1 < n; ++i) rest_angle_[i] = turning_angle(X_[i] - X_[i - 1], X_[i + 1] - X_[i]);
    held_.assign(n, 0);
    held_tangent_[0] = (X_[1] - X_[0]).normalized();
    held_tangent_[1] = (X_[n - 1] - X_[n - 2]).normalized();
    axial_force_.assign(n - 1, T(0));
    moment_.assign(n, T(0));
    a_int_.assign(n, Vector::Zero());
    a_ext_.assign(n, Vector::Zero());
    const T l_min = *std::min_element(rest_length_.begin(), rest_length_.end());
    const T e_r = modulus();
    const T omega_axial = T(2) * std::sqrt(e_r / material_.density) / l_min;
    const T omega_bend = T(4) * std::sqrt(e_r * params_.section.second_moment() / rho_a) / (l_min * l_min);
    omega_max_ = std::sqrt(omega_axial * omega_axial + omega_bend * omega_bend);
  }

  // ---- set-up ----
  /// Holds the nodes whose reference position satisfies pred at rest at their reference position. A held end
  /// node (base or tip) also holds the end tangent at its reference direction: that end is clamped (for an end
  /// that is only pinned, hold it and leave the tangent free with pin_where). Returns the number of held nodes.
  /// In 3D pred sees the rest positions of a node's row; the node is held if any of them satisfies it.
  template <class Predicate>
  std::size_t clamp_where(Predicate&& pred) {
    const std::size_t n = node_count();
    pin_where(pred);
    clamped_end_[0] = clamped_end_[0] || held_[0];
    clamped_end_[1] = clamped_end_[1] || held_[n - 1];
    return held_count();
  }
  /// Holds the nodes whose reference position satisfies pred, without holding the tangent (a pin).
  template <class Predicate>
  std::size_t pin_where(Predicate&& pred) {
    for (std::size_t i = 0; i < ids_.size(); ++i)
      if (pred(in_space(X_[i / per_node_], lateral_[i]))) held_[i / per_node_] = 1;
    return held_count();
  }
  /// Moves the held nodes rigidly: each sits at its reference position plus displacement(t) with velocity
  /// velocity(t), the clamped tangents unchanged (a blade towed along the bed through still water). Without it
  /// held nodes stay at rest.
  void set_clamp_motion(std::function<Vector(T)> displacement, std::function<Vector(T)> velocity) {
    if (!displacement || !velocity)
      throw InputError("ElasticRod::set_clamp_motion: both displacement(t) and velocity(t) must be given");
    clamp_displacement_ = std::move(displacement);
    clamp_velocity_ = std::move(velocity);
  }

  /// A rigid plane the nodes cannot cross (a bed under a blade that folds over): a node closer than `gap` to the
  /// plane through `point` with unit normal `normal` (pointing to the free side) is put back at `gap` and loses
  /// the velocity component into the plane (inelastic contact, no friction). Nodes whose rest position is closer
  /// than `gap` (next to a base clamped on the plane) are exempt. Without it the rod meets no walls. A gap g > 0
  /// also holds the lowest g of a blade clamped on the plane nearly upright (the node resting at height g must stay
  /// at g or above): it stiffens a blade that bends within a few g of its base (blade_in_current at Ca > 100).
  void set_contact_plane(const Vector& point, const Vector& normal, T gap) {
    require_positive("ElasticRod::set_contact_plane |normal|", normal.norm());
    require_non_negative("ElasticRod::set_contact_plane gap (m)", gap);
    contact_point_ = point;
    contact_normal_ = normal.normalized();
    contact_gap_ = gap;
    has_contact_ = true;
  }

  /// Clamps the base (node 0): position and tangent held. Returns the number of held nodes.
  std::size_t clamp_base() {
    held_[0] = 1;
    clamped_end_[0] = true;
    return held_count();
  }

  // ---- ParticleModel ----
  /// Reads the node state and publishes normal, density, pressure and sound speed of the nodes.
  void compute_rates(System& system, T time) {
    gather(system.particles(), false);
    set_damping_frame(time);
    internal_forces();
    publish(system.particles());
  }

  /// +inf when sub-cycling, otherwise the rod's own step over the cfl (the Simulation applies its own CFL).
  T stable_time_step(const System& /*system*/) const {
    if (params_.sub_cycle) return std::numeric_limits<T>::infinity();
    return solid_time_step() / params_.cfl;
  }

  /// Integrates the rod over [time, time + dt] in ceil(dt / solid_time_step()) velocity-Verlet sub-steps,
  /// holding the external acceleration found in p.acceleration (force per unit mass) constant.
  void advance(System& system, T time, T dt) {
    auto& p = system.particles();
    gather(p, true);
    const std::size_t n_sub = detail::sub_step_count(dt, solid_time_step());
    const T h = dt / T(n_sub);
    const std::size_t n = node_count();
    const Vector g = body_force();
    set_damping_frame(time);
    internal_forces();
    for (std::size_t s = 0; s < n_sub; ++s) {
      const T t_end = time + T(s + 1) * h;
      const Vector d = clamp_displacement_ ? clamp_displacement_(t_end) : Vector::Zero();
      const Vector u = clamp_velocity_ ? clamp_velocity_(t_end) : Vector::Zero();
      for (std::size_t k = 0; k < n; ++k) {
        if (held_[k]) {
          x_[k] = X_[k] + d;
          v_[k] = u;
          continue;
        }
        v_[k] += (T(0.5) * h * inertia_ratio_[k * per_node_]) * (a_int_[k] + a_ext_[k] + g);
        x_[k] += h * v_[k];
        if (has_contact_ && (X_[k] - contact_point_).dot(contact_normal_) >= contact_gap_) {
          const T d = (x_[k] - contact_point_).dot(contact_normal_);
          if (d < contact_gap_) {
            x_[k] += (contact_gap_ - d) * contact_normal_;
            const T vn = v_[k].dot(contact_normal_);
            if (vn < T(0)) v_[k] -= vn * contact_normal_;
          }
        }
      }
      set_damping_frame(t_end);
      internal_forces();
      for (std::size_t k = 0; k < n; ++k)
        if (!held_[k]) v_[k] += (T(0.5) * h * inertia_ratio_[k * per_node_]) * (a_int_[k] + a_ext_[k] + g);
      check_finite(time + T(s + 1) * h);
    }
    sub_steps_ += n_sub;
    if (params_.stretch_limit > T(0)) {
      const T stretch = max_stretch();
      if (stretch > params_.stretch_limit)
        throw BlowUpError(
            fmt::format("elastic rod (body {}) at t = {:.6g} s: largest edge stretch {:.4g} > "
                        "stretch_limit = {:.4g}",
                        body_, time + dt, stretch, params_.stretch_limit));
    }
    scatter(p);
    publish(p);
  }

  // ---- SolidModel ----
  std::int32_t body() const noexcept { return body_; }
  /// Node ids, base to tip (in 3D node by node, each node's row across the width in increasing y).
  const std::vector<std::uint32_t>& particle_ids() const noexcept { return ids_; }
  /// Number of nodes (particle_ids().size() / particles_per_node()).
  std::size_t node_count() const noexcept { return ids_.size() / per_node_; }
  /// Particles of a node's row across the width: 1 in 2D.
  std::size_t particles_per_node() const noexcept { return per_node_; }
  /// The rod's edges, base to tip, as pairs of node ids (a thin structure: the fluid does not interact across them).
  /// 2D only: the visibility criterion and the guard are planar (fluid/thin_structure_visibility.hpp).
  void structure_edges(std::vector<StructureEdge>& edges) const requires(Dim == 2) {
    for (std::size_t j = 0; j + 1 < ids_.size(); ++j) edges.push_back({ids_[j], ids_[j + 1]});
  }
  /// A ribbon's strip elements (3D): per edge of the rod and particle of the row, the edge between that particle and
  /// the one of the next row, with its lateral band (half-way to the row's neighbouring particles; the outer ones
  /// reach the strip's edges at +-b/2).
  void structure_edges(std::vector<StructureEdge>& edges, std::vector<std::array<T, 2>>& bands) const
      requires(Dim == 3) {
    const auto [lo, hi] = lateral_extent();
    const std::size_t w = per_node_;
    for (std::size_t j = 0; j + 1 < node_count(); ++j) {
      for (std::size_t r = 0; r < w; ++r) {
        edges.push_back({ids_[j * w + r], ids_[(j + 1) * w + r]});
        const T below = r == 0 ? lo : T(0.5) * (lateral_[r - 1] + lateral_[r]);
        const T above = r + 1 == w ? hi : T(0.5) * (lateral_[r] + lateral_[r + 1]);
        bands.push_back({below, above});
      }
    }
  }
  /// Lateral extent of a ribbon's strip, (lowest, highest) y of its width b, m (3D only).
  std::pair<T, T> lateral_extent() const requires(Dim == 3) {
    const auto [lo, hi] = std::minmax_element(lateral_.begin(), lateral_.begin() + std::ptrdiff_t(per_node_));
    const T centre = T(0.5) * (*lo + *hi), half = T(0.5) * params_.section.width;
    return {centre - half, centre + half};
  }
  /// Mean rest edge length ds, m.
  T reference_spacing() const {
    T sum = T(0);
    for (T l : rest_length_) sum += l;
    return sum / T(rest_length_.size());
  }
  const ElasticMaterial<T>& material() const noexcept { return material_; }
  const Parameters& parameters() const noexcept { return params_; }

  /// The rod's own stable step cfl 2 / omega_max (and cfl 2 / c_d with damping), s.
  T solid_time_step() const {
    const T rate = std::max(omega_max_, params_.damping);
    return params_.cfl * T(2) / rate;
  }

  /// Stress at the node as a uniaxial tensor along the tangent, sigma = s t (x) t, Pa (tension positive), with s
  /// the fibre stress of larger magnitude on the two faces: s = N/A + sign(N) |M| (t/2) / I (axial plus bending).
  Matrix cauchy_stress(std::uint32_t id) const {
    const std::size_t k = local(id);
    const T membrane = node_axial_force(k) / params_.section.area();
    const T bending = std::abs(moment_[k]) * T(0.5) * params_.section.thickness / params_.section.second_moment();
    const T s = membrane + (membrane >= T(0) ? bending : -bending);
    const Vector t = tangent(k);
    return s * t * t.transpose();
  }
  /// Largest edge stretch l_j / L_j (1 for the rest length; > 1 in tension).
  T max_stretch() const {
    T s = T(0);
    for (std::size_t j = 0; j + 1 < node_count(); ++j) s = std::max(s, (x_[j + 1] - x_[j]).norm() / rest_length_[j]);
    return s;
  }

  // ---- diagnostics ----
  /// Axial force N at a node (mean of its edges), N (tension positive).
  T axial_force(std::uint32_t id) const { return node_axial_force(local(id)); }
  /// Bending moment M = E_r I (phi - phi0) / D at a node, N m (positive: the blade bends towards +normal).
  T bending_moment(std::uint32_t id) const { return moment_[local(id)]; }
  /// Position of the tip node (last in id order), m.
  const Vector& tip_position() const { return x_.back(); }
  /// Rest positions of the nodes, base to tip, m (in the rod's plane: (x, z) in 3D).
  const std::vector<Vector>& reference_positions() const noexcept { return X_; }
  /// Current node positions and velocities, base to tip (as of the last compute_rates / advance).
  const std::vector<Vector>& positions() const noexcept { return x_; }
  const std::vector<Vector>& velocities() const noexcept { return v_; }
  /// Node masses m_i = rho A D_i of the real blade (width b), kg.
  const std::vector<T>& node_masses() const noexcept { return mass_; }
  /// Per particle (in particle_ids() order), m_i / (m_i + m_a b D_i): the share of a force on the node's own mass
  /// that becomes its acceleration (1 without added inertia). Couplings use it for their step limit
  /// (coupling/repulsive_force.hpp).
  const std::vector<T>& inertia_ratios() const noexcept { return inertia_ratio_; }
  /// E_r: E, or E / (1 - nu^2) in plane strain, Pa.
  T modulus() const { return params_.plane_strain ? material_.plane_strain_modulus() : material_.youngs_modulus; }
  /// Flexural rigidity E_r I, N m^2.
  T bending_stiffness() const { return modulus() * params_.section.second_moment(); }
  /// Upper bound of the highest angular frequency of the linearised rod, rad/s.
  T highest_frequency_bound() const noexcept { return omega_max_; }
  /// Body force per unit mass (1 - rho_w / rho) g, m/s^2.
  Vector body_force() const { return (T(1) - params_.ambient_density / material_.density) * params_.gravity; }
  /// Kinetic energy sum m v^2 / 2 of the real blade, J.
  T kinetic_energy() const {
    T e = T(0);
    for (std::size_t k = 0; k < node_count(); ++k) e += T(0.5) * mass_[k] * v_[k].squaredNorm();
    return e;
  }
  /// Stored elastic energy U (stretching plus bending), J.
  T strain_energy() const {
    const std::size_t n = node_count();
    const T ea = modulus() * params_.section.area(), ei = bending_stiffness();
    T e = T(0);
    for (std::size_t j = 0; j + 1 < n; ++j) {
      const T dl = (x_[j + 1] - x_[j]).norm() - rest_length_[j];
      e += T(0.5) * ea * dl * dl / rest_length_[j];
    }
    for (std::size_t i = 0; i < n; ++i) {
      const T dphi = bending_angle(i);
      e += T(0.5) * ei * dphi * dphi / voronoi_[i];
    }
    return e;
  }
  /// Potential energy of the body force, -sum m (1 - rho_w/rho) g . x, J.
  T potential_energy() const {
    T e = T(0);
    for (std::size_t k = 0; k < node_count(); ++k) e -= mass_[k] * body_force().dot(x_[k]);
    return e;
  }
  std::size_t sub_step_total() const noexcept { return sub_steps_; }
  /// Total force the couplings exert on the rod (all nodes, held ones included), N per unit depth in 2D, N in 3D:
  /// the sum of m_i a_i over the particles of the force per unit mass found in the particle set after the rate
  /// evaluation.
  SpaceVector coupling_force(const ParticleSet<Dim, T>& p) const {
    SpaceVector f = SpaceVector::Zero();
    for (const std::uint32_t id : ids_) {
      const std::size_t s = p.slot_of_id(id);
      f += p.mass[s] * p.acceleration[s];
    }
    return f;
  }

  // ---- checkpoint (io/checkpoint.hpp) ----
  template <class Writer>
  void save_checkpoint(Writer& w) const {
    w.write("elastic_rod.ids", ids_);
    w.write("elastic_rod.held", held_);
    w.write("elastic_rod.clamped_ends", std::vector<std::uint8_t>{clamped_end_[0], clamped_end_[1]});
    w.write("elastic_rod.position", x_);
    w.write("elastic_rod.velocity", v_);
    w.write("elastic_rod.sub_steps", static_cast<std::uint64_t>(sub_steps_));
  }
  /// Restores the state saved by save_checkpoint; the rod must be built from the same nodes (checked).
  template <class Reader>
  void load_checkpoint(Reader& r) {
    std::vector<std::uint32_t> ids;
    r.read("elastic_rod.ids", ids);
    if (ids != ids_)
      r.fail(fmt::format("elastic rod of body {}: the file holds {} nodes with other ids than this rod's {}", body_,
                         ids.size(), ids_.size()));
    std::vector<std::uint8_t> held, ends;
    r.read_exact("elastic_rod.held", held, node_count());
    r.read_exact("elastic_rod.clamped_ends", ends, 2);
    std::vector<Vector> x, v;
    r.read_exact("elastic_rod.position", x, node_count());
    r.read_exact("elastic_rod.velocity", v, node_count());
    std::uint64_t sub_steps = 0;
    r.read("elastic_rod.sub_steps", sub_steps);
    held_ = std::move(held);
    clamped_end_[0] = ends[0] != 0;
    clamped_end_[1] = ends[1] != 0;
    x_ = std::move(x);
    v_ = std::move(v);
    sub_steps_ = static_cast<std::size_t>(sub_steps);
    internal_forces();
  }

 private:
  static T turning_angle(const Vector& a, const Vector& b) {
    return std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
  }
  static Vector perp(const Vector& e) { return Vector(-e.y(), e.x()); }
  /// The point of the rod's plane at lateral position y (bending_plane, core/types.hpp, is the inverse).
  static SpaceVector in_space(const Vector& x, T lateral) {
    if constexpr (Dim == 2) return x;
    else return SpaceVector(x[0], lateral, x[1]);
  }
  void set_damping_frame(T t) {
    damping_frame_ = params_.damping_relative_to_clamp && clamp_velocity_ ? clamp_velocity_(t) : Vector::Zero();
  }

  std::size_t held_count() const {
    std::size_t c = 0;
    for (auto h : held_) c += h;
    return c;
  }
  std::size_t local(std::uint32_t id) const {
    const std::int64_t k = id < local_of_id_.size() ? local_of_id_[id] : -1;
    if (k < 0) throw InputError(fmt::format("particle id {} is not a node of the elastic rod (body {})", id, body_));
    return static_cast<std::size_t>(k);
  }

  /// phi_i - phi0_i at node i: the turning angle at an interior node, the angle between the held tangent and the
  /// end edge at a clamped end, 0 at a free end.
  T bending_angle(std::size_t i) const {
    const std::size_t n = node_count();
    if (i == 0) return clamped_end_[0] ? turning_angle(held_tangent_[0], x_[1] - x_[0]) : T(0);
    if (i == n - 1) return clamped_end_[1] ? turning_angle(x_[n - 1] - x_[n - 2], held_tangent_[1]) : T(0);
    return turning_angle(x_[i] - x_[i - 1], x_[i + 1] - x_[i]) - rest_angle_[i];
  }

  /// Axial forces, bending moments and the internal (elastic + damping) acceleration at the current state.
  void internal_forces() {
    const std::size_t n = node_count();
    const T ea = modulus() * params_.section.area(), ei = bending_stiffness();
    for (std::size_t i = 0; i < n; ++i) moment_[i] = ei * bending_angle(i) / voronoi_[i];
    for (auto& a : a_int_) a.setZero();
    for (std::size_t j = 0; j + 1 < n; ++j) {
      const Vector e = x_[j + 1] - x_[j];
      const T l2 = e.squaredNorm(), l = std::sqrt(l2);
      axial_force_[j] = ea * (l / rest_length_[j] - T(1));
      const T tau = moment_[j] - moment_[j + 1];
      const Vector f = (axial_force_[j] / l) * e + (tau / l2) * perp(e);
      a_int_[j] += f;
      a_int_[j + 1] -= f;
    }
    for (std::size_t i = 0; i < n; ++i) a_int_[i] = a_int_[i] / mass_[i] - params_.damping * (v_[i] - damping_frame_);
  }

  T node_axial_force(std::size_t k) const {
    const std::size_t n = node_count();
    if (k == 0) return axial_force_[0];
    if (k == n - 1) return axial_force_[n - 2];
    return T(0.5) * (axial_force_[k - 1] + axial_force_[k]);
  }
  /// Unit tangent at a node (mean direction of its edges), base to tip.
  Vector tangent(std::size_t k) const {
    const std::size_t n = node_count();
    if (k == 0) return (x_[1] - x_[0]).normalized();
    if (k == n - 1) return (x_[n - 1] - x_[n - 2]).normalized();
    return ((x_[k] - x_[k - 1]).normalized() + (x_[k + 1] - x_[k]).normalized()).normalized();
  }

  /// Node state from the first particle of each row; the external acceleration is the row's mass-weighted mean (in
  /// 2D the node's own).
  void gather(const ParticleSet<Dim, T>& p, bool external) {
    for (std::size_t k = 0; k < node_count(); ++k) {
      const std::size_t s = p.slot_of_id(ids_[k * per_node_]);
      x_[k] = bending_plane(p.position[s]);
      v_[k] = bending_plane(p.velocity[s]);
      if (!external) continue;
      if (held_[k]) {
        a_ext_[k] = Vector::Zero();
      } else if (per_node_ == 1) {
        a_ext_[k] = bending_plane(p.acceleration[s]);
      } else {
        Vector force = Vector::Zero();
        T mass = T(0);
        for (std::size_t j = 0; j < per_node_; ++j) {
          const std::size_t r = p.slot_of_id(ids_[k * per_node_ + j]);
          force += p.mass[r] * bending_plane(p.acceleration[r]);
          mass += p.mass[r];
        }
        a_ext_[k] = force / mass;
      }
    }
  }
  void scatter(ParticleSet<Dim, T>& p) const {
    for (std::size_t i = 0; i < ids_.size(); ++i) {
      const std::size_t s = p.slot_of_id(ids_[i]);
      p.position[s] = in_space(x_[i / per_node_], lateral_[i]);
      p.velocity[s] = in_space(v_[i / per_node_], T(0));
    }
  }
  /// Writes the blade normal, density rho / stretch, pressure -(N/A)/2 (the section-mean stress: the bending
  /// stress averages to zero over the thickness) and the bar wave speed sqrt(E_r / rho) of every node.
  void publish(ParticleSet<Dim, T>& p) const {
    const T c = std::sqrt(modulus() / material_.density);
    for (std::size_t i = 0; i < ids_.size(); ++i) {
      const std::size_t s = p.slot_of_id(ids_[i]), k = i / per_node_;
      const T n_k = node_axial_force(k);
      p.normal[s] = in_space(perp(tangent(k)), T(0));
      p.density[s] = material_.density / (T(1) + n_k / (modulus() * params_.section.area()));
      p.pressure[s] = -T(0.5) * n_k / params_.section.area();
      p.sound_speed[s] = c;
    }
  }

  void check_finite(T time) const {
    for (std::size_t k = 0; k < node_count(); ++k)
      if (!x_[k].allFinite() || !v_[k].allFinite())
        throw BlowUpError(fmt::format(
            "elastic rod blow-up at t = {:.6g} s: body {} node id {} (node {} of {}) has a "
            "non-finite {}; the particle set holds the state at the start of the outer step",
            time, body_, ids_[k * per_node_], k, node_count(), x_[k].allFinite() ? "velocity" : "position"));
  }

  ElasticMaterial<T> material_;
  Parameters params_;
  std::int32_t body_;
  std::vector<std::uint32_t> ids_;                 // particle ids, base to tip, row by row in 3D
  std::size_t per_node_{1};                        // particles per node (its row across the width in 3D)
  std::vector<T> lateral_;                         // per particle: its y (3D), m
  std::vector<std::int64_t> local_of_id_;          // node index of a particle id, -1 if not a node
  std::vector<Vector> X_, x_, v_;                  // rest and current positions (m), velocities (m/s)
  std::vector<T> rest_length_;                     // L_j, m
  std::vector<T> voronoi_;                         // D_i, m
  std::vector<T> mass_;                            // m_i = rho A D_i, kg
  std::vector<T> inertia_ratio_;                   // per particle: m_i / (m_i + m_a b D_i) (1 without added mass)
  std::vector<T> rest_angle_;                      // phi0_i, rad
  std::vector<std::uint8_t> held_;                 // 1: node held at rest at X
  std::array<bool, 2> clamped_end_{false, false};  // base, tip: tangent held
  std::array<Vector, 2> held_tangent_{};           // reference end tangents
  std::vector<T> axial_force_;                     // N_j, N
  std::vector<T> moment_;                          // M_i, N m
  std::vector<Vector> a_int_, a_ext_;              // internal and external acceleration, m/s^2
  T omega_max_{0};                                 // rad/s
  std::size_t sub_steps_{0};
  std::function<Vector(T)> clamp_displacement_, clamp_velocity_;  // motion of the held nodes (empty: at rest)
  Vector damping_frame_{Vector::Zero()};  // velocity the damping is relative to (damping_relative_to_clamp)
  Vector contact_point_ = Vector::Zero(), contact_normal_ = Vector::UnitY();  // contact plane, m
  T contact_gap_{0};                                                          // m
  bool has_contact_{false};
};

}  // namespace sphfsi
