// sphfsi: updated-Lagrangian elastic SPH solid, the reference paper's eq. (13) solid (Gray, Monaghan & Swift 2001,
// CMAME 190:6641; the SPHysics solid). Only particles of the same body interact; for a particle a and neighbour b,
// grad_ab = grad_a W(|x_a - x_b|, h_ab) on the current positions, V_b = m_b / rho_b, v_ba = v_b - v_a.
//
// Physics (both formulations), GMS 2001 eqs 2.3-2.10:
//   strain rate, spin   eps_dot = (L + L^T) / 2,   Omega = (L - L^T) / 2,   L = grad v
//   Hooke + Jaumann     dS/dt = 2 G (eps_dot - tr(eps_dot) I / 3) + Omega S - S Omega
//   pressure            p = c0^2 (rho - rho0),  c0^2 = K / rho0,   sigma = -p I + S
//   artificial stress   R_a = Q diag(-eps max(sigma'_i, 0) / rho_a^2) Q^T in the principal frame of sigma_a,
//                       pair term m_a m_b (R_a + R_b) f_ab^n grad_ab, f_ab = W(r_ab) / W(dp)
//                                                                         (Monaghan 2000, JCP 159:290; GMS 3.6)
//   artificial visc.    pair term -m_a m_b Pi_ab grad_ab, Pi_ab = (-alpha c0 mu_ab + beta mu_ab^2) / rho_ab,
//                       mu_ab = h v_ab.x_ab / (r^2 + 0.01 h^2) when v_ab . x_ab < 0        (Monaghan 1992, 4.1)
//   plus gravity, the external (fluid) acceleration and an optional mass-proportional damping - c_d v_a.
//
// Discretisation, formulation::gray_monaghan_swift (the original scheme, the paper's eq. 13):
//   drho_a/dt = sum_b m_b (v_a - v_b) . grad_ab,   L_a = sum_b V_b v_ba (x) grad_ab,
//   m_a dv_a/dt = sum_b m_a m_b (sigma_a / rho_a^2 + sigma_b / rho_b^2) grad_ab + artificial terms.
// Its sums are not consistent at a free surface (the support is one-sided): in bending, the surface particles
// see a strain rate of the wrong size and the force sum misses part of the stress divergence, so the Gray et al.
// plate is 31 % too slow at H/dp = 6.
// formulation::corrected (default). Corrected SPH for solids (Bonet & Lok 1999, CMAME 180:97; Vidal, Bonet &
// Huerta 2007, IJNME 69:2687) with the kernel sums taken over the neighbours of a reference configuration x_ref
// (a Lagrangian kernel: Belytschko, Guo, Liu & Xiao 2000, IJNME 48:1359, show that kernels of the current
// configuration are unstable in tension whatever the correction; Rabczuk, Belytschko & Xiao 2004, CMAME 193:1035).
// With V_ref = m / rho at x_ref and gradient weights g_ab exact for quadratic fields (detail::
// quadratic_gradient_weights; Bonet-Lok B_a^T grad_ab where the neighbours do not determine a quadratic):
//   F_a = sum_b V_ref_b x_ba (x) g_ab,   L_a = [sum_b V_ref_b v_ba (x) g_ab] F_a^-1,   rho_a = m_a / (V_ref_a det F_a)
//   m_a dv_a/dt = sum_b V_ref_a V_ref_b (P_a g_ab - P_b g_ba) + hourglass + artificial terms,  P = det F sigma F^-T
// The stress is still the eq. (13) one, integrated in rate form with the Jaumann rate; only the sums are taken on
// x_ref. The force's power is minus the stress power, sum_a v_a . f_a = -sum_a V_a sigma_a : L_a, so velocity
// gradient and force are compatible; the pair sum is antisymmetric (linear momentum to rounding) and, since
// sum_b V_ref_b x_ba (x) g_ab = F_a and sigma is symmetric, conserves angular momentum too. A rigid rotation gives
// F = R, L antisymmetric: no strain rate, surfaces included. Hourglass control as in the TLSPH model
// (Ganzenmueller 2015): f_a = -alpha_hg E V_a V_b W_ab delta_ab / |X_ba| e_ab with
// delta_ab = ((F_a + F_b)/2 X_ba - x_ba) . e_ab / |X_ba| on the reference bond X_ba. x_ref is the initial
// configuration; with reference_update > 0 it is replaced by the current one (V_ref = m / rho, F = I; stress and
// density carry over) whenever max |F - I| exceeds that value (for flows of the solid; measured unstable in the
// V_f = 0.05 plate at H/dp = 6 with updates every 0.2, so off by default: rotations need no update).
// The gray_monaghan_swift sums are kept as the reference paper's scheme; the artificial stress (epsilon = 0.3 in
// GMS 2001) is off by default because the corrected sums do not need it and it softens bending (+3.6 points on
// the plate period at H/dp = 6).
// Clamps: clamp_where() holds particles at rest; clamp_by_reflection() moves the wall part as the odd image of the
// free part (as in the TLSPH model): the images carry no stress of their own, keep their reference volume, and the
// forces on them act on their mirrors reversed.
// 2D is plane strain: the 3D deviator (the 1/3 above) with in-plane components (S_zz = -tr S). Time stepping:
// kick-drift-kick (velocity Verlet): v(t + h/2), x(t + h), then the rates from x(t + h) and v(t + h/2) advance
// density and stress to t + h (a leapfrog for the stress), then the forces at t + h.
// Sub-cycled inside a fluid step with the P-wave CFL step and, for the corrected formulation, the highest
// frequency of the linearised body (the quadratic weights stiffen surface modes, as in the TLSPH model).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>
#include <sphfsi/solid/body.hpp>
#include <sphfsi/solid/detail/pair_list.hpp>
#include <sphfsi/solid/elastic_material.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace sphfsi {

/// Discretisation of the updated-Lagrangian solid (the physics, eq. 13 of the reference paper, is the same).
enum class UpdatedLagrangianFormulation : std::uint8_t {
  corrected,            ///< consistent gradient weights, compatible velocity gradient and force (default)
  gray_monaghan_swift,  ///< the original Gray, Monaghan & Swift (2001) sums
};

/// Parameters of an UpdatedLagrangianSolid (designated initialisers; validated by the model's constructor).
template <int Dim, Real T>
struct UpdatedLagrangianParameters {
  Vec<Dim, T> gravity = standard_gravity<Dim, T>();  ///< body force per unit mass, m/s^2
  T cfl{T(0.3)};                                     ///< solid step = cfl h / (c_p + |v|max), (0, 1]
  bool sub_cycle{true};                ///< true: advance() sub-cycles and the solid does not limit the fluid step
  T artificial_viscosity{T(0.5)};      ///< alpha, [0, 5]
  T artificial_viscosity_beta{T(0)};   ///< beta, [0, 5]
  T artificial_stress{T(0)};           ///< epsilon of Monaghan's artificial stress, [0, 1] (0: off; GMS 2001 used 0.3)
  T artificial_stress_exponent{T(4)};  ///< n of f_ab^n, [1, 10]
  UpdatedLagrangianFormulation formulation{UpdatedLagrangianFormulation::corrected};  ///< see the file comment
  bool quadratic_correction{true};  ///< corrected formulation: weights exact for quadratic (false: linear) fields
  T hourglass{T(0.1)};              ///< corrected formulation: alpha_hg, hourglass penalty relative to E, [0, 10]
  T reference_update{T(0)};         ///< corrected: new reference once max |F - I| exceeds this, [0, 10] (0: never)
  T damping{T(0)};                  ///< c_d, mass-proportional velocity damping, 1/s, >= 0
  T stretch_limit{T(0)};            ///< stop with BlowUpError when max_stretch() exceeds this (0: off), else > 1

  void validate() const {
    for (int d = 0; d < Dim; ++d) require_finite("UpdatedLagrangianParameters::gravity (m/s^2)", gravity[d]);
    require_in_range("UpdatedLagrangianParameters::cfl", cfl, T(1e-6), T(1));
    require_in_range("UpdatedLagrangianParameters::artificial_viscosity (alpha)", artificial_viscosity, T(0), T(5));
    require_in_range("UpdatedLagrangianParameters::artificial_viscosity_beta (beta)", artificial_viscosity_beta, T(0),
                     T(5));
    require_in_range("UpdatedLagrangianParameters::artificial_stress (epsilon)", artificial_stress, T(0), T(1));
    require_in_range("UpdatedLagrangianParameters::artificial_stress_exponent (n)", artificial_stress_exponent, T(1),
                     T(10));
    if (formulation != UpdatedLagrangianFormulation::corrected &&
        formulation != UpdatedLagrangianFormulation::gray_monaghan_swift)
      throw InputError(
          fmt::format("UpdatedLagrangianParameters::formulation = {} is invalid: valid values are "
                      "corrected (0), gray_monaghan_swift (1)",
                      static_cast<int>(formulation)));
    require_in_range("UpdatedLagrangianParameters::hourglass (alpha_hg)", hourglass, T(0), T(10));
    require_in_range("UpdatedLagrangianParameters::reference_update (max |F - I|, 0: never)", reference_update, T(0),
                     T(10));
    require_non_negative("UpdatedLagrangianParameters::damping (c_d, 1/s)", damping);
    if (stretch_limit != T(0))
      require_in_open_range("UpdatedLagrangianParameters::stretch_limit", stretch_limit, T(1),
                            std::numeric_limits<T>::max());
  }
};

/// Updated-Lagrangian (Gray-Monaghan-Swift) SPH solid of one body of a System (a ParticleModel and a SolidModel).
template <class System>
class UpdatedLagrangianSolid {
 public:
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;
  using Matrix = Mat<Dim, T>;
  using Kernel = typename System::kernel_type;
  using Parameters = UpdatedLagrangianParameters<Dim, T>;

  UpdatedLagrangianSolid(const System& system, std::int32_t body, const ElasticMaterial<T>& material,
                         const Parameters& params = {})
      : material_((material.validate(), material)),
        params_((params.validate(), params)),
        kernel_(system.kernel()),
        body_(system.particles(), body, material, static_cast<T>(Kernel::support)) {
    const std::size_t n = body_.size();
    rho_.assign(n, material_.density);
    S_.assign(n, Matrix::Zero());
    a_int_.assign(n, Vector::Zero());
    drho_.assign(n, T(0));
    power_.assign(n, T(0));
    dS_.assign(n, Matrix::Zero());
    R_.assign(n, Matrix::Zero());
    volume_.assign(n, T(0));
    F_.assign(n, Matrix::Identity());
    P_.assign(n, Matrix::Zero());
    T h_min = std::numeric_limits<T>::max();
    for (T h : body_.smoothing_length()) h_min = std::min(h_min, h);
    skin_ = T(0.25) * h_min;
    if (corrected()) {
      set_reference(body_.reference_position(), reference_volumes());
      highest_frequency_ = highest_frequency();
    }
  }

  // ---- set-up ----
  /// Holds the particles whose reference position satisfies pred at rest (see SolidBody::clamp_where).
  template <class Predicate>
  std::size_t clamp_where(Predicate&& pred) {
    const std::size_t count = body_.clamp_where(std::forward<Predicate>(pred));
    if (corrected()) highest_frequency_ = highest_frequency();
    return count;
  }
  /// Clamps the particles behind the plane through `point` with normal `normal` (into the free part) by odd
  /// reflection (see SolidBody::clamp_by_reflection): u = 0 on the plane. Returns the number of images.
  std::size_t clamp_by_reflection(const Vector& point, const Vector& normal) {
    const std::size_t count = body_.clamp_by_reflection(point, normal);
    if (corrected()) highest_frequency_ = highest_frequency();
    return count;
  }
  SolidBody<Dim, T>& body_data() noexcept { return body_; }
  const SolidBody<Dim, T>& body_data() const noexcept { return body_; }

  // ---- ParticleModel ----
  /// Publishes density, pressure -tr(sigma)/Dim and the bulk sound speed of the body's particles.
  void compute_rates(System& system, T /*time*/) {
    body_.gather_state(system.particles());
    publish(system.particles());
  }

  T stable_time_step(const System&) const {
    if (params_.sub_cycle) return std::numeric_limits<T>::infinity();
    return solid_time_step() / params_.cfl;
  }

  /// Integrates the body over [time, time + dt] in ceil(dt / solid_time_step()) kick-drift-kick sub-steps,
  /// holding the external acceleration found in the particle set constant.
  void advance(System& system, T time, T dt) {
    auto& p = system.particles();
    body_.gather(p);
    if (!initialised_) {
      body_.reflect_images();
      if (!corrected()) rebuild_pairs();
      internal_acceleration(true);
      initialised_ = true;
    }
    const std::size_t n = body_.size();
    const Vector g = params_.gravity;
    const auto& X = body_.reference_position();
    sub_steps_ += detail::for_each_sub_step(time, dt, solid_time_step(), [&](T h, T t_end) {
      detail::for_each_solid_particle(n, [&](std::size_t k) {
        if (body_.is_clamped(k)) {
          if (body_.is_image(k)) return;
          body_.x[k] = X[k];
          body_.v[k] = Vector::Zero();
          return;
        }
        body_.v[k] += T(0.5) * h * (a_int_[k] + body_.a_ext[k] + g);
        body_.x[k] += h * body_.v[k];
      });
      body_.reflect_images();
      if (!corrected()) refresh_pairs();
      step_ = h;
      deformation_rates();  // at x(t + h) with v(t + h/2)
      for (std::size_t k = 0; k < n; ++k) work_ += h * power_[k];
      detail::for_each_solid_particle(n, [&](std::size_t k) {
        rho_[k] += h * drho_[k];
        S_[k] += h * dS_[k];
      });
      internal_acceleration(false);
      detail::for_each_solid_particle(n, [&](std::size_t k) {
        if (!body_.is_clamped(k)) body_.v[k] += T(0.5) * h * (a_int_[k] + body_.a_ext[k] + g);
      });
      body_.reflect_images();
      check(t_end);
      if (corrected() && params_.reference_update > T(0) && reference_distortion() > params_.reference_update) {
        set_reference(body_.x, reference_volumes());
        ++reference_updates_;
      }
    });
    body_.check_stretch_limit(params_.stretch_limit, time + dt);
    body_.scatter(p);
    publish(p);
  }

  // ---- SolidModel ----
  std::int32_t body() const noexcept { return body_.body(); }
  const std::vector<std::uint32_t>& particle_ids() const noexcept { return body_.particle_ids(); }
  T reference_spacing() const noexcept { return body_.reference_spacing(); }
  const ElasticMaterial<T>& material() const noexcept { return material_; }
  const Parameters& parameters() const noexcept { return params_; }

  /// Stable solid step, s: cfl h_min / (c_p + |v|max); for the corrected formulation also at most
  /// 4 cfl / omega_max (omega_max of the linearised body, see highest_frequency()).
  T solid_time_step() const {
    T v_max = T(0), h_min = std::numeric_limits<T>::max();
    for (std::size_t k = 0; k < body_.size(); ++k) {
      v_max = std::max(v_max, body_.v[k].norm());
      h_min = std::min(h_min, body_.smoothing_length()[k]);
    }
    T rate = material_.p_wave_speed() + v_max;
    if (params_.damping > T(0)) rate = std::max(rate, T(0.5) * params_.damping * h_min);
    if (!corrected()) return params_.cfl * h_min / rate;
    // Velocity Verlet is stable for omega_max dt < 2; held at omega_max dt <= 4 cfl as in the TLSPH model.
    return params_.cfl * std::min(h_min / rate, frequency_step_factor / highest_frequency_);
  }

  /// Cauchy stress -p I + S of a particle (by id), Pa (tension positive; zero at reflected clamp images).
  Matrix cauchy_stress(std::uint32_t id) const {
    const std::size_t k = local(id);
    return stress(k);
  }
  /// Deviatoric stress S of a particle (by id), Pa (in-plane components in 2D).
  const Matrix& deviatoric_stress(std::uint32_t id) const { return S_[local(id)]; }

  T max_stretch() const { return body_.max_stretch(); }
  T kinetic_energy() const { return body_.kinetic_energy(); }
  /// Stored elastic energy sum_a (m_a / rho_a) (S:S / (4 G) + p^2 / (2 K)), J (J/m in 2D; S_zz = -tr S;
  /// reflected clamp images store none).
  T strain_energy() const {
    const T G = material_.shear_modulus(), K = material_.bulk_modulus();
    T e = T(0);
    for (std::size_t k = 0; k < body_.size(); ++k) {
      if (body_.is_image(k)) continue;
      T s2 = S_[k].squaredNorm();
      if constexpr (Dim == 2) s2 += S_[k].trace() * S_[k].trace();
      const T pk = pressure(k);
      e += body_.mass()[k] / rho_[k] * (s2 / (T(4) * G) + pk * pk / (T(2) * K));
    }
    return e;
  }
  /// Work done on the body by its stresses since the start, int sum_a V_a sigma_a : eps_dot_a dt, J (J/m in 2D):
  /// the internal energy the SPH rates actually stored (kinetic + this is conserved up to the artificial terms).
  T stress_work() const noexcept { return work_; }
  std::size_t sub_step_total() const noexcept { return sub_steps_; }
  /// Highest angular frequency of the linearised body used by the step limit, rad/s (0 for the GMS formulation).
  T highest_frequency_estimate() const noexcept { return highest_frequency_; }
  /// Number of reference-configuration updates so far (corrected formulation).
  std::size_t reference_update_count() const noexcept { return reference_updates_; }
  /// Deformation gradient of a particle (by id) relative to the current reference configuration (corrected).
  const Matrix& deformation_gradient(std::uint32_t id) const { return F_[local(id)]; }
  /// Number of particles whose gradient weights are exact for quadratic fields (corrected formulation).
  std::size_t quadratic_particle_count() const {
    std::size_t c = 0;
    for (auto q : quadratic_) c += q;
    return c;
  }

  // ---- checkpoint (io/checkpoint.hpp) ----
  /// Saves the evolved state besides the particle arrays: density, deviatoric stress, the internal acceleration
  /// of the last sub-step (it holds the half-step velocity's viscous terms), the accumulated stress work and the
  /// positions at the last neighbour-list build (GMS formulation: the list is rebuilt from them, so the pair order,
  /// and with it the summation order, is the one of the uninterrupted run), and the reference configuration of
  /// the kernel sums with its volumes (corrected formulation: pairs and weights are rebuilt from them). Clamps and
  /// the frequency estimate are rebuilt by the scene.
  template <class Writer>
  void save_checkpoint(Writer& w) const {
    const auto prefix = fmt::format("updated_lagrangian_solid.{}.", body_.body());
    body_.save_checkpoint_header(w, prefix, initialised_, sub_steps_);
    w.write(prefix + "density", rho_);
    w.write(prefix + "deviatoric_stress", S_);
    w.write(prefix + "internal_acceleration", a_int_);
    w.write(prefix + "stress_work", work_);
    w.write(prefix + "positions_at_list_build", x_at_build_);
    w.write(prefix + "reference_positions", x_ref_);
    w.write(prefix + "reference_volumes", volume_);
    w.write(prefix + "reference_updates", static_cast<std::uint64_t>(reference_updates_));
  }
  /// Restores the state saved by save_checkpoint into a solid built by the same scene (same body and particles).
  template <class Reader>
  void load_checkpoint(Reader& r) {
    const auto prefix = fmt::format("updated_lagrangian_solid.{}.", body_.body());
    const std::size_t n = body_.size();
    bool initialised = false;
    std::size_t sub_steps = 0;
    body_.load_checkpoint_header(r, prefix, initialised, sub_steps);
    r.read_exact(prefix + "density", rho_, n);
    r.read_exact(prefix + "deviatoric_stress", S_, n);
    r.read_exact(prefix + "internal_acceleration", a_int_, n);
    r.read(prefix + "stress_work", work_);
    std::vector<Vector> x_at_build, x_ref;
    std::vector<T> v_ref;
    std::uint64_t updates = 0;
    r.read(prefix + "positions_at_list_build", x_at_build);
    r.read(prefix + "reference_positions", x_ref);
    r.read(prefix + "reference_volumes", v_ref);
    r.read(prefix + "reference_updates", updates);
    initialised_ = initialised;
    sub_steps_ = sub_steps;
    reference_updates_ = static_cast<std::size_t>(updates);
    if (corrected()) {  // the kernel sums of the saved reference configuration (weights recomputed bit-identically)
      if (x_ref.size() != n || v_ref.size() != n)
        r.fail(
            fmt::format("'{}reference_positions' or '{}reference_volumes' has the wrong length (the checkpoint "
                        "was written with the other formulation?)",
                        prefix, prefix));
      set_reference(x_ref, v_ref);
    } else if (initialised_) {
      if (x_at_build.size() != n) r.fail(fmt::format("'{}positions_at_list_build' has the wrong length", prefix));
      x_at_build_ = std::move(x_at_build);
      set_pairs(detail::build_pair_list<Dim, T>(x_at_build_, body_.smoothing_length(), static_cast<T>(Kernel::support),
                                                skin_));
    }
  }

 private:
  bool corrected() const noexcept { return params_.formulation == UpdatedLagrangianFormulation::corrected; }
  std::size_t local(std::uint32_t id) const {
    const auto k = body_.local_index(id);
    if (k < 0) throw InputError(fmt::format("particle id {} is not in solid body {}", id, body_.body()));
    return static_cast<std::size_t>(k);
  }
  T pressure(std::size_t k) const {
    if (body_.is_image(k)) return T(0);
    const T c0 = material_.sound_speed();
    return c0 * c0 * (rho_[k] - material_.density);
  }
  Matrix stress(std::size_t k) const { return S_[k] - pressure(k) * Matrix::Identity(); }

  void rebuild_pairs() {
    set_pairs(
        detail::build_pair_list<Dim, T>(body_.x, body_.smoothing_length(), static_cast<T>(Kernel::support), skin_));
    x_at_build_ = body_.x;
  }
  /// Installs a Verlet list: per-pair storage and the index of the pair (b, a) of each pair (a, b).
  void set_pairs(detail::PairList list) {
    pairs_ = std::move(list);
    const std::size_t m = pairs_.neighbor.size();
    reverse_.resize(m);
    grad_.assign(m, Vector::Zero());
    w_.assign(m, T(0));
    weight_.assign(m, Vector::Zero());
    for (std::size_t a = 0; a < pairs_.size(); ++a)
      for (std::uint32_t k = pairs_.offset[a]; k < pairs_.offset[a + 1]; ++k) {
        const std::uint32_t b = pairs_.neighbor[k];
        std::uint32_t back = pairs_.offset[b];  // the list is symmetric: (b, a) exists
        while (back < pairs_.offset[b + 1] && pairs_.neighbor[back] != a) ++back;
        reverse_[k] = back;
      }
  }
  /// Rebuilds the Verlet list once a particle moved more than half the skin since the last build.
  void refresh_pairs() {
    T d2 = T(0);
    for (std::size_t k = 0; k < body_.size(); ++k) d2 = std::max(d2, (body_.x[k] - x_at_build_[k]).squaredNorm());
    if (d2 > T(0.25) * skin_ * skin_) rebuild_pairs();
  }

  /// Calls f(b, dx, r, h_ab) for the current neighbours b of a within the kernel support.
  template <class F>
  void for_each_neighbor(std::size_t a, F&& f) const {
    const auto& x = body_.x;
    const auto& hs = body_.smoothing_length();
    constexpr T support = static_cast<T>(Kernel::support);
    pairs_.for_each(a, [&](std::uint32_t b) {
      const Vector dx = x[a] - x[b];
      const T hab = T(0.5) * (hs[a] + hs[b]);
      const T r2 = dx.squaredNorm();
      if (r2 < support * support * hab * hab) f(b, dx, std::sqrt(r2), hab);
    });
  }

  /// Corrected formulation: installs x_ref (with volumes V_ref) as the reference configuration of the kernel
  /// sums: the pairs within the support there, the kernel values and gradients, and the gradient weights g_ab
  /// (exact for quadratic fields where the neighbours determine a quadratic, else Bonet-Lok). F becomes I.
  void set_reference(const std::vector<Vector>& x_ref, const std::vector<T>& v_ref) {
    const std::size_t n = body_.size();
    const auto& hs = body_.smoothing_length();
    x_ref_ = x_ref;
    volume_ = v_ref;
    set_pairs(detail::build_pair_list<Dim, T>(x_ref_, hs, static_cast<T>(Kernel::support), T(0)));
    quadratic_.assign(n, 0);
    detail::for_each_solid_particle(n, [&](std::size_t a) {
      for (std::uint32_t k = pairs_.offset[a]; k < pairs_.offset[a + 1]; ++k) {
        const std::uint32_t b = pairs_.neighbor[k];
        const Vector dx = x_ref_[a] - x_ref_[b];
        const T hab = T(0.5) * (hs[a] + hs[b]);
        const T r = dx.norm();
        grad_[k] = kernel_gradient(kernel_, dx, r, hab);
        w_[k] = kernel_.value(r, hab);
      }
      Matrix moment = Matrix::Zero();
      for (std::uint32_t k = pairs_.offset[a]; k < pairs_.offset[a + 1]; ++k)
        moment += volume_[pairs_.neighbor[k]] * (x_ref_[pairs_.neighbor[k]] - x_ref_[a]) * grad_[k].transpose();
      // An isolated or collinear particle (det ~ 0) keeps the plain kernel gradient.
      const Matrix correction =
          std::abs(moment.determinant()) > T(1e-3) ? Matrix(moment.inverse().transpose()) : Matrix(Matrix::Identity());
      for (std::uint32_t k = pairs_.offset[a]; k < pairs_.offset[a + 1]; ++k) weight_[k] = correction * grad_[k];
      if (params_.quadratic_correction)
        quadratic_[a] = detail::quadratic_gradient_weights<Dim, T>(a, pairs_, x_ref_, volume_, hs[a], grad_, w_,
                                                                   weight_, quadratic_condition_limit);
    });
    F_.assign(n, Matrix::Identity());
  }
  /// Volumes m / rho of the current state, m^Dim (the reference volumes of a new reference configuration).
  std::vector<T> reference_volumes() const {
    std::vector<T> v(body_.size());
    for (std::size_t k = 0; k < body_.size(); ++k) v[k] = body_.mass()[k] / rho_[k];
    return v;
  }
  /// Largest |F - I| (Frobenius) over the body: the distortion since the last reference configuration.
  T reference_distortion() const {
    T d = T(0);
    for (const auto& F : F_) d = std::max(d, (F - Matrix::Identity()).norm());
    return d;
  }

  /// Corrected gradient sum_b V_b (f_b - f_a) (x) g_ab of a vector field at particle a, over the reference pairs.
  Matrix corrected_gradient(std::size_t a, const std::vector<Vector>& f) const {
    Matrix G = Matrix::Zero();
    for (std::uint32_t k = pairs_.offset[a]; k < pairs_.offset[a + 1]; ++k) {
      const std::uint32_t b = pairs_.neighbor[k];
      G += volume_[b] * (f[b] - f[a]) * weight_[k].transpose();
    }
    return G;
  }

  /// Corrected stress force on particle a, sum_b V_a V_b (P_a g_ab - P_b g_ba), N (N/m in 2D).
  template <class Stress>
  Vector corrected_stress_force(std::size_t a, const Stress& P) const {
    Vector f = Vector::Zero();
    const Matrix pa = P(a);
    for (std::uint32_t k = pairs_.offset[a]; k < pairs_.offset[a + 1]; ++k) {
      const std::uint32_t b = pairs_.neighbor[k];
      f += volume_[a] * volume_[b] * (pa * weight_[k] - P(b) * weight_[reverse_[k]]);
    }
    return f;
  }

  /// drho/dt and dS/dt (GMS 2001 eqs 2.3, 2.5-2.7) at the current positions and velocities; the corrected
  /// formulation also updates F.
  void deformation_rates() {
    const auto& v = body_.v;
    const auto& m = body_.mass();
    const T G = material_.shear_modulus();
    const bool consistent = corrected();
    detail::for_each_solid_particle(body_.size(), [&](std::size_t a) {
      Matrix L = Matrix::Zero();
      T drho = T(0);
      if (consistent) {
        F_[a] = corrected_gradient(a, body_.x);
        L = corrected_gradient(a, v) * F_[a].inverse();  // dF/dt F^-1
        // Continuity in Lagrangian form, rho = m / (V_ref det F) (images keep V_ref: no stress, no volume change);
        // written as a rate over the sub-step so both formulations share the update.
        const T J = body_.is_image(a) ? T(1) : F_[a].determinant();
        drho = (m[a] / (volume_[a] * J) - rho_[a]) / step_;
      } else {
        for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T hab) {
          const Vector grad = kernel_gradient(kernel_, dx, r, hab);
          const Vector v_ba = v[b] - v[a];
          drho -= m[b] * v_ba.dot(grad);
          L += m[b] / rho_[b] * v_ba * grad.transpose();
        });
      }
      const Matrix eps_dot = T(0.5) * (L + L.transpose());
      const Matrix omega = T(0.5) * (L - L.transpose());
      drho_[a] = drho;
      power_[a] = m[a] / rho_[a] * (stress(a).cwiseProduct(eps_dot)).sum();
      dS_[a] = body_.is_image(a) ? Matrix(Matrix::Zero())  // images carry no stress of their own
                                 : Matrix(T(2) * G * (eps_dot - eps_dot.trace() / T(3) * Matrix::Identity()) +
                                          omega * S_[a] - S_[a] * omega);
    });
  }

  /// Internal acceleration (GMS 2001 eq. 2.2, or the corrected stress force with hourglass control, with the
  /// artificial stress and viscosity) and damping; forces on reflected clamp images act on their mirrors
  /// reversed. The corrected formulation uses F from deformation_rates() at the same positions unless new_F.
  void internal_acceleration(bool new_F = false) {
    const std::size_t n = body_.size();
    const auto& v = body_.v;
    const auto& m = body_.mass();
    const auto& hs = body_.smoothing_length();
    const T eps = params_.artificial_stress, n_exp = params_.artificial_stress_exponent;
    const T alpha = params_.artificial_viscosity, beta = params_.artificial_viscosity_beta;
    const T c0 = material_.sound_speed(), c_d = params_.damping, dp = body_.reference_spacing();
    const bool consistent = corrected();
    const T alpha_hg = consistent ? params_.hourglass * material_.youngs_modulus : T(0);
    constexpr T support = static_cast<T>(Kernel::support);
    detail::for_each_solid_particle(n, [&](std::size_t a) {
      if (consistent) {
        if (new_F) F_[a] = corrected_gradient(a, body_.x);
        P_[a] = F_[a].determinant() * stress(a) * F_[a].inverse().transpose();  // J sigma F^-T (zero at images)
      }
      R_[a] = Matrix::Zero();
      if (eps <= T(0)) return;
      const Matrix sigma = stress(a) / (rho_[a] * rho_[a]);
      Eigen::SelfAdjointEigenSolver<Matrix> eig;
      eig.computeDirect(sigma);
      Vector r = Vector::Zero();
      for (int d = 0; d < Dim; ++d) r[d] = eig.eigenvalues()[d] > T(0) ? -eps * eig.eigenvalues()[d] : T(0);
      R_[a] = eig.eigenvectors() * r.asDiagonal() * eig.eigenvectors().transpose();
    });
    // Artificial stress and viscosity of the pair (a, b) with current kernel gradient grad and value w.
    auto artificial = [&](std::size_t a, std::size_t b, const Vector& dx, T r, T hab, const Vector& grad, T w) {
      Matrix bracket = Matrix::Zero();
      if (eps > T(0)) bracket += (R_[a] + R_[b]) * tensile_weight(w / kernel_.value(dp, hab), n_exp);
      const T vr = (v[a] - v[b]).dot(dx);
      if (vr < T(0) && (alpha > T(0) || beta > T(0))) {
        const T mu = hab * vr / (r * r + T(0.01) * hab * hab);
        bracket -= ((-alpha * c0 * mu + beta * mu * mu) / (T(0.5) * (rho_[a] + rho_[b]))) * Matrix::Identity();
      }
      return Vector(m[b] * (bracket * grad));
    };
    detail::for_each_solid_particle(n, [&](std::size_t a) {
      Vector acc = Vector::Zero();
      if (consistent) {
        Vector force = corrected_stress_force(a, [&](std::size_t k) { return P_[k]; });
        for (std::uint32_t k = pairs_.offset[a]; k < pairs_.offset[a + 1]; ++k) {
          const std::uint32_t b = pairs_.neighbor[k];
          const Vector dx = body_.x[a] - body_.x[b];
          const T r = dx.norm();
          if (!(r > T(0))) continue;
          if (alpha_hg > T(0) && !body_.is_image(a) && !body_.is_image(b)) {  // as in the TLSPH model
            const Vector e = -dx / r;
            const Vector X_ba = x_ref_[b] - x_ref_[a];
            const T r0 = X_ba.norm();
            const T delta = ((T(0.5) * (F_[a] + F_[b]) * X_ba + dx).dot(e)) / r0;
            force -= (alpha_hg * volume_[a] * volume_[b] * w_[k] * delta / r0) * e;
          }
          const T hab = T(0.5) * (hs[a] + hs[b]);
          if ((eps > T(0) || alpha > T(0) || beta > T(0)) && r < support * hab)
            acc += artificial(a, b, dx, r, hab, kernel_gradient(kernel_, dx, r, hab), kernel_.value(r, hab));
        }
        acc += force / m[a];
      } else {
        const Matrix sa = stress(a) / (rho_[a] * rho_[a]);
        for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T hab) {
          const Vector grad = kernel_gradient(kernel_, dx, r, hab);
          acc += m[b] * ((sa + stress(b) / (rho_[b] * rho_[b])) * grad) +
                 artificial(a, b, dx, r, hab, grad, kernel_.value(r, hab));
        });
      }
      a_int_[a] = acc - c_d * v[a];
    });
    for (std::size_t g = 0; g < n; ++g)  // the image moves with minus its mirror's displacement
      if (body_.is_image(g)) {
        const auto k = static_cast<std::size_t>(body_.mirror(g));
        a_int_[k] -= (a_int_[g] + c_d * v[g]) * (m[g] / m[k]);
      }
  }

  /// Highest angular frequency of the body linearised about the reference configuration with the corrected
  /// weights, rad/s: sqrt of the largest eigenvalue of M^-1 K by power iteration (100 products; a deterministic
  /// start). The linear stress of a displacement u is sigma = lambda tr(eps) I + 2 G eps, eps = sym(grad u), which
  /// is what the rates give for small strains (p = -K tr eps, S = 2 G dev eps); held particles do not move and
  /// images move as minus their mirrors. (The hourglass penalty adds about alpha_hg of the stiffness.)
  T highest_frequency() const {
    const std::size_t n = body_.size();
    const auto& m = body_.mass();
    const T lambda = material_.lame_lambda(), G = material_.shear_modulus();
    std::vector<Vector> u(n), force(n);
    std::vector<Matrix> sigma(n);
    for (std::size_t k = 0; k < n; ++k)
      for (int d = 0; d < Dim; ++d) u[k][d] = std::sin(T(12.9898) * T(k) + T(78.233) * T(d + 1));
    T eigenvalue = T(0);
    for (int iteration = 0; iteration < 100; ++iteration) {
      for (std::size_t k = 0; k < n; ++k)
        if (body_.is_image(k)) u[k] = -u[static_cast<std::size_t>(body_.mirror(k))];
        else if (body_.is_clamped(k)) u[k].setZero();
      T norm = T(0);
      for (const auto& uk : u) norm += uk.squaredNorm();
      norm = std::sqrt(norm);
      for (auto& uk : u) uk /= norm;
      for (std::size_t k = 0; k < n; ++k) {
        const Matrix grad_u = corrected_gradient(k, u);
        const Matrix e = T(0.5) * (grad_u + grad_u.transpose());
        sigma[k] =
            body_.is_image(k) ? Matrix(Matrix::Zero()) : Matrix(lambda * e.trace() * Matrix::Identity() + T(2) * G * e);
      }
      for (std::size_t k = 0; k < n; ++k) force[k] = corrected_stress_force(k, [&](std::size_t j) { return sigma[j]; });
      for (std::size_t g = 0; g < n; ++g)
        if (body_.is_image(g)) force[static_cast<std::size_t>(body_.mirror(g))] -= force[g];
      T image = T(0);
      for (std::size_t k = 0; k < n; ++k) {
        u[k] = force[k] / m[k];
        if (!body_.is_clamped(k)) image += u[k].squaredNorm();
      }
      eigenvalue = std::sqrt(image);
    }
    return std::sqrt(eigenvalue);
  }
  static constexpr T quadratic_condition_limit = T(1e-6);
  static constexpr T frequency_step_factor = T(4);  // omega_max dt <= 4 cfl (1.2 at cfl 0.3; the limit is 2)

  /// f^n, with repeated multiplication for the usual integer exponents.
  static T tensile_weight(T f, T n) {
    if (n == T(4)) {
      const T f2 = f * f;
      return f2 * f2;
    }
    return std::pow(f, n);
  }

  void check(T time) const {
    body_.check_finite(time);  // first: a bad position or velocity is the origin, bad stresses follow from it
    for (std::size_t k = 0; k < body_.size(); ++k) {
      if (!std::isfinite(rho_[k]) || !(rho_[k] > T(0))) body_.throw_blow_up(k, "density", time);
      if (!S_[k].allFinite()) body_.throw_blow_up(k, "stress (deviatoric)", time);
    }
  }

  void publish(ParticleSet<Dim, T>& p) const {
    const T c0 = material_.sound_speed();
    const auto& ids = body_.particle_ids();
    for (std::size_t k = 0; k < body_.size(); ++k) {
      const std::size_t i = p.slot_of_id(ids[k]);
      p.density[i] = rho_[k];
      p.pressure[i] = -stress(k).trace() / T(Dim);
      p.sound_speed[i] = c0;
    }
  }

  ElasticMaterial<T> material_;
  Parameters params_;
  Kernel kernel_;
  SolidBody<Dim, T> body_;
  std::vector<T> rho_, drho_, power_;  // density (kg/m^3), its rate, stress power V sigma:eps_dot (W)
  std::vector<T> volume_;              // V_ref = m / rho at the reference configuration, m^Dim (corrected)
  T work_{0};                          // accumulated stress work sum_a int V_a sigma_a:eps_dot_a dt, J
  std::vector<Matrix> S_, dS_, R_;     // deviatoric stress (Pa), its rate, artificial stress (Pa m^6/kg^2)
  std::vector<Matrix> F_, P_;          // deformation gradient since the reference, J sigma F^-T (Pa) (corrected)
  std::vector<Vector> x_ref_;          // reference configuration of the kernel sums (corrected), m
  std::size_t reference_updates_{0};
  T step_{1};                            // the current sub-step, s
  std::vector<Vector> a_int_;            // internal acceleration, m/s^2
  detail::PairList pairs_;               // pairs of x_ref (corrected) or Verlet list of the current positions (GMS)
  std::vector<std::uint32_t> reverse_;   // index of the pair (b, a) of each pair (a, b)
  std::vector<Vector> grad_;             // kernel gradient grad_a W_ab per pair on x_ref, 1/m^(Dim+1)
  std::vector<T> w_;                     // kernel value per pair on x_ref, 1/m^Dim
  std::vector<Vector> weight_;           // corrected gradient weight g_ab per pair, 1/m^(Dim+1)
  std::vector<std::uint8_t> quadratic_;  // 1 where the weights are exact for quadratic fields (on x_ref)
  std::vector<Vector> x_at_build_;
  T skin_{0};
  T highest_frequency_{0};  // omega_max of the linearised body (corrected formulation), rad/s
  std::size_t sub_steps_{0};
  bool initialised_{false};
};

}  // namespace sphfsi
