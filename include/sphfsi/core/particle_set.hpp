// sphfsi: structure-of-arrays particle storage.
//
// One array per field; all arrays are permuted together when particles are re-sorted by cell. Every particle
// carries its own mass and smoothing length, so particles of different sizes live in one set. A stable `id`
// (the index at creation) survives re-sorting; models that keep per-particle state of their own (solids, probes)
// index it by id and find the current slot with slot_of_id().
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>
#include <vector>

namespace sphfsi {

template <int Dim, Real T>
  requires SpatialDimension<Dim>
struct ParticleSet {
  using Vector = Vec<Dim, T>;
  static constexpr int dimension = Dim;
  using scalar_type = T;

  // State.
  std::vector<Vector> position;     ///< m
  std::vector<Vector> velocity;     ///< m/s
  std::vector<T> density;           ///< kg/m^3
  std::vector<T> mass;              ///< kg (per unit depth in 2D: kg/m)
  std::vector<T> smoothing_length;  ///< h, m
  std::vector<Kind> kind;           ///< fluid, wall or solid
  std::vector<std::int32_t> body;   ///< body or wall group index (-1: none); solids use it for the body id
  std::vector<std::uint32_t> id;    ///< stable identity, index at creation
  std::vector<Vector> normal;       ///< outward unit normal of wall/solid surface particles (zero elsewhere)

  // Derived per-particle quantities (recomputed each evaluation).
  std::vector<T> pressure;     ///< Pa
  std::vector<T> sound_speed;  ///< m/s

  // Rates (recomputed each evaluation).
  std::vector<Vector> acceleration;   ///< dv/dt, m/s^2
  std::vector<T> density_rate;        ///< drho/dt, kg/m^3/s
  std::vector<Vector> xsph_velocity;  ///< XSPH correction added to dx/dt, m/s

  // Integrator storage (state at the start of the step).
  std::vector<Vector> position_old;
  std::vector<Vector> velocity_old;
  std::vector<T> density_old;

  std::size_t size() const noexcept { return position.size(); }

  /// Appends one particle and returns its slot (== its id until the first re-sort).
  std::size_t add(Kind k, const Vector& x, const Vector& v, T rho, T m, T h, std::int32_t body_index = -1) {
    require_positive("particle density rho (kg/m^3)", rho);
    require_positive("particle mass m (kg)", m);
    require_positive("particle smoothing length h (m)", h);
    for (int d = 0; d < Dim; ++d) require_finite("particle position", x[d]);
    for (int d = 0; d < Dim; ++d) require_finite("particle velocity", v[d]);
    const std::size_t slot = size();
    if (slot >= std::numeric_limits<std::uint32_t>::max())
      throw InputError("particle count exceeds the 32-bit id range");
    position.push_back(x);
    velocity.push_back(v);
    density.push_back(rho);
    mass.push_back(m);
    smoothing_length.push_back(h);
    kind.push_back(k);
    body.push_back(body_index);
    id.push_back(static_cast<std::uint32_t>(slot));
    normal.push_back(Vector::Zero());
    pressure.push_back(T(0));
    sound_speed.push_back(T(0));
    acceleration.push_back(Vector::Zero());
    density_rate.push_back(T(0));
    xsph_velocity.push_back(Vector::Zero());
    position_old.push_back(x);
    velocity_old.push_back(v);
    density_old.push_back(rho);
    slot_of_id_.push_back(static_cast<std::uint32_t>(slot));
    return slot;
  }

  /// Reorders every field: new slot i holds the particle previously in slot order[i].
  void permute(const std::vector<std::uint32_t>& order) {
    apply(order, position);
    apply(order, velocity);
    apply(order, density);
    apply(order, mass);
    apply(order, smoothing_length);
    apply(order, kind);
    apply(order, body);
    apply(order, id);
    apply(order, normal);
    apply(order, pressure);
    apply(order, sound_speed);
    apply(order, acceleration);
    apply(order, density_rate);
    apply(order, xsph_velocity);
    apply(order, position_old);
    apply(order, velocity_old);
    apply(order, density_old);
    for (std::size_t i = 0; i < id.size(); ++i) slot_of_id_[id[i]] = static_cast<std::uint32_t>(i);
  }

  /// Current slot of the particle created with the given id.
  std::size_t slot_of_id(std::uint32_t particle_id) const { return slot_of_id_[particle_id]; }

  /// Rebuilds the id -> slot map from `id`, for arrays filled directly (a checkpoint being read).
  /// Throws InputError unless `id` is a permutation of 0 .. size() - 1.
  void rebuild_slot_of_id() {
    const std::size_t n = id.size();
    slot_of_id_.assign(n, std::numeric_limits<std::uint32_t>::max());
    for (std::size_t i = 0; i < n; ++i) {
      if (id[i] >= n || slot_of_id_[id[i]] != std::numeric_limits<std::uint32_t>::max())
        throw InputError(
            fmt::format("ParticleSet: particle id {} in slot {} is out of range or repeated: ids must "
                        "be a permutation of 0 .. {}",
                        id[i], i, n - 1));
      slot_of_id_[id[i]] = static_cast<std::uint32_t>(i);
    }
  }

  /// Number of particles of a kind.
  std::size_t count(Kind k) const {
    std::size_t n = 0;
    for (Kind q : kind) n += (q == k);
    return n;
  }

 private:
  template <class V>
  void apply(const std::vector<std::uint32_t>& order, std::vector<V>& field) {
    static_assert(alignof(V) <= alignof(std::max_align_t));
    scratch_.resize((field.size() * sizeof(V)) / sizeof(std::max_align_t) + 1);
    V* tmp = reinterpret_cast<V*>(scratch_.data());
    for (std::size_t i = 0; i < order.size(); ++i) new (tmp + i) V(field[order[i]]);
    for (std::size_t i = 0; i < order.size(); ++i) field[i] = tmp[i];
  }

  std::vector<std::uint32_t> slot_of_id_;
  std::vector<std::max_align_t> scratch_;  // reused buffer: no allocation in the time loop
};

}  // namespace sphfsi
