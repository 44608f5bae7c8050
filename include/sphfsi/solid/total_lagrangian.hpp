// sphfsi: total-Lagrangian SPH elastic solid with kernel-gradient correction and hourglass control.
//
// All sums run over the neighbours of the reference configuration X (Ganzenmueller 2015, CMAME 286:87;
// Zhang, Rezavand & Hu 2021, J. Comput. Phys. 429:110028, the SPHinXsys solid). With V0_b = m_b / rho0,
// grad0_ab = grad_a W(|X_a - X_b|, h_ab) and X_ba = X_b - X_a, x_ba = x_b - x_a:
//   gradient weights  g_ab = B_a^T grad0_ab, B_a = [ sum_b V0_b X_ba (x) grad0_ab ]^-1   (Bonet & Lok 1999,
//                     exact for linear fields), or by default weights exact for quadratic fields (a Taylor fit
//                     to second order tested with [grad0_ab, W0_ab X_ba X_ba]: see quadratic_gradient_weights)
//   deformation grad. F_a  = sum_b V0_b x_ba (x) g_ab
//   Green strain      E_a  = (F_a^T F_a - I) / 2
//   Saint Venant-Kirchhoff   S_a = lambda tr(E_a) I + 2 G E_a,   P_a = F_a S_a   (first Piola-Kirchhoff)
//   momentum          m_a dv_a/dt = sum_b V0_a V0_b (P_a g_ab - P_b g_ba) + hourglass + viscosity
//                     + m_a (g + a_ext) - m_a c_d v_a
// The momentum equation is the gradient of the discrete strain energy sum_a V0_a Psi(F_a) with
// Psi = lambda/2 tr(E)^2 + G E:E (Ganzenmueller 2015, sec. 2), so linear and angular momentum are conserved
// and a rigid rotation (F = R, E = 0) gives no stress. 2D is plane strain (3D lambda and G).
// Why quadratic weights: with the Bonet-Lok weights the one-sided support of a free-surface particle evaluates
// the bending strain (u_x = -kappa x y) as if the particle sat about one row inside the body, so the outer
// fibres, which carry the bending stiffness, are under-strained: the Gray et al. plate was 29 % too slow at
// H/dp = 4. The quadratic weights remove that O(dp) surface error; they are larger at surfaces and corners,
// so the step is also limited by the highest frequency of the linearised body (power iteration).
// Clamps: clamp_where() holds particles at rest (the clamp then acts about dp/2 inside the wall, at the first
// clamped column: +2.5 % on the plate period at H/dp = 4); clamp_by_reflection() moves the wall part as the
// odd image of the free part (u_image = -u_mirror), which puts the clamp (u = 0) on the wall plane; the images
// carry no energy of their own (no stress, no hourglass force) and pass the forces on them to their mirrors.
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
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace sphfsi {

/// Parameters of a TotalLagrangianSolid (designated initialisers; validated by the model's constructor).
template <int Dim, Real T>
struct TotalLagrangianParameters {
  Vec<Dim, T> gravity = standard_gravity<Dim, T>();  ///< body force per unit mass, m/s^2
  T cfl{T(0.3)};                                     ///< solid step = cfl h / (c_p + |v|max), (0, 1]
  bool sub_cycle{true};             ///< true: advance() sub-cycles and the solid does not limit the fluid step
  T hourglass{T(0.1)};              ///< alpha_hg, hourglass penalty relative to E, [0, 10]
  T artificial_viscosity{T(0)};     ///< alpha of Monaghan's artificial viscosity, [0, 5]
  T damping{T(0)};                  ///< c_d, mass-proportional velocity damping, 1/s, >= 0 (0 for dynamics)
  T stretch_limit{T(0)};            ///< stop with BlowUpError when max_stretch() exceeds this (0: off), else > 1
  bool quadratic_correction{true};  ///< gradient exact for quadratic fields (false: Bonet-Lok, exact for linear)

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
    reverse_.resize(pairs.neighbor.size());
    for (std::size_t a = 0; a < n; ++a) {
      for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k) {
        const std::uint32_t b = pairs.neighbor[k];
        const Vector dx = X[a] - X[b];
        const T r = dx.norm(), hab = T(0.5) * (h[a] + h[b]);
        grad0_[k] = kernel_gradient(kernel_, dx, r, hab);
        w0_[k] = kernel_.value(r, hab);
        std::uint32_t back = pairs.offset[b];  // the pair (b, a): the lists are symmetric
        while (back < pairs.offset[b + 1] && pairs.neighbor[back] != a) ++back;
        reverse_[k] = back;
      }
    }
    correction_.resize(n);
    quadratic_.assign(n, 0);
    for (std::size_t a = 0; a < n; ++a) {
      Matrix m = Matrix::Zero();
      for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k)
        m += V0[pairs.neighbor[k]] * (X[pairs.neighbor[k]] - X[a]) * grad0_[k].transpose();
      if (!(std::abs(m.determinant()) > T(1e-3)))
        throw InputError(
            fmt::format("TotalLagrangianSolid: particle id {} of body {} has too few neighbours for "
                        "the kernel-gradient correction (det M = {}): use h/dp >= 1.2",
                        body_.particle_ids()[a], body, m.determinant()));
      correction_[a] = m.inverse();
    }
    gradient_weight_.resize(pairs.neighbor.size());
    for (std::size_t a = 0; a < n; ++a)
      for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k)
        gradient_weight_[k] = correction_[a].transpose() * grad0_[k];
    F_.assign(n, Matrix::Identity());
    P_.assign(n, Matrix::Zero());
    a_int_.assign(n, Vector::Zero());
    if (params_.quadratic_correction)
      for (std::size_t a = 0; a < n; ++a) quadratic_[a] = quadratic_gradient_weights(a);
    highest_frequency_ = highest_frequency();
  }

  // ---- set-up ----
  /// Clamps the particles whose reference position satisfies pred (see SolidBody::clamp_where).
  template <class Predicate>
  std::size_t clamp_where(Predicate&& pred) {
    return body_.clamp_where(std::forward<Predicate>(pred));
  }
  /// Clamps the particles behind the plane through `point` with normal `normal` (pointing into the free part)
  /// by odd reflection: each moves with minus the displacement and velocity of its mirror image in the plane,
  /// so the displacement vanishes on the plane itself (a clamp at the wall face). Every such particle must have
  /// a free particle at its mirror position (a lattice symmetric about the plane). Returns their number.
  std::size_t clamp_by_reflection(const Vector& point, const Vector& normal) {
    const std::size_t count = body_.clamp_by_reflection(point, normal);
    highest_frequency_ = highest_frequency();  // the images couple each particle near the plane to its mirror
    return count;
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
      internal_acceleration();
      detail::for_each_solid_particle(n, [&](std::size_t k) {
        if (!body_.is_clamped(k)) body_.v[k] += T(0.5) * h * (a_int_[k] + body_.a_ext[k] + g);
      });
      body_.reflect_images();
      check(t_end);
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

  /// Stable solid step cfl h_min / (c_p + |v|max), s.
  T solid_time_step() const {
    T v_max = T(0), h_min = std::numeric_limits<T>::max();
    for (std::size_t k = 0; k < body_.size(); ++k) {
      v_max = std::max(v_max, body_.v[k].norm());
      h_min = std::min(h_min, body_.smoothing_length()[k]);
    }
    T rate = material_.p_wave_speed() + v_max;
    if (params_.damping > T(0)) rate = std::max(rate, T(0.5) * params_.damping * h_min);  // c_d dt <= 2 cfl
    // Velocity Verlet is stable for omega_max dt < 2; the Bonet-Lok weights at cfl = 0.3 run at omega_max dt
    // of about 0.6; the quadratic weights (stiffer surface and corner modes) are held at omega_max dt <= 4 cfl.
    return params_.cfl * std::min(h_min / rate, frequency_step_factor / highest_frequency_);
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
      if (body_.is_image(k)) continue;  // images of a reflected clamp store no energy
      const Matrix E = T(0.5) * (F_[k].transpose() * F_[k] - Matrix::Identity());
      const T tr = E.trace();
      e += body_.volume()[k] * (T(0.5) * lambda * tr * tr + mu * E.squaredNorm());
    }
    return e;
  }
  std::size_t sub_step_total() const noexcept { return sub_steps_; }

  // ---- checkpoint (io/checkpoint.hpp) ----
  /// Saves what the next sub-step reads besides the particle arrays: the internal acceleration of the last
  /// sub-step (it holds the half-step velocity's viscous and damping terms, so it cannot be recomputed), F, P
  /// and the sub-step count. The reference configuration, clamps and weights are rebuilt by the scene.
  template <class Writer>
  void save_checkpoint(Writer& w) const {
    const auto prefix = fmt::format("total_lagrangian_solid.{}.", body_.body());
    body_.save_checkpoint_header(w, prefix, initialised_, sub_steps_);
    w.write(prefix + "internal_acceleration", a_int_);
    w.write(prefix + "deformation_gradient", F_);
    w.write(prefix + "first_piola_kirchhoff_stress", P_);
  }
  /// Restores the state saved by save_checkpoint into a solid built by the same scene (same body and particles).
  template <class Reader>
  void load_checkpoint(Reader& r) {
    const auto prefix = fmt::format("total_lagrangian_solid.{}.", body_.body());
    body_.load_checkpoint_header(r, prefix, initialised_, sub_steps_);
    r.read_exact(prefix + "internal_acceleration", a_int_, body_.size());
    r.read_exact(prefix + "deformation_gradient", F_, body_.size());
    r.read_exact(prefix + "first_piola_kirchhoff_stress", P_, body_.size());
  }

  /// Number of particles whose gradient weights are exact for quadratic fields (the others use Bonet-Lok).
  std::size_t quadratic_particle_count() const {
    std::size_t c = 0;
    for (auto q : quadratic_) c += q;
    return c;
  }

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
        f += V0[b] * (x[b] - x[a]) * gradient_weight_[k].transpose();
      }
      F_[a] = f;
      const Matrix E = T(0.5) * (F_[a].transpose() * F_[a] - Matrix::Identity());
      const Matrix S = lambda * E.trace() * Matrix::Identity() + T(2) * mu * E;
      P_[a] = F_[a] * S;
      if (body_.is_image(a)) P_[a].setZero();  // image of the body: no energy of its own
    });
    const T alpha_hg = params_.hourglass * material_.youngs_modulus;
    const T alpha_av = params_.artificial_viscosity;
    const T c0 = material_.sound_speed(), rho0 = material_.density;
    const T c_d = params_.damping;
    detail::for_each_solid_particle(n, [&](std::size_t a) {
      Vector force = Vector::Zero();
      for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k) {
        const std::uint32_t b = pairs.neighbor[k];
        force += V0[a] * V0[b] * (P_[a] * gradient_weight_[k] - P_[b] * gradient_weight_[reverse_[k]]);
        const Vector x_ba = x[b] - x[a];
        const T r = x_ba.norm();
        if (r <= T(0)) continue;
        const Vector e = x_ba / r;
        const Vector X_ba = X[b] - X[a];
        const T r0 = X_ba.norm();
        if (alpha_hg > T(0) && !body_.is_image(a) && !body_.is_image(b)) {  // images carry no energy: no hourglass
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
    // The images move with minus their mirror's displacement: the force on an image acts on its mirror reversed.
    for (std::size_t g = 0; g < n; ++g)
      if (body_.is_image(g)) {
        const auto k = static_cast<std::size_t>(body_.mirror(g));
        a_int_[k] -= (a_int_[g] + c_d * v[g]) * (m[g] / m[k]);
      }
  }

  /// Gradient weights of particle a exact for quadratic fields on the reference configuration (see
  /// detail::quadratic_gradient_weights); keeps the Bonet-Lok weights (returns 0) where the neighbours do not
  /// determine a quadratic (fewer than three rows in some direction).
  std::uint8_t quadratic_gradient_weights(std::size_t a) {
    return detail::quadratic_gradient_weights<Dim, T>(a, body_.reference_pairs(), body_.reference_position(),
                                                      body_.volume(), body_.smoothing_length()[a], grad0_, w0_,
                                                      gradient_weight_, quadratic_condition_limit)
               ? 1
               : 0;
  }
  static constexpr T quadratic_condition_limit = T(1e-6);
  static constexpr T frequency_step_factor = T(4);  // omega_max dt <= 4 cfl (1.2, 60 % of the limit 2, at cfl 0.3)

  /// Highest angular frequency of the free body linearised about the reference configuration, rad/s: the
  /// largest eigenvalue of M^-1 K by power iteration (100 products with the internal force; a deterministic start).
  T highest_frequency() {
    const std::size_t n = body_.size();
    const auto& X = body_.reference_position();
    const std::vector<Vector> velocity = body_.v;
    for (auto& vk : body_.v) vk.setZero();
    std::vector<Vector> u(n);
    for (std::size_t k = 0; k < n; ++k)
      for (int d = 0; d < Dim; ++d) u[k][d] = std::sin(T(12.9898) * T(k) + T(78.233) * T(d + 1));
    const T eps = T(1e-6) * body_.reference_spacing();
    T lambda = T(0);
    for (int iteration = 0; iteration < 100; ++iteration) {
      T norm = T(0);
      for (const auto& uk : u) norm += uk.squaredNorm();
      norm = std::sqrt(norm);
      for (std::size_t k = 0; k < n; ++k) body_.x[k] = X[k] + eps * u[k] / norm;
      internal_acceleration();
      T image = T(0);
      for (std::size_t k = 0; k < n; ++k) {
        u[k] = a_int_[k] / eps;
        image += u[k].squaredNorm();
      }
      lambda = std::sqrt(image);
    }
    body_.x = X;
    body_.v = velocity;
    F_.assign(n, Matrix::Identity());
    P_.assign(n, Matrix::Zero());
    a_int_.assign(n, Vector::Zero());
    return std::sqrt(lambda);
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
  std::vector<Vector> grad0_;            // reference kernel gradient per pair, 1/m^(Dim+1)
  std::vector<T> w0_;                    // reference kernel value per pair, 1/m^Dim
  std::vector<Matrix> correction_;       // B_a
  std::vector<Vector> gradient_weight_;  // corrected gradient weight L_a grad0_ab per pair, 1/m^(Dim+1)
  std::vector<std::uint32_t> reverse_;   // index of the pair (b, a) of each pair (a, b)
  std::vector<std::uint8_t> quadratic_;  // 1 where the weights are exact for quadratic fields
  std::vector<Matrix> F_, P_;            // deformation gradient, PK1 stress (Pa)
  T highest_frequency_{0};               // omega_max of the linearised body with its reflected clamps, rad/s
  std::vector<Vector> a_int_;            // internal acceleration, m/s^2
  std::size_t sub_steps_{0};
  bool initialised_{false};
};

}  // namespace sphfsi
