// sphfsi: a guard that keeps fluid particles on their own face of a thin structure (2D).
//
// With the visibility criterion (thin_structure_visibility.hpp) the fluid on one face of a blade does not see the
// fluid on the other, so what keeps a particle on its face is the coupling's push from the line of nodes alone
// (coupling/repulsive_force.hpp). A particle driven hard enough, e.g. by a wave's orbital flow squeezing past a blade
// that bends towards it, can still step through that line within one time step; once across it sits in the other
// face's water and stays there. The guard acts at the end of each step, on the fluid particles with candidate edges
// (those within the kernel support of a node): for every structure (a connected chain of edges) it takes the
// particle's nearest point on the chain at the start of the step (old positions of the particle and of the nodes) and
// at its end. Beside the chain means that nearest point is not beyond a free end (a blade's base or tip; a particle
// passing over the tip goes round the blade, it does not cross it). A particle beside the chain at both times, within
// `reach` of it, on opposite faces has crossed: it is moved back across the line of its nearest edge, to the
// distance from the structure it had at the start of the step (at least `min_offset` x that edge's length), and
// its velocity relative to the edge (nodes' velocities interpolated)
// loses the component towards the wrong face: an inelastic collision with the edge. The impulse is given to the
// fluid particle only (the blade does not feel it), so the guard is a last resort whose use is counted
// (crossings_prevented()): the coupling should make it rare.
//
// Faces are compared per chain, not against the nearest edge of any structure, so a particle between two blades
// whose nearest blade changes within a step is not mistaken for a crossing.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/fluid/thin_structure_visibility.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <vector>

namespace sphfsi {

/// Puts back the fluid particles that stepped through a thin structure (see the header comment).
template <Real T>
class ThinStructureGuard {
 public:
  using Vector = Vec<2, T>;

  /// The structure's edges (node id pairs, as given to ThinStructureVisibility): finds their chains and free ends.
  void set_edges(const std::vector<StructureEdge>& edges) {
    const std::size_t m = edges.size();
    std::unordered_map<std::uint32_t, std::size_t> uses;
    for (const auto& e : edges) ++uses[e[0]], ++uses[e[1]];
    free_start_.assign(m, false);
    free_end_.assign(m, false);
    for (std::size_t k = 0; k < m; ++k) {
      free_start_[k] = uses[edges[k][0]] == 1;
      free_end_[k] = uses[edges[k][1]] == 1;
    }
    // Chains: edges sharing a node (union-find over the edges through their end nodes).
    std::vector<std::size_t> parent(m);
    std::iota(parent.begin(), parent.end(), std::size_t(0));
    const auto root = [&](std::size_t k) {
      while (parent[k] != k) k = parent[k] = parent[parent[k]];
      return k;
    };
    std::unordered_map<std::uint32_t, std::size_t> edge_at_node;
    for (std::size_t k = 0; k < m; ++k)
      for (const std::uint32_t id : edges[k]) {
        const auto [it, first] = edge_at_node.emplace(id, k);
        if (!first) parent[root(k)] = root(it->second);
      }
    chain_.resize(m);
    for (std::size_t k = 0; k < m; ++k) chain_[k] = std::int32_t(root(k));
  }

  /// Distance from the structure beyond which a change of face is not a crossing (a particle that far has gone round
  /// it), m; and the smallest offset from the edge a particle is put back at, as a fraction of the edge's length.
  void set_limits(T reach, T min_offset) {
    require_positive("ThinStructureGuard reach (m)", reach);
    require_in_range("ThinStructureGuard min_offset (fraction of the edge length)", min_offset, T(0), T(0.5));
    reach_ = reach;
    min_offset_ = min_offset;
  }

  /// After a step: p.position_old and p.position hold every particle's positions at its start and end, the
  /// visibility's candidate edges are those of this step's neighbours. Returns the particles put back.
  template <class Particles>
  std::size_t restore(Particles& p, const ThinStructureVisibility<T>& visibility) {
    const auto& edges = visibility.edges();
    if (edges.size() != chain_.size())
      throw InputError(fmt::format("ThinStructureGuard: {} edges known, the visibility has {} (call set_edges)",
                                   chain_.size(), edges.size()));
    slots_.resize(edges.size());
    for (std::size_t k = 0; k < edges.size(); ++k) slots_[k] = {p.slot_of_id(edges[k][0]), p.slot_of_id(edges[k][1])};
    std::atomic<std::size_t> put_back{0};
    parallel_for(p.size(), [&](std::size_t f) {
      if (p.kind[f] != Kind::fluid || !visibility.near(f)) return;
      // The chains among this particle's candidates (few: one per blade within reach).
      std::array<std::int32_t, 8> seen{};
      std::size_t n_seen = 0;
      visibility.for_each_candidate(f, [&](std::int32_t e) {
        const std::int32_t c = chain_[e];
        if (std::find(seen.begin(), seen.begin() + n_seen, c) != seen.begin() + n_seen) return;
        if (n_seen < seen.size()) seen[n_seen++] = c;  // beyond 8 chains a chain may be checked twice: harmless
        if (keep_on_face(p, visibility, f, c)) put_back.fetch_add(1, std::memory_order_relaxed);
      });
    });
    total_ += put_back.load();
    return put_back.load();
  }

  /// Particles put back since construction.
  std::size_t crossings_prevented() const noexcept { return total_; }

 private:
  struct Nearest {
    T distance{std::numeric_limits<T>::infinity()};
    T face{0};  // +1: left of the edge's direction, -1: right
    std::int32_t edge{-1};
    T along{0};  // position of the nearest point along the edge, [0, 1]
  };

  /// Nearest point of x on chain c's candidate edges of slot f, with end points from `old` or current positions;
  /// edge -1 when there is none or it is a free end with x beyond it.
  template <class Particles>
  Nearest nearest(const Particles& p, const ThinStructureVisibility<T>& visibility, std::size_t f, std::int32_t c,
                  const Vector& x, bool old) const {
    Nearest best;
    bool beyond = false;
    visibility.for_each_candidate(f, [&](std::int32_t e) {
      if (chain_[e] != c) return;
      const auto [s0, s1] = slots_[e];
      const Vector& a = old ? p.position_old[s0] : p.position[s0];
      const Vector& b = old ? p.position_old[s1] : p.position[s1];
      const Vector t = b - a;
      const T length2 = t.squaredNorm();
      if (!(length2 > T(0))) return;
      const T s = (x - a).dot(t) / length2;
      const T along = std::clamp(s, T(0), T(1));
      const T d = (x - (a + along * t)).norm();
      if (d < best.distance) {
        const T cross = t[0] * (x - a)[1] - t[1] * (x - a)[0];
        best = {d, cross > T(0) ? T(1) : (cross < T(0) ? T(-1) : T(0)), e, along};
        beyond = (s < T(0) && free_start_[e]) || (s > T(1) && free_end_[e]);
      }
    });
    if (beyond) best.edge = -1;  // the nearest point is a free end, the particle beyond it: not beside the chain
    return best;
  }

  template <class Particles>
  bool keep_on_face(Particles& p, const ThinStructureVisibility<T>& visibility, std::size_t f, std::int32_t c) const {
    const Nearest before = nearest(p, visibility, f, c, p.position_old[f], true);
    if (before.edge < 0 || before.face == T(0) || !(before.distance < reach_)) return false;
    const Nearest after = nearest(p, visibility, f, c, p.position[f], false);
    if (after.edge < 0 || !(after.distance < reach_) || after.face == before.face) return false;
    // Back across the line of the nearest edge, to the face it started on, as far from the line as it was from the
    // structure at the start of the step (the mirror image of a small overshoot would sit deep in the coupling's
    // repulsion and be thrown off).
    const auto [s0, s1] = slots_[after.edge];
    const Vector a = p.position[s0], t = p.position[s1] - a;
    const T length = t.norm();
    const Vector normal = Vector(-t[1], t[0]) / length * before.face;  // towards the starting face
    const T offset = (p.position[f] - a).dot(normal);                  // <= 0: on the wrong side of the line
    p.position[f] += (std::max(before.distance, min_offset_ * length) - offset) * normal;
    const Vector edge_velocity = (T(1) - after.along) * p.velocity[s0] + after.along * p.velocity[s1];
    const T towards_wrong_face = (p.velocity[f] - edge_velocity).dot(normal);
    if (towards_wrong_face < T(0)) p.velocity[f] -= towards_wrong_face * normal;
    return true;
  }

  std::vector<std::int32_t> chain_;
  std::vector<bool> free_start_, free_end_;
  std::vector<std::array<std::size_t, 2>> slots_;
  T reach_{std::numeric_limits<T>::infinity()};
  T min_offset_{T(0.01)};
  std::size_t total_{0};
};

}  // namespace sphfsi
