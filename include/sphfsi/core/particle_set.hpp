// sphfsi: structure-of-arrays particle storage.
//
// One array per field; all arrays are permuted together when particles are re-sorted by cell. Every particle
// carries its own mass and smoothing length, so particles of different sizes live in one set. A stable `id`
// (a creation counter) survives re-sorting; models that keep per-particle state of their own (solids, probes)
// index it by id and find the current slot with slot_of_id(). Particles can be removed (remove(), used by fluid
// particle merging): ids stay unique and below id_capacity(), the ids of removed particles are never reused, and
// without removals the ids are a permutation of 0 .. size() - 1 as before.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <algorithm>
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
  std::vector<std::uint32_t> id;    ///< stable identity: creation counter, unique, < id_capacity()
  std::vector<Vector> normal;       ///< outward unit normal of wall/solid surface particles (zero elsewhere)
  /// 1: a passive fluid particle of an overlapping resolution (fluid/adaptive_refinement.hpp): a model sets its
  /// velocity and density from the particles of the other resolution, the fluid gives it no rates, and it serves
  /// as a neighbour of its own resolution's active particles. 0 (the default): an ordinary particle.
  std::vector<std::uint8_t> passive;

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

  /// Marks a removed id in the id -> slot map (slot_of_id() of a removed particle).
  static constexpr std::uint32_t no_slot = std::numeric_limits<std::uint32_t>::max();

  /// Appends one particle with the next unused id and returns its slot (== its id until the first re-sort or
  /// removal). x and v may be elements of this set.
  std::size_t add(Kind k, const Vector& x_in, const Vector& v_in, T rho, T m, T h, std::int32_t body_index = -1) {
    // Copies on purpose: x_in and v_in may be elements of this set, whose arrays reallocate below.
    const Vector x = x_in;  // NOLINT(performance-unnecessary-copy-initialization)
    const Vector v = v_in;  // NOLINT(performance-unnecessary-copy-initialization)
    require_positive("particle density rho (kg/m^3)", rho);
    require_positive("particle mass m (kg)", m);
    require_positive("particle smoothing length h (m)", h);
    for (int d = 0; d < Dim; ++d) require_finite("particle position", x[d]);
    for (int d = 0; d < Dim; ++d) require_finite("particle velocity", v[d]);
    const std::size_t slot = size();
    if (next_id_ >= no_slot) throw InputError("particle count exceeds the 32-bit id range");
    position.push_back(x);
    velocity.push_back(v);
    density.push_back(rho);
    mass.push_back(m);
    smoothing_length.push_back(h);
    kind.push_back(k);
    body.push_back(body_index);
    id.push_back(next_id_);
    normal.push_back(Vector::Zero());
    passive.push_back(0);
    pressure.push_back(T(0));
    sound_speed.push_back(T(0));
    acceleration.push_back(Vector::Zero());
    density_rate.push_back(T(0));
    xsph_velocity.push_back(Vector::Zero());
    position_old.push_back(x);
    velocity_old.push_back(v);
    density_old.push_back(rho);
    slot_of_id_.push_back(static_cast<std::uint32_t>(slot));  // slot_of_id_ holds next_id_ entries
    ++next_id_;
    return slot;
  }

  /// Removes the particle in `slot`: the last particle moves into the slot (every field), the set shrinks by one
  /// and the removed id is marked absent (contains_id() false). O(1); slots other than `slot` and the last keep
  /// their particle. To remove several, remove them in decreasing slot order.
  void remove(std::size_t slot) {
    if (slot >= size())
      throw InputError(fmt::format("ParticleSet::remove slot = {} is invalid: valid range is [0, {})", slot, size()));
    const std::size_t last = size() - 1;
    slot_of_id_[id[slot]] = no_slot;
    if (slot != last) {
      move_last_into(slot, position);
      move_last_into(slot, velocity);
      move_last_into(slot, density);
      move_last_into(slot, mass);
      move_last_into(slot, smoothing_length);
      move_last_into(slot, kind);
      move_last_into(slot, body);
      move_last_into(slot, id);
      move_last_into(slot, normal);
      move_last_into(slot, passive);
      move_last_into(slot, pressure);
      move_last_into(slot, sound_speed);
      move_last_into(slot, acceleration);
      move_last_into(slot, density_rate);
      move_last_into(slot, xsph_velocity);
      move_last_into(slot, position_old);
      move_last_into(slot, velocity_old);
      move_last_into(slot, density_old);
      slot_of_id_[id[slot]] = static_cast<std::uint32_t>(slot);
    }
    pop_back_all();
  }

  /// One past the largest id ever given out: every id is below it (== size() if nothing was removed).
  std::size_t id_capacity() const noexcept { return next_id_; }

  /// Whether a particle with this id is in the set (false for removed ids and ids never given out).
  bool contains_id(std::uint32_t particle_id) const noexcept {
    return particle_id < slot_of_id_.size() && slot_of_id_[particle_id] != no_slot;
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
    apply(order, passive);
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

  /// Current slot of the particle created with the given id (no_slot if it was removed; the id must be below
  /// id_capacity()).
  std::size_t slot_of_id(std::uint32_t particle_id) const { return slot_of_id_[particle_id]; }

  /// Rebuilds the id -> slot map from `id`, for arrays filled directly (a checkpoint being read). `capacity` is
  /// the id_capacity() to restore (0: one past the largest id); ids of removed particles below it stay unused.
  /// Throws InputError unless the ids are unique and below the capacity.
  void rebuild_slot_of_id(std::size_t capacity = 0) {
    const std::size_t n = id.size();
    const bool given = capacity != 0;
    if (!given)  // repeated ids are reported below
      for (std::uint32_t k : id) capacity = std::max<std::size_t>(capacity, std::size_t(k) + 1);
    if ((given && capacity < n) || capacity >= no_slot)
      throw InputError(fmt::format("ParticleSet: id capacity {} is invalid for {} particles: valid range is [{}, {})",
                                   capacity, n, n, no_slot));
    slot_of_id_.assign(capacity, no_slot);
    for (std::size_t i = 0; i < n; ++i) {
      if (id[i] >= capacity || slot_of_id_[id[i]] != no_slot)
        throw InputError(
            fmt::format("ParticleSet: particle id {} in slot {} is out of range or repeated: ids must "
                        "be unique and below {}",
                        id[i], i, capacity));
      slot_of_id_[id[i]] = static_cast<std::uint32_t>(i);
    }
    next_id_ = static_cast<std::uint32_t>(capacity);
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

  template <class V>
  static void move_last_into(std::size_t slot, std::vector<V>& field) {
    field[slot] = field.back();
  }

  void pop_back_all() {
    position.pop_back();
    velocity.pop_back();
    density.pop_back();
    mass.pop_back();
    smoothing_length.pop_back();
    kind.pop_back();
    body.pop_back();
    id.pop_back();
    normal.pop_back();
    passive.pop_back();
    pressure.pop_back();
    sound_speed.pop_back();
    acceleration.pop_back();
    density_rate.pop_back();
    xsph_velocity.pop_back();
    position_old.pop_back();
    velocity_old.pop_back();
    density_old.pop_back();
  }

  std::vector<std::uint32_t> slot_of_id_;  // id -> slot, next_id_ entries, no_slot for removed ids
  std::uint32_t next_id_{0};               // the id the next add() gives out
  std::vector<std::max_align_t> scratch_;  // reused buffer: no allocation in the time loop
};

}  // namespace sphfsi
