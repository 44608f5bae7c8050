// sphfsi: a visibility criterion for particle pairs across thin structures (2D blades, 3D ribbons).
//
// A blade modelled as one line of nodes (solid/elastic_rod.hpp) has no particles of its own between its faces: the
// fluid particles on its two faces are within each other's kernel support and, without a criterion, interact
// through it in every SPH sum (pressure, viscosity, continuity). The blade then carries only part of the pressure
// difference, and the fluid leaks through it in the sums. The criterion used here is the one of meshless methods
// with cracks and thin walls: two particles interact only if the straight segment between them does not cross
// the structure: the "visibility criterion" for cracks of the element-free Galerkin method (Belytschko, Lu & Gu
// 1994, Int. J. Numer. Methods Eng. 37:229; reviewed in Belytschko et al. 1996, Comput. Methods Appl. Mech. Eng.
// 139:3). A pair (a, b) is blocked when x_a and x_b lie strictly on opposite sides of an edge x_i x_j's line and
// the edge's end points on opposite sides of the pair's line, half-open: an edge's first end point on that line
// counts as below it, its second as above. So a pair whose segment passes exactly through a node between two edges
// (a lattice line through the nodes) is hidden by exactly one of them, and a particle exactly on an edge is not. The
// structure's coupling policy then has to carry the whole load of each face (a blade holds the pressure of both sides,
// not only their difference).
//
// Candidate edges of a particle: the edges adjacent to the structure's nodes that have the particle within their
// kernel support (the system's own neighbour lists). For a blocked pair with crossing point c,
// |x_a - c| + |c - x_b| = r_ab < support, so the particle closer to c is within support / 2 of c and, for edges
// shorter than sqrt(3) x support, within the support of one of that edge's nodes: testing the candidates of both
// particles finds every blocked pair. Edges are given once as pairs of particle ids (they do not change over a
// run); their end points are read from the current positions at every evaluation.
//
// In 3D the structures are ribbons (solid/elastic_rod.hpp): strips bending in the x-z plane. An edge is then a strip
// element, the segment between two particles of consecutive rows swept along y over its lateral band [lo, hi] (the
// share of the width that particle stands for). A pair is blocked when its projection on the x-z plane crosses the
// edge's segment (the 2D test above) at a point whose y, interpolated along the pair, lies in the band. The
// candidate search is the same, from the edge's two particles; the band is at most the particles' support radius wide
// (checked), so that the crossing point lies within half a support laterally of them (a ribbon's bands are its rows'
// spacing, a fraction of the support).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace sphfsi {

/// Which pairs of particles a set of thin-structure edges hides from each other (see the header comment).
template <Real T, int Dim = 2>
class ThinStructureVisibility {
 public:
  static_assert(Dim == 2 || Dim == 3, "ThinStructureVisibility: 2D blades or 3D ribbons");
  using Vector = Vec<2, T>;  ///< in the structure's plane: (x, vertical)
  using SpaceVector = Vec<Dim, T>;
  using Band = std::array<T, 2>;

  /// Replaces the edges (ids of their end nodes; the nodes must be particles of the system). In 3D each edge has
  /// its lateral band [lo, hi] along y (lo < hi), one per edge.
  void set_edges(std::vector<StructureEdge> edges, std::vector<Band> bands = {}) {
    if (Dim == 3 && bands.size() != edges.size())
      throw InputError(
          fmt::format("ThinStructureVisibility: {} edges with {} lateral bands (valid: in 3D one band "
                      "[lo, hi] per edge; in 2D none)",
                      edges.size(), bands.size()));
    if (Dim == 2 && !bands.empty())
      throw InputError("ThinStructureVisibility: lateral bands are for 3D ribbons (valid in 2D: none)");
    for (std::size_t k = 0; k < bands.size(); ++k)
      if (!(bands[k][0] < bands[k][1]) || !std::isfinite(bands[k][0]) || !std::isfinite(bands[k][1]))
        throw InputError(
            fmt::format("ThinStructureVisibility: edge {} has the lateral band [{}, {}] m (valid: finite, "
                        "lo < hi)",
                        k, bands[k][0], bands[k][1]));
    edges_ = std::move(edges);
    bands_ = std::move(bands);
  }
  const std::vector<StructureEdge>& edges() const noexcept { return edges_; }
  /// Lateral band of edge k (3D), m.
  const Band& band(std::size_t k) const { return bands_[k]; }
  bool active() const noexcept { return !edges_.empty(); }

  /// Reads the edges' end points and builds each particle's candidate edges from the nodes' neighbour lists
  /// (neighbours must be current). Serial: a structure has few nodes.
  template <class System>
  void update(const System& system) {
    const auto& p = system.particles();
    const std::size_t n = p.size();
    head_.assign(n, -1);
    ids_.assign(p.id.begin(), p.id.end());
    entries_.clear();
    from_.resize(edges_.size());
    to_.resize(edges_.size());
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      for (int end = 0; end < 2; ++end) {
        if (!p.contains_id(edges_[k][end]))
          throw InputError(
              fmt::format("ThinStructureVisibility: edge {} names particle id {}, which is not in the "
                          "system (valid: ids of the structure's nodes)",
                          k, edges_[k][end]));
      }
      const std::size_t s0 = p.slot_of_id(edges_[k][0]), s1 = p.slot_of_id(edges_[k][1]);
      from_[k] = bending_plane(p.position[s0]);
      to_[k] = bending_plane(p.position[s1]);
      // The candidate search finds every hidden pair only for edges up to sqrt(3) x the nodes' support radius.
      const T reach =
          support_radius<typename System::kernel_type>(std::min(p.smoothing_length[s0], p.smoothing_length[s1]));
      if (!((to_[k] - from_[k]).norm() <= std::sqrt(T(3)) * reach))
        throw InputError(
            fmt::format("ThinStructureVisibility: edge {} is {:.4g} m long: valid range is up to "
                        "sqrt(3) x the nodes' support radius, {:.4g} m (refine the structure's nodes)",
                        k, double((to_[k] - from_[k]).norm()), double(std::sqrt(T(3)) * reach)));
      if (Dim == 3 && !(bands_[k][1] - bands_[k][0] <= reach))
        throw InputError(
            fmt::format("ThinStructureVisibility: edge {} has a lateral band {:.4g} m wide: valid range is "
                        "up to the nodes' support radius, {:.4g} m (more particles across the ribbon)",
                        k, double(bands_[k][1] - bands_[k][0]), double(reach)));
      for (const std::size_t s : {s0, s1}) {
        system.for_each_neighbor(s, [&](std::size_t f, const SpaceVector&, T, T) {
          if (p.kind[f] == Kind::solid) return;
          for (std::int32_t e = head_[f]; e >= 0; e = entries_[e].next)
            if (entries_[e].edge == std::int32_t(k)) return;
          entries_.push_back({std::int32_t(k), head_[f]});
          head_[f] = std::int32_t(entries_.size() - 1);
        });
      }
    }
  }

  /// Whether the candidate lists still fit the particle set: the same particles in the same slots as at update()
  /// (a model that splits, merges or re-sorts particles after the evaluation invalidates them).
  template <class Particles>
  bool matches(const Particles& p) const noexcept {
    return p.size() == ids_.size() && std::equal(ids_.begin(), ids_.end(), p.id.begin());
  }

  /// Whether slot a has any candidate edge (a pair with neither particle near an edge is never blocked).
  bool near(std::size_t a) const noexcept { return head_[a] >= 0; }

  /// Calls f(edge index) for each candidate edge of slot a (as found by the last update()).
  template <class F>
  void for_each_candidate(std::size_t a, F&& f) const {
    for (std::int32_t e = head_[a]; e >= 0; e = entries_[e].next) f(entries_[e].edge);
  }

  /// Whether the pair (a at xa, b at xb) is hidden by an edge: tests the candidates of both particles.
  bool blocks(std::size_t a, std::size_t b, const SpaceVector& xa, const SpaceVector& xb) const noexcept {
    return crosses_any(head_[a], xa, xb) || crosses_any(head_[b], xa, xb);
  }

  /// Whether the pair segment p0 p1 crosses the edge q0 q1: p0, p1 strictly on opposite sides of the edge's line,
  /// q0, q1 on opposite sides of the pair's line with q0 on it counted as below and q1 on it as above (half-open:
  /// a chain of edges through a point of the pair's line is crossed once).
  static bool segments_cross(const Vector& p0, const Vector& p1, const Vector& q0, const Vector& q1) noexcept {
    const auto orient = [](const Vector& o, const Vector& a, const Vector& b) {
      return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    };
    const T d1 = orient(q0, q1, p0), d2 = orient(q0, q1, p1);
    if (!((d1 > T(0) && d2 < T(0)) || (d1 < T(0) && d2 > T(0)))) return false;
    return (orient(p0, p1, q0) > T(0)) != (orient(p0, p1, q1) > T(0));
  }

 private:
  struct Entry {
    std::int32_t edge, next;
  };
  bool crosses_any(std::int32_t e, const SpaceVector& xa, const SpaceVector& xb) const noexcept {
    const Vector pa = bending_plane(xa), pb = bending_plane(xb);
    for (; e >= 0; e = entries_[e].next) {
      const std::int32_t k = entries_[e].edge;
      if (!segments_cross(pa, pb, from_[k], to_[k])) continue;
      if constexpr (Dim == 2) {
        return true;
      } else {  // where along the pair it meets the edge's line, and that point's y
        const Vector u = to_[k] - from_[k];
        const T da = u[0] * (pa[1] - from_[k][1]) - u[1] * (pa[0] - from_[k][0]);
        const T db = u[0] * (pb[1] - from_[k][1]) - u[1] * (pb[0] - from_[k][0]);
        const T y = xa[1] + (da / (da - db)) * (xb[1] - xa[1]);
        if (y >= bands_[k][0] && y <= bands_[k][1]) return true;
      }
    }
    return false;
  }

  std::vector<StructureEdge> edges_;
  std::vector<Band> bands_;         // 3D: lateral band of each edge
  std::vector<Vector> from_, to_;   // current end points of each edge
  std::vector<std::int32_t> head_;  // per slot: first candidate entry, -1: none
  std::vector<std::uint32_t> ids_;  // particle id per slot at update()
  std::vector<Entry> entries_;      // linked lists of candidate edges
};

}  // namespace sphfsi
