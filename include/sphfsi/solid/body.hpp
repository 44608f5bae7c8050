// sphfsi: one elastic body made of solid particles: its reference configuration, clamps, the state the solid
// models advance between the system's evaluations, and the stability diagnostics of issue 3 part 6.
//
// A body is the set of particles with kind == Kind::solid and the same `body` index. The reference configuration
// (positions X, volumes V0 = m / rho0, the pairs within the kernel support) is the configuration at construction.
// Per-particle data are held in body order (local index k = 0 .. size()-1, in increasing particle id), so they
// survive the system's re-sorting; gather()/scatter() move state between the particle set and body order.
// Shared by both solid models: the clamps (held particles, or odd reflection about a wall plane), the stretch
// diagnostic, the sub-cycling loop and the kernel-gradient weights exact for quadratic fields.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/particle_set.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/solid/detail/pair_list.hpp>
#include <sphfsi/solid/elastic_material.hpp>

#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace sphfsi {

template <int Dim, Real T>
class SolidBody {
 public:
  using Vector = Vec<Dim, T>;

  /// Collects the solid particles of `body`; `support` is the kernel support radius over h.
  SolidBody(const ParticleSet<Dim, T>& p, std::int32_t body, const ElasticMaterial<T>& material, T support)
      : body_(body) {
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::solid && p.body[i] == body) ids_.push_back(p.id[i]);
    if (ids_.empty())
      throw InputError(
          fmt::format("solid body {} has no particles: add particles with Kind::solid and body = {} "
                      "before creating its solid model",
                      body, body));
    std::sort(ids_.begin(), ids_.end());
    local_of_id_.assign(p.id_capacity(), -1);  // indexed by id: ids of removed particles stay unused
    const std::size_t n = ids_.size();
    reference_position_.resize(n);
    volume_.resize(n);
    mass_.resize(n);
    h_.resize(n);
    clamped_.assign(n, 0);
    mirror_.assign(n, -1);
    x.resize(n);
    v.resize(n);
    a_ext.assign(n, Vector::Zero());
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = p.slot_of_id(ids_[k]);
      local_of_id_[ids_[k]] = static_cast<std::int64_t>(k);
      reference_position_[k] = p.position[i];
      mass_[k] = p.mass[i];
      volume_[k] = p.mass[i] / material.density;
      h_[k] = p.smoothing_length[i];
      x[k] = p.position[i];
      v[k] = p.velocity[i];
    }
    T mean_volume = T(0);
    for (T vk : volume_) mean_volume += vk;
    spacing_ = std::pow(mean_volume / T(n), T(1) / T(Dim));
    reference_pairs_ = detail::build_pair_list<Dim, T>(reference_position_, h_, support, T(0));
  }

  std::int32_t body() const noexcept { return body_; }
  std::size_t size() const noexcept { return ids_.size(); }
  /// Particle ids of the body in body order.
  const std::vector<std::uint32_t>& particle_ids() const noexcept { return ids_; }
  /// Body-order index of a particle id, or -1 if the particle is not in this body.
  std::int64_t local_index(std::uint32_t id) const { return id < local_of_id_.size() ? local_of_id_[id] : -1; }
  const std::vector<Vector>& reference_position() const noexcept { return reference_position_; }  ///< X, m
  const std::vector<T>& volume() const noexcept { return volume_; }       ///< V0, m^Dim (per unit depth in 2D)
  const std::vector<T>& mass() const noexcept { return mass_; }           ///< kg
  const std::vector<T>& smoothing_length() const noexcept { return h_; }  ///< m
  T reference_spacing() const noexcept { return spacing_; }               ///< (mean V0)^(1/Dim), m
  bool is_clamped(std::size_t k) const { return clamped_[k] != 0; }
  /// Pairs within the kernel support in the reference configuration (body order).
  const detail::PairList& reference_pairs() const noexcept { return reference_pairs_; }

  /// Holds every particle whose reference position satisfies pred(X) at its reference position, at rest
  /// (a clamped end, or the part of a plate embedded in a wall). Returns the number of clamped particles.
  template <class Predicate>
  std::size_t clamp_where(Predicate&& pred) {
    std::size_t count = 0;
    for (std::size_t k = 0; k < size(); ++k) {
      if (pred(reference_position_[k])) clamped_[k] = 1;
      count += clamped_[k];
    }
    return count;
  }
  /// Holds one particle (by id) at its reference position.
  void clamp(std::uint32_t id) {
    const auto k = local_index(id);
    if (k < 0) throw InputError(fmt::format("clamp: particle id {} is not in solid body {}", id, body_));
    clamped_[static_cast<std::size_t>(k)] = 1;
  }

  /// Clamps the particles behind the plane through `point` with normal `normal` (pointing into the free part)
  /// by odd reflection: each becomes the image of the free particle at its mirror position and moves with minus
  /// its displacement and velocity (reflect_images()), so the displacement vanishes on the plane itself (a clamp
  /// at the wall face, not dp/2 inside it). Every such particle must have a free particle at its mirror position
  /// (a lattice symmetric about the plane). Returns the number of image particles.
  std::size_t clamp_by_reflection(const Vector& point, const Vector& normal) {
    const Vector nn = normal.normalized();
    const T tolerance = T(1e-6) * spacing_;
    std::size_t count = 0;
    for (std::size_t k = 0; k < size(); ++k) {
      const T depth = (reference_position_[k] - point).dot(nn);
      if (!(depth < T(0))) continue;
      const Vector image = reference_position_[k] - T(2) * depth * nn;
      std::int64_t m = -1;
      for (std::size_t j = 0; j < size(); ++j)
        if ((reference_position_[j] - image).norm() < tolerance) m = static_cast<std::int64_t>(j);
      if (m < 0 || (reference_position_[m] - point).dot(nn) <= T(0))
        throw InputError(
            fmt::format("clamp_by_reflection: particle id {} at [{}] has no free particle at its "
                        "mirror position: the lattice must be symmetric about the clamp plane",
                        ids_[k], format_vector(reference_position_[k])));
      mirror_[k] = m;
      clamped_[k] = 1;
      ++count;
    }
    return count;
  }
  /// Body-order index of the mirror of a reflected clamp particle, or -1 (a free or held particle).
  std::int64_t mirror(std::size_t k) const { return mirror_[k]; }
  bool is_image(std::size_t k) const { return mirror_[k] >= 0; }
  /// Places each reflected clamp particle g at X_g - (x_m - X_m) with velocity -v_m (m its mirror).
  void reflect_images() {
    for (std::size_t g = 0; g < size(); ++g)
      if (mirror_[g] >= 0) {
        const auto k = static_cast<std::size_t>(mirror_[g]);
        x[g] = reference_position_[g] - (x[k] - reference_position_[k]);
        v[g] = -v[k];
      }
  }

  /// Reads positions, velocities and external accelerations (the coupling's fluid force per unit mass).
  void gather(const ParticleSet<Dim, T>& p) {
    for (std::size_t k = 0; k < size(); ++k) {
      const std::size_t i = p.slot_of_id(ids_[k]);
      x[k] = p.position[i];
      v[k] = p.velocity[i];
      a_ext[k] = clamped_[k] ? Vector::Zero() : p.acceleration[i];
    }
  }
  /// Reads positions and velocities only (the scene may have set initial velocities after construction).
  void gather_state(const ParticleSet<Dim, T>& p) {
    for (std::size_t k = 0; k < size(); ++k) {
      const std::size_t i = p.slot_of_id(ids_[k]);
      x[k] = p.position[i];
      v[k] = p.velocity[i];
    }
  }
  /// Writes positions and velocities back (acceleration keeps the external part).
  void scatter(ParticleSet<Dim, T>& p) const {
    for (std::size_t k = 0; k < size(); ++k) {
      const std::size_t i = p.slot_of_id(ids_[k]);
      p.position[i] = x[k];
      p.velocity[i] = v[k];
    }
  }

  /// Largest stretch |x_a - x_b| / |X_a - X_b| over the pairs that were neighbours in the reference
  /// configuration (1 when undeformed; a plate that tears shows values well above 1).
  /// Checkpoint records every solid model starts with: particle count, initialised flag, sub-step count.
  template <class Writer>
  void save_checkpoint_header(Writer& w, const std::string& prefix, bool initialised, std::size_t sub_steps) const {
    w.write(prefix + "particle_count", static_cast<std::uint64_t>(size()));
    w.write(prefix + "initialised", static_cast<std::uint8_t>(initialised ? 1 : 0));
    w.write(prefix + "sub_steps", static_cast<std::uint64_t>(sub_steps));
  }
  /// Reads the records of save_checkpoint_header; a particle count other than this body's is a reader failure.
  template <class Reader>
  void load_checkpoint_header(Reader& r, const std::string& prefix, bool& initialised, std::size_t& sub_steps) const {
    std::uint64_t count = 0, steps = 0;
    std::uint8_t flag = 0;
    r.read(prefix + "particle_count", count);
    if (count != size())
      r.fail(fmt::format("solid body {} was saved with {} particles, this scene built {}", body_, count, size()));
    r.read(prefix + "initialised", flag);
    r.read(prefix + "sub_steps", steps);
    initialised = flag != 0;
    sub_steps = static_cast<std::size_t>(steps);
  }

  T max_stretch() const {
    T s = T(0);
    for (std::size_t a = 0; a < size(); ++a)
      reference_pairs_.for_each(a, [&](std::uint32_t b) {
        const T r0 = (reference_position_[a] - reference_position_[b]).norm();
        if (r0 > T(0)) s = std::max(s, (x[a] - x[b]).norm() / r0);
      });
    return s;
  }

  /// Throws BlowUpError when max_stretch() exceeds `limit` (0: no limit) at the end of a step ending at `time`.
  void check_stretch_limit(T limit, T time) const {
    if (!(limit > T(0))) return;
    const T s = max_stretch();
    if (s > limit)
      throw BlowUpError(
          fmt::format("solid body {} at t = {:.6g} s: largest stretch between initially "
                      "neighbouring particles is {:.4g} > stretch_limit = {:.4g} (the body tore)",
                      body_, time, s, limit));
  }

  /// Kinetic energy sum m v^2 / 2, J (J/m per unit depth in 2D).
  T kinetic_energy() const {
    T e = T(0);
    for (std::size_t k = 0; k < size(); ++k) e += T(0.5) * mass_[k] * v[k].squaredNorm();
    return e;
  }

  /// Throws BlowUpError naming particle, quantity and time if a position or velocity is not finite.
  void check_finite(T time) const {
    // Positions first: a bad velocity spreads to the neighbours' velocities within one sub-step, a bad position
    // stays with the particle that caused it.
    for (std::size_t k = 0; k < size(); ++k)
      if (!x[k].allFinite()) throw_blow_up(k, "position", time);
    for (std::size_t k = 0; k < size(); ++k)
      if (!v[k].allFinite()) throw_blow_up(k, "velocity", time);
  }
  [[noreturn]] void throw_blow_up(std::size_t k, const std::string& quantity, T time) const {
    throw BlowUpError(
        fmt::format("solid blow-up at t = {:.6g} s: body {} particle id {} has a non-finite or "
                    "non-physical {} (reference position [{}]); the particle set holds the last good "
                    "state, at the start of the failed solid step",
                    time, body_, ids_[k], quantity, format_vector(reference_position_[k])));
  }

  // State in body order, advanced by the solid models.
  std::vector<Vector> x;      ///< position, m
  std::vector<Vector> v;      ///< velocity, m/s
  std::vector<Vector> a_ext;  ///< external (fluid) acceleration, held constant over a fluid step, m/s^2

 private:
  static std::string format_vector(const Vector& u) {
    std::string s;
    for (int d = 0; d < Dim; ++d) s += (d ? ", " : "") + fmt::format("{:.6g}", u[d]);
    return s;
  }

  std::int32_t body_;
  std::vector<std::uint32_t> ids_;
  std::vector<std::int64_t> local_of_id_;
  std::vector<Vector> reference_position_;
  std::vector<T> volume_, mass_, h_;
  std::vector<std::uint8_t> clamped_;
  std::vector<std::int64_t> mirror_;  // mirror of a reflected clamp particle, -1 otherwise
  T spacing_{0};
  detail::PairList reference_pairs_;
};

namespace detail {
/// Loop over the particles of a body: in parallel for large bodies; serially below a few thousand particles,
/// where a fork-join per sub-step would cost more than the work itself.
template <class Body>
void for_each_solid_particle(std::size_t n, Body&& body) {
  if (n >= 4096) parallel_for(n, std::forward<Body>(body));
  else
    for (std::size_t k = 0; k < n; ++k) body(k);
}

/// Number of equal sub-steps of at most dt_stable covering dt.
template <class T>
std::size_t sub_step_count(T dt, T dt_stable) {
  if (!(dt > T(0))) return 0;
  const T n = std::ceil(dt / dt_stable * (T(1) - T(64) * std::numeric_limits<T>::epsilon()));
  return static_cast<std::size_t>(std::max(T(1), n));
}

/// The sub-cycling of both solid models: covers [time, time + dt] with sub_step_count(dt, dt_stable) equal
/// sub-steps, calling step(h, t_end) for each (h the sub-step, t_end the time at its end). Returns their number.
template <class T, class Step>
std::size_t for_each_sub_step(T time, T dt, T dt_stable, Step&& step) {
  const std::size_t n_sub = sub_step_count(dt, dt_stable);
  const T h = dt / T(n_sub);
  for (std::size_t s = 0; s < n_sub; ++s) step(h, time + T(s + 1) * h);
  return n_sub;
}

/// Kernel-gradient weights of particle a exact for quadratic fields. With Delta = x_b - x_a over the pairs k of
/// a (neighbour pairs.neighbor[k], kernel gradient grad[k] = grad_a W_ab, value w[k]), the Taylor expansion
/// phi_b - phi_a = grad phi . Delta + Delta_i Delta_j H_ij / 2 is tested with t_ab = [grad_ab; W_ab Delta_i Delta_j]
/// and summed with the volumes V_b; solving the (Dim + Dim(Dim+1)/2)-square system for the gradient gives weights
/// g_ab with sum_b V_b (phi_b - phi_a) g_ab = grad phi for every quadratic phi (a second-order Taylor-series
/// correction as in the finite particle method; Liu & Liu 2010, Arch. Comput. Methods Eng. 17:25, sec. 4). On a
/// symmetric lattice in the interior the system is block-diagonal and g_ab equals the Bonet & Lok (1999) weights B_a^T
/// grad_ab; at a free surface the one-sided support no longer biases the gradient of a bending field towards the
/// inside. Writes weight[k] and returns true; returns false (weights untouched) where the neighbours do not determine a
/// quadratic (fewer than three rows in some direction: smallest singular value below condition_limit times the
/// largest).
template <int Dim, class T>
bool quadratic_gradient_weights(std::size_t a, const PairList& pairs, const std::vector<Vec<Dim, T>>& x,
                                const std::vector<T>& volume, T h, const std::vector<Vec<Dim, T>>& grad,
                                const std::vector<T>& w, std::vector<Vec<Dim, T>>& weight, T condition_limit) {
  constexpr int Q = Dim * (Dim + 1) / 2, M = Dim + Q;
  using Moment = Eigen::Matrix<T, M, M>;
  using Column = Eigen::Matrix<T, M, 1>;
  const T scale = std::pow(h, T(Dim));
  auto monomials = [&](const Vec<Dim, T>& d) {  // [Delta / h; Delta_i Delta_j / h^2]
    Column p;
    for (int i = 0; i < Dim; ++i) p[i] = d[i] / h;
    int q = Dim;
    for (int i = 0; i < Dim; ++i)
      for (int j = i; j < Dim; ++j) p[q++] = d[i] * d[j] / (h * h);
    return p;
  };
  auto test = [&](std::uint32_t k, const Column& p) {  // [grad h^(Dim+1); W h^Dim Delta_i Delta_j / h^2]
    Column t;
    t.template head<Dim>() = grad[k] * (scale * h);
    t.template tail<Q>() = w[k] * scale * p.template tail<Q>();
    return t;
  };
  Moment A = Moment::Zero();
  for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k) {
    const std::uint32_t b = pairs.neighbor[k];
    const Column p = monomials(x[b] - x[a]);
    A += (volume[b] / scale) * test(k, p) * p.transpose();
  }
  const Eigen::JacobiSVD<Moment> svd(A);
  const auto& sv = svd.singularValues();
  if (!(sv[M - 1] > condition_limit * sv[0])) return false;
  const Moment inverse = A.inverse();
  for (std::uint32_t k = pairs.offset[a]; k < pairs.offset[a + 1]; ++k) {
    const Column p = monomials(x[pairs.neighbor[k]] - x[a]);
    weight[k] = (inverse * test(k, p)).template head<Dim>() / (scale * h);
  }
  return true;
}
}  // namespace detail

}  // namespace sphfsi
