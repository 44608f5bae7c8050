// sphfsi: updated-Lagrangian elastic SPH solid, the reference paper's eq. (13) solid (Gray, Monaghan & Swift 2001,
// CMAME 190:6641; the SPHysics solid). Sums run over the current neighbours of the same body; for a particle a
// and neighbour b, grad = grad_a W(|x_a - x_b|, h_ab), V_b = m_b / rho_b, v_ba = v_b - v_a:
//   continuity          drho_a/dt = sum_b m_b (v_a - v_b) . grad                                  (GMS 2001, 2.3)
//   velocity gradient   L_a = [ sum_b V_b v_ba (x) grad ] C_a,   C_a = [ sum_b V_b x_ba (x) grad ]^-1 or I
//   strain rate, spin   eps_dot = (L + L^T) / 2,   Omega = (L - L^T) / 2                        (GMS 2001, 2.6-2.7)
//   Hooke + Jaumann     dS/dt = 2 G (eps_dot - tr(eps_dot) I / 3) + Omega S - S Omega            (GMS 2001, 2.5)
//   pressure            p = c0^2 (rho - rho0),  c0^2 = K / rho0,   sigma = -p I + S              (GMS 2001, 2.10)
//   momentum            dv_a/dt = sum_b m_b (sigma_a/rho_a^2 + sigma_b/rho_b^2 + (R_a + R_b) f_ab^n - Pi_ab I) . grad
//                                 + g + a_ext - c_d v_a                                            (GMS 2001, 2.2)
//   artificial stress   R_a = Q diag(-eps max(sigma'_i, 0) / rho_a^2) Q^T in the principal frame of sigma_a,
//                       f_ab = W(r_ab) / W(dp)                                   (Monaghan 2000, JCP 159:290; GMS 3.6)
//   artificial visc.    Pi_ab = (-alpha c0 mu_ab + beta mu_ab^2) / rho_ab,  mu_ab = h v_ab.x_ab / (r^2 + 0.01 h^2)
//                       when v_ab . x_ab < 0                                               (Monaghan 1992, 4.1)
// With the optional correction C_a (Randles & Libersky 1996, CMAME 139:375; Bonet & Lok 1999) the velocity
// gradient is exact for affine motions, so a rigid rotation produces no strain rate even at free surfaces; without
// it the scheme is the original GMS 2001 one. The 3D deviator (the 1/3 above) with in-plane components is plane
// strain in 2D (S_zz = -tr S). Time stepping: kick-drift-kick (velocity Verlet; density and stress updated at the
// mid-point positions), sub-cycled inside a fluid step with the P-wave CFL step.
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
#include <limits>
#include <vector>

namespace sphfsi {

/// Parameters of an UpdatedLagrangianSolid (designated initialisers; validated by the model's constructor).
template <int Dim, Real T>
struct UpdatedLagrangianParameters {
  Vec<Dim, T> gravity = standard_gravity<Dim, T>();  ///< body force per unit mass, m/s^2
  T cfl{T(0.3)};                                     ///< solid step = cfl h / (c_p + |v|max), (0, 1]
  bool sub_cycle{true};                    ///< true: advance() sub-cycles and the solid does not limit the fluid step
  T artificial_viscosity{T(0.5)};          ///< alpha, [0, 5]
  T artificial_viscosity_beta{T(0)};       ///< beta, [0, 5]
  T artificial_stress{T(0.3)};             ///< epsilon of Monaghan's artificial stress, [0, 1] (0: off)
  T artificial_stress_exponent{T(4)};      ///< n of f_ab^n, [1, 10]
  bool corrected_velocity_gradient{true};  ///< kernel-gradient correction of L (false: original GMS 2001)
  T damping{T(0)};                         ///< c_d, mass-proportional velocity damping, 1/s, >= 0
  T stretch_limit{T(0)};                   ///< stop with BlowUpError when max_stretch() exceeds this (0: off), else > 1

  void validate() const {
    for (int d = 0; d < Dim; ++d) require_finite("UpdatedLagrangianParameters::gravity (m/s^2)", gravity[d]);
    require_in_range("UpdatedLagrangianParameters::cfl", cfl, T(1e-6), T(1));
    require_in_range("UpdatedLagrangianParameters::artificial_viscosity (alpha)", artificial_viscosity, T(0), T(5));
    require_in_range("UpdatedLagrangianParameters::artificial_viscosity_beta (beta)", artificial_viscosity_beta, T(0),
                     T(5));
    require_in_range("UpdatedLagrangianParameters::artificial_stress (epsilon)", artificial_stress, T(0), T(1));
    require_in_range("UpdatedLagrangianParameters::artificial_stress_exponent (n)", artificial_stress_exponent, T(1),
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
    T h_min = std::numeric_limits<T>::max();
    for (T h : body_.smoothing_length()) h_min = std::min(h_min, h);
    skin_ = T(0.25) * h_min;
  }

  // ---- set-up ----
  template <class Predicate>
  std::size_t clamp_where(Predicate&& pred) {
    return body_.clamp_where(std::forward<Predicate>(pred));
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
      rebuild_pairs();
      internal_acceleration();
      initialised_ = true;
    }
    const std::size_t n_sub = detail::sub_step_count(dt, solid_time_step());
    const T h = dt / T(n_sub);
    const std::size_t n = body_.size();
    const Vector g = params_.gravity;
    const auto& X = body_.reference_position();
    for (std::size_t s = 0; s < n_sub; ++s) {
      detail::for_each_solid_particle(n, [&](std::size_t k) {
        if (body_.is_clamped(k)) {
          body_.x[k] = X[k];
          body_.v[k] = Vector::Zero();
          return;
        }
        body_.v[k] += T(0.5) * h * (a_int_[k] + body_.a_ext[k] + g);
        body_.x[k] += T(0.5) * h * body_.v[k];
      });
      refresh_pairs();
      deformation_rates();
      for (std::size_t k = 0; k < n; ++k) work_ += h * power_[k];
      detail::for_each_solid_particle(n, [&](std::size_t k) {
        rho_[k] += h * drho_[k];
        S_[k] += h * dS_[k];
        if (!body_.is_clamped(k)) body_.x[k] += T(0.5) * h * body_.v[k];
      });
      refresh_pairs();
      internal_acceleration();
      detail::for_each_solid_particle(n, [&](std::size_t k) {
        if (!body_.is_clamped(k)) body_.v[k] += T(0.5) * h * (a_int_[k] + body_.a_ext[k] + g);
      });
      check(time + T(s + 1) * h);
    }
    sub_steps_ += n_sub;
    if (params_.stretch_limit > T(0)) {
      const T st = body_.max_stretch();
      if (st > params_.stretch_limit)
        throw BlowUpError(
            fmt::format("solid body {} at t = {:.6g} s: largest stretch between initially "
                        "neighbouring particles is {:.4g} > stretch_limit = {:.4g} (the body tore)",
                        body_.body(), time + dt, st, params_.stretch_limit));
    }
    body_.scatter(p);
    publish(p);
  }

  // ---- SolidModel ----
  std::int32_t body() const noexcept { return body_.body(); }
  const std::vector<std::uint32_t>& particle_ids() const noexcept { return body_.particle_ids(); }
  T reference_spacing() const noexcept { return body_.reference_spacing(); }
  const ElasticMaterial<T>& material() const noexcept { return material_; }
  const Parameters& parameters() const noexcept { return params_; }

  /// Stable solid step cfl h_min / (c_p + |v|max), s.
  T solid_time_step() const {
    T v_max = T(0), h_min = std::numeric_limits<T>::max();
    for (std::size_t k = 0; k < body_.size(); ++k) {
      v_max = std::max(v_max, body_.v[k].norm());
      h_min = std::min(h_min, body_.smoothing_length()[k]);
    }
    T rate = material_.p_wave_speed() + v_max;
    if (params_.damping > T(0)) rate = std::max(rate, T(0.5) * params_.damping * h_min);
    return params_.cfl * h_min / rate;
  }

  /// Cauchy stress -p I + S of a particle (by id), Pa (tension positive).
  Matrix cauchy_stress(std::uint32_t id) const {
    const std::size_t k = local(id);
    return stress(k);
  }
  /// Deviatoric stress S of a particle (by id), Pa (in-plane components in 2D).
  const Matrix& deviatoric_stress(std::uint32_t id) const { return S_[local(id)]; }

  T max_stretch() const { return body_.max_stretch(); }
  T kinetic_energy() const { return body_.kinetic_energy(); }
  /// Stored elastic energy sum_a (m_a / rho_a) (S:S / (4 G) + p^2 / (2 K)), J (J/m in 2D; S_zz = -tr S).
  T strain_energy() const {
    const T G = material_.shear_modulus(), K = material_.bulk_modulus();
    T e = T(0);
    for (std::size_t k = 0; k < body_.size(); ++k) {
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

  // ---- checkpoint (io/checkpoint.hpp) ----
  /// Saves the evolved state besides the particle arrays: density, deviatoric stress, the internal acceleration
  /// of the last sub-step (it holds the half-step velocity's viscous terms), the accumulated stress work and the
  /// positions at the last neighbour-list build (the list is rebuilt from them, so the pair order, and with it
  /// the summation order, is the one of the uninterrupted run).
  template <class Writer>
  void save_checkpoint(Writer& w) const {
    const auto prefix = fmt::format("updated_lagrangian_solid.{}.", body_.body());
    w.write(prefix + "particle_count", static_cast<std::uint64_t>(body_.size()));
    w.write(prefix + "initialised", static_cast<std::uint8_t>(initialised_ ? 1 : 0));
    w.write(prefix + "sub_steps", static_cast<std::uint64_t>(sub_steps_));
    w.write(prefix + "density", rho_);
    w.write(prefix + "deviatoric_stress", S_);
    w.write(prefix + "internal_acceleration", a_int_);
    w.write(prefix + "stress_work", work_);
    w.write(prefix + "positions_at_list_build", x_at_build_);
  }
  /// Restores the state saved by save_checkpoint into a solid built by the same scene (same body and particles).
  template <class Reader>
  void load_checkpoint(Reader& r) {
    const auto prefix = fmt::format("updated_lagrangian_solid.{}.", body_.body());
    const std::size_t n = body_.size();
    std::uint64_t count = 0, sub_steps = 0;
    std::uint8_t initialised = 0;
    r.read(prefix + "particle_count", count);
    if (count != n)
      r.fail(fmt::format("solid body {} was saved with {} particles, this scene built {}", body_.body(), count, n));
    r.read(prefix + "initialised", initialised);
    r.read(prefix + "sub_steps", sub_steps);
    r.read_exact(prefix + "density", rho_, n);
    r.read_exact(prefix + "deviatoric_stress", S_, n);
    r.read_exact(prefix + "internal_acceleration", a_int_, n);
    r.read(prefix + "stress_work", work_);
    std::vector<Vector> x_at_build;
    r.read(prefix + "positions_at_list_build", x_at_build);
    initialised_ = initialised != 0;
    sub_steps_ = static_cast<std::size_t>(sub_steps);
    if (initialised_) {
      if (x_at_build.size() != n) r.fail(fmt::format("'{}positions_at_list_build' has the wrong length", prefix));
      x_at_build_ = std::move(x_at_build);
      pairs_ = detail::build_pair_list<Dim, T>(x_at_build_, body_.smoothing_length(), static_cast<T>(Kernel::support),
                                               skin_);
    }
  }

 private:
  std::size_t local(std::uint32_t id) const {
    const auto k = body_.local_index(id);
    if (k < 0) throw InputError(fmt::format("particle id {} is not in solid body {}", id, body_.body()));
    return static_cast<std::size_t>(k);
  }
  T pressure(std::size_t k) const {
    const T c0 = material_.sound_speed();
    return c0 * c0 * (rho_[k] - material_.density);
  }
  Matrix stress(std::size_t k) const { return S_[k] - pressure(k) * Matrix::Identity(); }

  void rebuild_pairs() {
    pairs_ = detail::build_pair_list<Dim, T>(body_.x, body_.smoothing_length(), static_cast<T>(Kernel::support), skin_);
    x_at_build_ = body_.x;
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

  /// drho/dt and dS/dt (GMS 2001 eqs 2.3, 2.5-2.7) at the current positions and velocities.
  void deformation_rates() {
    const auto& v = body_.v;
    const auto& m = body_.mass();
    const T G = material_.shear_modulus();
    const bool corrected = params_.corrected_velocity_gradient;
    detail::for_each_solid_particle(body_.size(), [&](std::size_t a) {
      Matrix L = Matrix::Zero(), C = Matrix::Zero();
      T drho = T(0);
      for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T hab) {
        const Vector grad = kernel_gradient(kernel_, dx, r, hab);
        const T Vb = m[b] / rho_[b];
        const Vector v_ba = v[b] - v[a];
        drho -= m[b] * v_ba.dot(grad);
        L += Vb * v_ba * grad.transpose();
        if (corrected) C -= Vb * dx * grad.transpose();  // x_ba = -dx
      });
      if (corrected && std::abs(C.determinant()) > T(1e-3)) L = L * C.inverse();
      const Matrix eps_dot = T(0.5) * (L + L.transpose());
      const Matrix omega = T(0.5) * (L - L.transpose());
      drho_[a] = drho;
      power_[a] = m[a] / rho_[a] * (stress(a).cwiseProduct(eps_dot)).sum();
      dS_[a] = T(2) * G * (eps_dot - eps_dot.trace() / T(3) * Matrix::Identity()) + omega * S_[a] - S_[a] * omega;
    });
  }

  /// Internal acceleration (GMS 2001 eq. 2.2 with artificial stress and viscosity) and damping.
  void internal_acceleration() {
    const std::size_t n = body_.size();
    const auto& v = body_.v;
    const auto& m = body_.mass();
    const T eps = params_.artificial_stress, n_exp = params_.artificial_stress_exponent;
    const T alpha = params_.artificial_viscosity, beta = params_.artificial_viscosity_beta;
    const T c0 = material_.sound_speed(), c_d = params_.damping, dp = body_.reference_spacing();
    detail::for_each_solid_particle(n, [&](std::size_t a) {
      R_[a] = Matrix::Zero();
      if (eps <= T(0)) return;
      const Matrix sigma = stress(a) / (rho_[a] * rho_[a]);
      Eigen::SelfAdjointEigenSolver<Matrix> eig;
      eig.computeDirect(sigma);
      Vector r = Vector::Zero();
      for (int d = 0; d < Dim; ++d) r[d] = eig.eigenvalues()[d] > T(0) ? -eps * eig.eigenvalues()[d] : T(0);
      R_[a] = eig.eigenvectors() * r.asDiagonal() * eig.eigenvectors().transpose();
    });
    detail::for_each_solid_particle(n, [&](std::size_t a) {
      const Matrix sa = stress(a) / (rho_[a] * rho_[a]);
      Vector acc = Vector::Zero();
      for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T hab) {
        const Vector grad = kernel_gradient(kernel_, dx, r, hab);
        Matrix bracket = sa + stress(b) / (rho_[b] * rho_[b]);
        if (eps > T(0))
          bracket += (R_[a] + R_[b]) * tensile_weight(kernel_.value(r, hab) / kernel_.value(dp, hab), n_exp);
        const T vr = (v[a] - v[b]).dot(dx);
        if (vr < T(0) && (alpha > T(0) || beta > T(0))) {
          const T mu = hab * vr / (r * r + T(0.01) * hab * hab);
          bracket -= ((-alpha * c0 * mu + beta * mu * mu) / (T(0.5) * (rho_[a] + rho_[b]))) * Matrix::Identity();
        }
        acc += m[b] * (bracket * grad);
      });
      a_int_[a] = acc - c_d * v[a];
    });
  }

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
  T work_{0};                          // accumulated stress work sum_a int V_a sigma_a:eps_dot_a dt, J
  std::vector<Matrix> S_, dS_, R_;     // deviatoric stress (Pa), its rate, artificial stress (m^2/s^2... /rho^2)
  std::vector<Vector> a_int_;          // internal acceleration, m/s^2
  detail::PairList pairs_;
  std::vector<Vector> x_at_build_;
  T skin_{0};
  std::size_t sub_steps_{0};
  bool initialised_{false};
};

}  // namespace sphfsi
