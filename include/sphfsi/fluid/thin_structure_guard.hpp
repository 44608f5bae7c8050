// sphfsi: a guard that keeps fluid particles on their own face of a thin structure (2D blades, 3D ribbons).
//
// With the visibility criterion (thin_structure_visibility.hpp) the fluid on one face of a blade does not see the
// fluid on the other, so what keeps a particle on its face is the coupling's push from the line of nodes alone
// (coupling/repulsive_force.hpp). A particle driven hard enough, or met by a blade swinging into the water faster
// than the repulsion was sized for, can still step through that line within one time step; once across it sits in
// the other face's water and stays there. The guard acts at the end of each step on the fluid particles with
// candidate edges (those within the kernel support of a node). It is a continuous collision test: over the step the
// particle and the edge's end nodes are taken to move linearly from their old positions (position_old) to their new
// ones, and the particle has crossed the edge if, having started strictly on one side of the edge's line, it ends
// on the other side (or on it) and the point where it met the moving line lies on the edge (along-edge parameter in
// [0, 1]). The meeting time solves cross(b - a, x - a) = 0, a quadratic in time. A particle going round a tip, or
// between two blades, never meets an edge and is never touched. A particle that crossed is moved back across the
// line of the edge it met first, to the distance from that line it had at the start of the step (at least
// `min_offset` x the edge's length), and its velocity relative to the edge (node velocities interpolated) loses the
// component towards the wrong face: an inelastic collision with the edge. (A mirror image of a small overshoot would
// sit deep in the coupling's repulsion.) The corrected path is tested again: where it meets another edge (a folded
// blade, blades close together) the particle is put back across that one too, up to three times; a particle whose path
// still meets an edge then keeps its start offset from the point of the edge it met (it moves with the edge;
// counted by moved_with_edge()). The impulse is given to the fluid particle only (the blade does not feel
// it), so the guard is a last resort whose use is counted (crossings_prevented()): the coupling should make it rare.
// In 3D (ribbons bending in the x-z plane: thin_structure_visibility.hpp) the same test runs on the x-z projections,
// and a meeting counts only where the particle's y at the meeting time lies in the edge's lateral band; the put-back
// moves the particle and changes its velocity in the x-z plane only.
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
#include <vector>

namespace sphfsi {

/// Puts back the fluid particles that stepped through a thin structure (see the header comment).
template <Real T, int Dim = 2>
class ThinStructureGuard {
 public:
  using Vector = Vec<2, T>;  ///< in the structures' plane: (x, vertical)
  using Visibility = ThinStructureVisibility<T, Dim>;

  /// Where and when a moving point met a moving segment within a step.
  struct Meeting {
    T time{-1};   ///< fraction of the step, (0, 1]; -1: no crossing
    T along{0};   ///< position along the segment at that time, [0, 1]
    T side{0};    ///< +1: the point started left of a -> b, -1: right
    T offset{0};  ///< its distance from the segment's line at the start, m
  };

  /// Whether point x (x0 -> x1) crossed segment a b (a0 -> a1, b0 -> b1) within the step, all moving linearly: it
  /// started strictly on one side of the line, ended on the other side or on it, and met the line on the segment.
  static Meeting crossing(const Vector& x0, const Vector& x1, const Vector& a0, const Vector& a1, const Vector& b0,
                          const Vector& b1) noexcept {
    const auto cross = [](const Vector& u, const Vector& w) { return u[0] * w[1] - u[1] * w[0]; };
    const Vector u0 = b0 - a0, du = (b1 - a1) - u0, w0 = x0 - a0, dw = (x1 - a1) - w0;
    // c(t) = cross(u0 + t du, w0 + t dw) = c0 + t c1 + t^2 c2
    const T c0 = cross(u0, w0), c1 = cross(u0, dw) + cross(du, w0), c2 = cross(du, dw);
    const T end = c0 + c1 + c2;
    Meeting m;
    if (c0 == T(0) || (c0 > T(0) && end > T(0)) || (c0 < T(0) && end < T(0))) return m;
    // Exactly one root in (0, 1]: the sign changes over the step.
    T t;
    const T scale = std::abs(c0) + std::abs(c1) + std::abs(c2);
    if (std::abs(c2) <= T(1e-12) * scale) {
      t = -c0 / c1;
    } else {
      const T disc = std::max(c1 * c1 - T(4) * c2 * c0, T(0));
      const T q = T(-0.5) * (c1 + std::copysign(std::sqrt(disc), c1));  // stable roots q / c2 and c0 / q
      const T r1 = q / c2, r2 = q != T(0) ? c0 / q : T(2);
      const bool in1 = r1 > T(0) && r1 <= T(1), in2 = r2 > T(0) && r2 <= T(1);
      t = in1 && in2 ? std::min(r1, r2) : (in1 ? r1 : r2);
    }
    t = std::clamp(t, T(0), T(1));
    const Vector u = u0 + t * du, w = w0 + t * dw;
    const T length2 = u.squaredNorm();
    if (!(length2 > T(0))) return m;
    const T s = w.dot(u) / length2;
    if (s < T(0) || s > T(1)) return m;
    m.time = std::max(t, std::numeric_limits<T>::min());
    m.along = s;
    m.side = c0 > T(0) ? T(1) : T(-1);
    m.offset = std::abs(c0) / std::sqrt(u0.squaredNorm());
    return m;
  }

  /// The smallest distance from the edge's line a particle is put back at, as a fraction of the edge's length.
  void set_min_offset(T min_offset) {
    require_in_range("ThinStructureGuard min_offset (fraction of the edge length)", min_offset, T(0), T(0.5));
    min_offset_ = min_offset;
  }

  /// After a step: p.position_old and p.position hold every particle's positions at its start and end, the
  /// visibility's candidate edges are those of this step's neighbours. Returns the particles put back.
  template <class Particles>
  std::size_t restore(Particles& p, const Visibility& visibility) {
    const auto& edges = visibility.edges();
    slots_.resize(edges.size());
    for (std::size_t k = 0; k < edges.size(); ++k) slots_[k] = {p.slot_of_id(edges[k][0]), p.slot_of_id(edges[k][1])};
    std::atomic<std::size_t> put_back{0}, rode{0};
    parallel_for(p.size(), [&](std::size_t f) {
      if (p.kind[f] != Kind::fluid || !visibility.near(f)) return;
      // Put back across the first edge met; the corrected path may still meet another edge (a folded blade, two
      // blades close together): test again, up to three put-backs, then let the particle ride with the edge it met.
      Meeting first;
      std::int32_t edge = first_meeting(p, visibility, f, first);
      if (edge < 0) return;
      put_back.fetch_add(1, std::memory_order_relaxed);
      for (int put_backs = 0; edge >= 0; edge = first_meeting(p, visibility, f, first)) {
        if (put_backs++ == 3) {  // still crossing: keep its start offset from the point of the edge it met
          const auto [s0, s1] = slots_[edge];
          const Vector then =
              (T(1) - first.along) * plane(p.position_old[s0]) + first.along * plane(p.position_old[s1]);
          const Vector now = (T(1) - first.along) * plane(p.position[s0]) + first.along * plane(p.position[s1]);
          p.position[f] = p.position_old[f];
          add_in_plane(p.position[f], now - then);
          rode.fetch_add(1, std::memory_order_relaxed);
          break;
        }
        put_back_across(p, f, edge, first);
      }
    });
    total_ += put_back.load();
    rode_total_ += rode.load();
    return put_back.load();
  }

  /// Particles put back since construction.
  std::size_t crossings_prevented() const noexcept { return total_; }
  /// Of those, the ones whose path still met an edge after three put-backs and were moved with the edge instead.
  std::size_t moved_with_edge() const noexcept { return rode_total_; }

 private:
  /// The candidate edge slot f's path met first this step (-1: none), and the meeting.
  template <class Particles>
  std::int32_t first_meeting(const Particles& p, const Visibility& visibility, std::size_t f, Meeting& first) const {
    std::int32_t edge = -1;
    visibility.for_each_candidate(f, [&](std::int32_t e) {
      const auto [s0, s1] = slots_[e];
      const Meeting m = crossing(plane(p.position_old[f]), plane(p.position[f]), plane(p.position_old[s0]),
                                 plane(p.position[s0]), plane(p.position_old[s1]), plane(p.position[s1]));
      if (!(m.time > T(0))) return;
      if constexpr (Dim == 3) {  // the particle's y when it met the edge's line must lie in the edge's band
        const T y = p.position_old[f][1] + m.time * (p.position[f][1] - p.position_old[f][1]);
        if (y < visibility.band(std::size_t(e))[0] || y > visibility.band(std::size_t(e))[1]) return;
      }
      if (edge < 0 || m.time < first.time) first = m, edge = e;
    });
    return edge;
  }
  static Vector plane(const Vec<Dim, T>& x) { return bending_plane(x); }
  static void add_in_plane(Vec<Dim, T>& x, const Vector& d) {
    x[0] += d[0];
    x[Dim - 1] += d[1];
  }

  /// Back across the line of the edge it met, at the distance it had from that line at the start of the step; its
  /// velocity relative to the edge loses the component towards the wrong face.
  template <class Particles>
  void put_back_across(Particles& p, std::size_t f, std::int32_t edge, const Meeting& first) const {
    const auto [s0, s1] = slots_[edge];
    const Vector a = plane(p.position[s0]), t = plane(p.position[s1]) - a;
    const T length = t.norm();
    const Vector normal = Vector(-t[1], t[0]) / length * first.side;  // towards the starting face
    const T offset = (plane(p.position[f]) - a).dot(normal);          // <= 0: on the wrong side of the line
    add_in_plane(p.position[f], (std::max(first.offset, min_offset_ * length) - offset) * normal);
    const Vector edge_velocity = (T(1) - first.along) * plane(p.velocity[s0]) + first.along * plane(p.velocity[s1]);
    const T towards_wrong_face = (plane(p.velocity[f]) - edge_velocity).dot(normal);
    if (towards_wrong_face < T(0)) add_in_plane(p.velocity[f], -towards_wrong_face * normal);
  }

  std::vector<std::array<std::size_t, 2>> slots_;
  T min_offset_{T(0.01)};
  std::size_t total_{0}, rode_total_{0};
};

}  // namespace sphfsi
