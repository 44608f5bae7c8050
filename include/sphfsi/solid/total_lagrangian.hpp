// sphfsi: total-Lagrangian SPH elastic solid with kernel-gradient correction and hourglass control.
//
// All sums run over the neighbours of the reference configuration X (Ganzenmueller 2015, CMAME 286:87;
// Zhang, Rezavand & Hu 2021, J. Comput. Phys. 429:110028, the SPHinXsys solid). With V0_b = m_b / rho0,
// grad0_ab = grad_a W(|X_a - X_b|, h_ab) and X_ba = X_b - X_a, x_ba = x_b - x_a:
//   correction        B_a  = [ sum_b V0_b X_ba (x) grad0_ab ]^-1           (Bonet & Lok 1999, CMAME 180:97)
//   deformation grad. F_a  = [ sum_b V0_b x_ba (x) grad0_ab ] B_a            (exact for any affine motion)
//   Green strain      E_a  = (F_a^T F_a - I) / 2
//   Saint Venant-Kirchhoff   S_a = lambda tr(E_a) I + 2 G E_a,   P_a = F_a S_a   (first Piola-Kirchhoff)
//   momentum          m_a dv_a/dt = sum_b V0_a V0_b (P_a B_a^T + P_b B_b^T) grad0_ab + hourglass + viscosity
//                     + m_a (g + a_ext) - m_a c_d v_a
// The momentum equation is the gradient of the discrete strain energy sum_a V0_a Psi(F_a) with
// Psi = lambda/2 tr(E)^2 + G E:E (Ganzenmueller 2015, sec. 2), so linear and angular momentum are conserved
// and a rigid rotation (F = R, E = 0) gives no stress. 2D is plane strain (3D lambda and G).
// Hourglass control (zero-energy modes of the collocated gradient; Ganzenmueller 2015, sec. 3, written here
// per pair and along the current bond so both momenta stay conserved): the mismatch between the bond the
// averaged deformation gradient predicts and the actual bond,
//   delta_ab = ((F_a + F_b)/2 X_ba - x_ba) . e_ab / |X_ba|,   e_ab = x_ba / |x_ba|,
// is penalised with f_a = -alpha_hg E V0_a V0_b W0_ab delta_ab / |X_ba| e_ab (f_b = -f_a).
// Optional Monaghan (1992) artificial viscosity on the current bond and a mass-proportional damping c_d
// (for static equilibria: the cantilever under its own weight).
// Time stepping: velocity Verlet (kick-drift-kick) with the P-wave CFL step, sub-cycled inside a fluid step.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>
#include <sphfsi/solid/body.hpp>
#include <sphfsi/solid/elastic_material.hpp>

#include <Eigen/LU>

#include <cmath>
#include <limits>
#include <vector>

namespace sphfsi {

/// Parameters of a TotalLagrangianSolid (designated initialisers; validated by the model's constructor).
template <int Dim, Real T>
struct TotalLagrangianParameters {
  Vec<Dim, T> gravity = default_gravity();  ///< body force per unit mass, m/s^2
  T cfl{T(0.3)};                            ///< solid step = cfl h / (c_p + |v|max), (0, 1]
  bool sub_cycle{true};   ///< true: advance() sub-cycles and the solid does not limit the fluid step
  T hourglass{T(0.1)};    ///< alpha_hg, hourglass penalty relative to E, [0, 10]
  T artificial_viscosity{T(0)};  ///< alpha of Monaghan's artificial viscosity, [0, 5]
  T damping{T(0)};        ///< c_d, mass-proportional velocity damping, 1/s, >= 0 (0 for dynamics)
  T stretch_limit{T(0)};  ///< stop with BlowUpError when max_stretch() exceeds this (0: off), else > 1

  static Vec<Dim, T> default_gravity() {
    Vec<Dim, T> g = Vec<Dim, T>::Zero();
    g[Dim - 1] = T(-9.81);
    return g;
  }
  void validate() const {
    for (int d = 0; d < Dim; ++d) require_finite("TotalLagrangianParameters::gravity (m/s^2)", gravity[d]);
    require_in_range("TotalLagrangianParameters::cfl", cfl, T(1e-6), T(1));
    require_in_range("TotalLagrangianParameters::hourglass (alpha_hg)", hourglass, T(0), T(10));
    require_in_range("TotalLagrangianParameters::artificial_viscosity (alpha)", artificial_viscosity, T(0), T(5));
    require_non_negative("TotalLagrangianParameters::damping (c_d, 1/s)", damping);
    if (stretch_limit != T(0))
      require_in_open_range("TotalLagrangianParameters::stretch_limit", stretch_limit, T(1),
                            std::numeric_limits<T>::max());
  }
};

/// Total-Lagrangian SPH solid of one body of a System (a ParticleModel and a SolidModel).
template <class System>
class TotalLagrangianSolid {
 public:
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;
  using Matrix = Mat<Dim, T>;
  using Kernel = typename System::kernel_type;
  using Parameters = TotalLagrangianParameters<Dim, T>;

  /// Builds the reference configuration of body `body` from the system's current solid particles.
  TotalLagrangianSolid(const System& system, std::int32_t body, const ElasticMaterial<T>& material,
                       const Parameters& params = {})
      : material_((material.validate(), material)),
        params_((params.validate(), params)),
        kernel_(system.kernel()),
        body_(system.particles(), body, material, static_cast<T>(Kernel::support)) {
    const std::size_t n = body_.size();
    const auto& X = body_.reference_position();
    const auto& V0 = body_.volume();
    const auto& h = body_.smoothing_length();
    const auto& pairs = body_.reference_pairs();
    grad0_.resize(pairs.neighbor.size());
    w0_.resize(pairs.neighbor.size());
    correction_.resize(n);
    for (std::size_t a = 0; a < n; ++a) {
      Matrix m = Matrix::Zero();
      for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k) {
        const std::uint32_t b = pairs.neighbor[k];
        const Vector dx = X[a] - X[b];
        const T r = dx.norm(), hab = T(0.5) * (h[a] + h[b]);
        grad0_[k] = kernel_gradient(kernel_, dx, r, hab);
        w0_[k] = kernel_.value(r, hab);
        m += V0[b] * (X[b] - X[a]) * grad0_[k].transpose();
      }
      if (!(std::abs(m.determinant()) > T(1e-3)))
        throw InputError(fmt::format("TotalLagrangianSolid: particle id {} of body {} has too few neighbours for "
                                     "the kernel-gradient correction (det M = {}): use h/dp >= 1.2",
                                     body_.particle_ids()[a], body, m.determinant()));
      correction_[a] = m.inverse();
    }
    F_.assign(n, Matrix::Identity());
    P_.assign(n, Matrix::Zero());
    PB_.assign(n, Matrix::Zero());
    a_int_.assign(n, Vector::Zero());
  }

  // ---- set-up ----
  /// Clamps the particles whose reference position satisfies pred (see SolidBody::clamp_where).
  template <class Predicate>
  std::size_t clamp_where(Predicate&& pred) {
    return body_.clamp_where(std::forward<Predicate>(pred));
  }
  SolidBody<Dim, T>& body_data() noexcept { return body_; }
  const SolidBody<Dim, T>& body_data() const noexcept { return body_; }

  // ---- ParticleModel ----
  /// Publishes the solid's pressure, sound speed and density (rho0 / det F) in the particle set for couplings.
  void compute_rates(System& system, T /*time*/) {
    body_.gather_state(system.particles());
    publish(system.particles());
  }

  /// +inf when sub-cycling, otherwise h / (c_p + |v|max) (the Simulation applies its CFL).
  T stable_time_step(const System&) const {
    if (params_.sub_cycle) return std::numeric_limits<T>::infinity();
    return solid_time_step() / params_.cfl;
  }

  /// Integrates the body over [time, time + dt] in ceil(dt / solid_time_step()) velocity-Verlet sub-steps,
  /// holding the external acceleration found in the particle set constant.
  void advance(System& system, T time, T dt) {
    auto& p = system.particles();
    body_.gather(p);
    if (!initialised_) {
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
        body_.x[k] += h * body_.v[k];
      });
      internal_acceleration();
      detail::for_each_solid_particle(n, [&](std::size_t k) {
        if (!body_.is_clamped(k)) body_.v[k] += T(0.5) * h * (a_int_[k] + body_.a_ext[k] + g);
      });
      check(time + T(s + 1) * h);
    }
    sub_steps_ += n_sub;
    if (params_.stretch_limit > T(0)) {
      const T s = body_.max_stretch();
      if (s > params_.stretch_limit)
        throw BlowUpError(fmt::format("solid body {} at t = {:.6g} s: largest stretch between initially "
                                      "neighbouring particles is {:.4g} > stretch_limit = {:.4g} (the body tore)",
                                      body_.body(), time + dt, s, params_.stretch_limit));
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
    if (params_.damping > T(0)) rate = std::max(rate, T(0.5) * params_.damping * h_min);  // c_d dt <= 2 cfl
    return params_.cfl * h_min / rate;
  }

  /// Cauchy stress sigma = P F^T / det F of a particle (by id), Pa (tension positive).
  Matrix cauchy_stress(std::uint32_t id) const {
    const std::size_t k = local(id);
    return P_[k] * F_[k].transpose() / F_[k].determinant();
  }
  /// Deformation gradient of a particle (by id).
  const Matrix& deformation_gradient(std::uint32_t id) const { return F_[local(id)]; }

  /// Largest stretch between initially neighbouring particles (stability diagnostic).
  T max_stretch() const { return body_.max_stretch(); }
  T kinetic_energy() const { return body_.kinetic_energy(); }
  /// Stored elastic energy sum_a V0_a Psi(F_a), J (J/m in 2D).
  T strain_energy() const {
    const T lambda = material_.lame_lambda(), mu = material_.shear_modulus();
    T e = T(0);
    for (std::size_t k = 0; k < body_.size(); ++k) {
      const Matrix E = T(0.5) * (F_[k].transpose() * F_[k] - Matrix::Identity());
      const T tr = E.trace();
      e += body_.volume()[k] * (T(0.5) * lambda * tr * tr + mu * E.squaredNorm());
    }
    return e;
  }
  std::size_t sub_step_total() const noexcept { return sub_steps_; }

 private:
  std::size_t local(std::uint32_t id) const {
    const auto k = body_.local_index(id);
    if (k < 0) throw InputError(fmt::format("particle id {} is not in solid body {}", id, body_.body()));
    return static_cast<std::size_t>(k);
  }

  /// F, P and the internal (elastic + hourglass + viscous + damping) acceleration at the body's state.
  void internal_acceleration() {
    const std::size_t n = body_.size();
    const auto& pairs = body_.reference_pairs();
    const auto& X = body_.reference_position();
    const auto& V0 = body_.volume();
    const auto& m = body_.mass();
    const auto& hs = body_.smoothing_length();
    const auto& x = body_.x;
    const auto& v = body_.v;
    const T lambda = material_.lame_lambda(), mu = material_.shear_modulus();
    detail::for_each_solid_particle(n, [&](std::size_t a) {
      Matrix f = Matrix::Zero();
      for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k) {
        const std::uint32_t b = pairs.neighbor[k];
        f += V0[b] * (x[b] - x[a]) * grad0_[k].transpose();
      }
      F_[a] = f * correction_[a];
      const Matrix E = T(0.5) * (F_[a].transpose() * F_[a] - Matrix::Identity());
      const Matrix S = lambda * E.trace() * Matrix::Identity() + T(2) * mu * E;
      P_[a] = F_[a] * S;
      PB_[a] = P_[a] * correction_[a].transpose();
    });
    const T alpha_hg = params_.hourglass * material_.youngs_modulus;
    const T alpha_av = params_.artificial_viscosity;
    const T c0 = material_.sound_speed(), rho0 = material_.density;
    const T c_d = params_.damping;
    detail::for_each_solid_particle(n, [&](std::size_t a) {
      Vector force = Vector::Zero();
      for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k) {
        const std::uint32_t b = pairs.neighbor[k];
        force += V0[a] * V0[b] * ((PB_[a] + PB_[b]) * grad0_[k]);
        const Vector x_ba = x[b] - x[a];
        const T r = x_ba.norm();
        if (r <= T(0)) continue;
        const Vector e = x_ba / r;
        const Vector X_ba = X[b] - X[a];
        const T r0 = X_ba.norm();
        if (alpha_hg > T(0)) {
          const T delta = ((T(0.5) * (F_[a] + F_[b]) * X_ba - x_ba).dot(e)) / r0;
          force -= (alpha_hg * V0[a] * V0[b] * w0_[k] * delta / r0) * e;
        }
        if (alpha_av > T(0)) {
          const T hab = T(0.5) * (hs[a] + hs[b]);
          const Vector v_ab = v[a] - v[b];
          const T vr = -v_ab.dot(x_ba);  // v_ab . x_ab
          if (vr < T(0)) {
            const T mu_ab = hab * vr / (r * r + T(0.01) * hab * hab);
            const T pi_ab = -alpha_av * c0 * mu_ab / rho0;
            force -= m[a] * m[b] * pi_ab * kernel_gradient(kernel_, Vector(-x_ba), r, hab);
          }
        }
      }
      a_int_[a] = force / m[a] - c_d * v[a];
    });
  }

  void check(T time) const {
    body_.check_finite(time);  // first: a bad position or velocity is the origin, bad stresses follow from it
    for (std::size_t k = 0; k < body_.size(); ++k)
      if (!P_[k].allFinite()) body_.throw_blow_up(k, "stress (first Piola-Kirchhoff)", time);
  }

  /// Writes density rho0 / det F, pressure -tr(sigma)/Dim and bulk sound speed into the particle set.
  void publish(ParticleSet<Dim, T>& p) const {
    const T c0 = material_.sound_speed();
    const auto& ids = body_.particle_ids();
    for (std::size_t k = 0; k < body_.size(); ++k) {
      const std::size_t i = p.slot_of_id(ids[k]);
      const T J = F_[k].determinant();
      p.density[i] = material_.density / J;
      p.pressure[i] = -(P_[k] * F_[k].transpose()).trace() / (T(Dim) * J);
      p.sound_speed[i] = c0;
    }
  }

  ElasticMaterial<T> material_;
  Parameters params_;
  Kernel kernel_;
  SolidBody<Dim, T> body_;
  std::vector<Vector> grad0_;         // reference kernel gradient per pair, 1/m^(Dim+1)
  std::vector<T> w0_;                 // reference kernel value per pair, 1/m^Dim
  std::vector<Matrix> correction_;    // B_a
  std::vector<Matrix> F_, P_, PB_;    // deformation gradient, PK1 stress (Pa), P B^T
  std::vector<Vector> a_int_;         // internal acceleration, m/s^2
  std::size_t sub_steps_{0};
  bool initialised_{false};
};

}  // namespace sphfsi
