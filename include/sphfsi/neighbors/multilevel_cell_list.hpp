// sphfsi: multi-level (hierarchical) cell lists for particles of several sizes, O(N).
//
// The nested hierarchical cell space of Ogarko & Luding 2012 (Comput. Phys. Commun. 183:931, "A fast multilevel
// algorithm for contact detection of arbitrarily polydisperse objects"; its cost model in Krijgsman, Ogarko &
// Luding 2014, Comput. Part. Mech. 1:357), applied to SPH pairs with the averaged smoothing length
// h_ab = (h_a + h_b) / 2, whose interaction radius is R_ab = support h_ab = (r_a + r_b) / 2 (r = support h).
//
// Level 0 is the single grid of neighbors/cell_list.hpp, cell edge e_0 = r_max (the largest support radius).
// Level k halves it k times, e_k = e_0 / 2^k, so that every level-k cell lies inside one level-0 cell, and holds
// the particles with r in (e_k / 2, e_k] (the finest level also takes anything smaller). A particle a finds its
// neighbours in every level l by scanning the level-l cells that overlap the box x_a +- max_b R_ab, with b over
// level l: at most 3 cells per axis on its own and coarser levels (R_ab <= e_l there), a few more on finer ones.
// A fine particle thus scans cells sized for fine particles, and a coarse one finds the fine particles around
// it without the fine particles' radius being forced up to the coarsest.
//
// Storage order: the particles are sorted by level-0 cell (the order of the single grid), and within a level-0
// cell by level, then by cell of their own level. The particles of each cell of each level are then contiguous
// (one slot range per cell), and every neighbour of a particle lies in the 3^D level-0 cells around it, so the
// reach of the pairs visited once (candidate_once_end) is that of the single grid: the per-thread spill buffers of
// the pair loops (fluid/wcsph.hpp) stay as small as with one grid. A level-0 particle with no finer particle in
// its 3^D level-0 cells has the single grid's candidates exactly, and keeps its contiguous rows (needs_levels()).
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_set.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/neighbors/cell_list.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace sphfsi {

template <int Dim, Real T>
class MultilevelCellList {
 public:
  using Vector = Vec<Dim, T>;

  /// Most levels: particles more than 2^(max_levels - 1) times smaller than the largest share the finest level.
  static constexpr int max_levels = 8;

  /// Sorts `particles` by level-0 cell of `coarse` (cell edge: the largest support radius support * h) and, within
  /// each, by level and cell of their level, then builds the index of every level. Returns the number of levels;
  /// with 1 (all support radii within a factor 2 of the largest) `coarse` is built as the plain single grid and
  /// this list must not be queried. Levels are added only while their cells (all fine levels together) number at
  /// most 16 (N + level-0 cells), which keeps memory and rebuild time O(N): smaller particles then share the
  /// finest level, which stays correct (its cells are larger than their radius), only slower.
  int build(ParticleSet<Dim, T>& particles, const Domain<Dim, T>& domain, T support, CellList<Dim, T>& coarse) {
    require_positive("MultilevelCellList support (smoothing lengths)", support);
    const std::size_t n = particles.size();
    T r_max = T(0), r_min = std::numeric_limits<T>::max();
    for (T h : particles.smoothing_length) {
      r_max = std::max(r_max, support * h);
      r_min = std::min(r_min, support * h);
    }
    if (!(r_max > T(0))) r_max = support;
    coarse.set_grid(domain, r_max);

    // How many levels: as many as the smallest radius needs, within the cell budget.
    std::array<std::int64_t, Dim> coarse_cells{};
    std::size_t coarse_total = 1;
    for (int d = 0; d < Dim; ++d) {
      coarse_cells[d] = coarse.cells_along(d);
      coarse_total *= static_cast<std::size_t>(coarse_cells[d]);
    }
    const std::size_t budget = 16 * (n + coarse_total);
    int levels = 1;
    std::size_t fine_total = 0;
    while (levels < max_levels && r_min * std::ldexp(T(1), levels) <= r_max) {
      const std::size_t cells = coarse_total << (levels * Dim);
      if (fine_total + cells > budget || coarse_total + fine_total + cells >= std::numeric_limits<std::uint32_t>::max())
        break;
      fine_total += cells;
      ++levels;
    }
    if (levels == 1) {
      coarse.build(particles, domain, r_max);
      levels_ = 1;
      return 1;
    }

    // The grid of every level and its place in the flat cell index.
    const bool same_layout = levels == levels_ && coarse_cells == level_[0].cells;
    std::size_t offset = 0;
    for (int l = 0; l < levels; ++l) {
      Level& level = level_[l];
      level.offset = offset;
      std::size_t total = 1;
      for (int d = 0; d < Dim; ++d) {
        level.cells[d] = coarse_cells[d] << l;
        total *= static_cast<std::size_t>(level.cells[d]);
      }
      offset += total;
      level.scale = std::ldexp(T(1), l);
      level.radius = T(0);
      level.min_radius = std::numeric_limits<T>::max();
      level.count = 0;
      level.first.fill(std::numeric_limits<std::int64_t>::max());
      level.last.fill(-1);
    }
    levels_ = levels;
    coarse_cell_size_ = r_max;
    inverse_coarse_cell_size_ = T(1) / r_max;

    // Level, grid coordinates and cell of every particle, in storage order.
    key_.resize(n);
    scratch_coordinates_.resize(n);
    scratch_radius_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const T r = support * particles.smoothing_length[i];
      int l = 0;
      while (l + 1 < levels && r * level_[l + 1].scale <= r_max) ++l;
      const Vector y = coarse.grid_coordinates(particles.position[i]);
      Level& level = level_[l];
      std::array<std::int64_t, Dim> c;
      key_[i] = cell_of(y, l, c);
      scratch_coordinates_[i] = y;
      scratch_radius_[i] = r;
      level.radius = std::max(level.radius, r);
      level.min_radius = std::min(level.min_radius, r);
      ++level.count;
      for (int d = 0; d < Dim; ++d) {
        level.first[d] = std::min(level.first[d], c[d]);
        level.last[d] = std::max(level.last[d], c[d]);
      }
    }
    // Sort: level-0 cell first (CellList, stable), then (level, cell of the level) within it.
    const std::uint32_t* key = key_.data();
    coarse.sort(particles, [key](std::uint32_t* first, std::uint32_t* last) {
      const auto before = [key](std::uint32_t a, std::uint32_t b) {
        return key[a] < key[b] || (key[a] == key[b] && a < b);
      };
      if (!std::is_sorted(first, last, before)) std::sort(first, last, before);
    });

    // Per-slot state in the new order; the slot range of every cell.
    if (same_layout) {
      for (std::uint32_t g : cell_) range_[2 * std::size_t(g)] = range_[2 * std::size_t(g) + 1] = 0;
    } else {
      range_.assign(2 * offset, 0);
    }
    const auto& order = coarse.order();
    cell_.resize(n);
    coordinates_.resize(n);
    radius_.resize(n);
    for (std::size_t s = 0; s < n; ++s) {
      const std::uint32_t from = order[s];
      const std::uint32_t g = key_[from];
      cell_[s] = g;
      coordinates_[s] = scratch_coordinates_[from];
      radius_[s] = scratch_radius_[from];
      if (range_[2 * std::size_t(g) + 1] == 0) range_[2 * std::size_t(g)] = static_cast<std::uint32_t>(s);
      range_[2 * std::size_t(g) + 1] = static_cast<std::uint32_t>(s + 1);
    }
    // Level-0 cells with finer particles in their 3^D neighbourhood; the particles of the other level-0 cells are
    // searched by the single grid alone (needs_levels()).
    const std::size_t coarse_cells_total = level_[1].offset;
    finer_near_.assign(coarse_cells_total, 0);
    for (std::size_t s = 0; s < n; ++s) {
      if (cell_[s] < coarse_cells_total) continue;  // a level-0 particle
      std::array<std::int64_t, Dim> c;
      const std::uint32_t own = cell_of(coordinates_[s], 0, c);
      if (finer_near_[own] & 2) continue;  // this cell's neighbourhood is marked already
      finer_near_[own] |= 2;
      std::array<std::int64_t, Dim> lo{}, hi{};
      for (int d = 0; d < Dim; ++d) {
        lo[d] = std::max<std::int64_t>(c[d] - 1, 0);
        hi[d] = std::min<std::int64_t>(c[d] + 1, coarse_cells[d] - 1);
      }
      for (std::int64_t z = Dim == 3 ? lo[Dim - 1] : 0; z <= (Dim == 3 ? hi[Dim - 1] : 0); ++z)
        for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
          for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
            finer_near_[static_cast<std::size_t>((z * coarse_cells[1] + y) * coarse_cells[0] + x)] |= 1;
    }
    needs_levels_.resize(n);
    for (std::size_t s = 0; s < n; ++s)
      needs_levels_[s] = cell_[s] >= coarse_cells_total || (finer_near_[cell_[s]] & 1) != 0;
    return levels;
  }

  /// Whether slot i needs the levels: it is finer than level 0, or finer particles lie in the 3^D level-0 cells
  /// around it. If not, its candidates are exactly those of the level-0 CellList (all of them level-0 particles),
  /// whose contiguous rows are the cheaper scan: ParticleSystem uses it for those particles.
  bool needs_levels(std::size_t i) const noexcept { return needs_levels_[i] != 0; }

  /// Calls f(j) for every particle j (i itself included) in the cells of every level that can hold a neighbour of
  /// slot i: |x_i - x_j| < (r_i + r_j) / 2 implies that j is visited.
  template <class F>
  void for_each_candidate(std::size_t i, F&& f) const {
    visit<false>(i, f);
  }

  /// Calls f(j) like for_each_candidate, but only for j > i: over all i every pair of candidates is visited exactly
  /// once. Every j lies in the 3^D level-0 cells around i, so below CellList::candidate_once_end(i).
  template <class F>
  void for_each_candidate_once(std::size_t i, F&& f) const {
    visit<true>(i, f);
  }

  /// for_each_candidate and for_each_candidate_once restricted to the levels that hold a particle whose support
  /// radius lies in [r_low, r_high]: pair loops that take partners of one size only (same_resolution_pairs) skip the
  /// cells of the other sizes. Candidates of other sizes that share a level with those are still passed to f.
  template <class F>
  void for_each_candidate_of_size(std::size_t i, T r_low, T r_high, F&& f) const {
    visit<false>(i, f, r_low, r_high);
  }
  template <class F>
  void for_each_candidate_once_of_size(std::size_t i, T r_low, T r_high, F&& f) const {
    visit<true>(i, f, r_low, r_high);
  }

  /// Number of levels of the last build (1: single grid).
  int levels() const noexcept { return levels_; }
  /// Cell edge of level l, m.
  T cell_size(int l) const noexcept { return std::ldexp(coarse_cell_size_, -l); }
  /// Particles in level l at the last build.
  std::size_t level_count(int l) const noexcept { return level_[l].count; }

 private:
  struct Level {
    std::array<std::int64_t, Dim> cells{};          // cells along each axis (level-0 cells times 2^l)
    std::size_t offset = 0;                         // first cell in the flat index
    T scale{1};                                     // 2^l: level-0 cell units to level-l cell units
    T radius{0};                                    // largest support radius of the level's particles, m
    T min_radius{0};                                // smallest support radius of the level's particles, m
    std::size_t count = 0;                          // particles in the level
    std::array<std::int64_t, Dim> first{}, last{};  // the cells the level's particles occupy: a bounding box
  };

  // Flat index of the level-l cell holding grid coordinates y (in level-0 cell units; scaling by 2^l is exact,
  // so the level-l cell lies inside the level-0 cell floor(y) of the CellList).
  // floor(v) as an integer, equal to static_cast<std::int64_t>(std::floor(v)) for the grid coordinates here (|v| far
  // below 2^62), without the libm call that std::floor is on baseline x86-64.
  static std::int64_t floor_index(T v) noexcept {
    const auto truncated = static_cast<std::int64_t>(v);
    return truncated - static_cast<std::int64_t>(v < static_cast<T>(truncated));
  }

  // Also returns the cell's coordinates along each axis in c.
  std::uint32_t cell_of(const Vector& y, int l, std::array<std::int64_t, Dim>& c) const {
    const Level& level = level_[l];
    const T scale = level.scale;
    std::int64_t index = 0, stride = 1;
    for (int d = 0; d < Dim; ++d) {
      c[d] = std::clamp<std::int64_t>(floor_index(y[d] * scale), 0, level.cells[d] - 1);
      index += c[d] * stride;
      stride *= level.cells[d];
    }
    return static_cast<std::uint32_t>(level.offset + static_cast<std::size_t>(index));
  }

  // Calls f(j) for the slots j of every cell, on every level, overlapping the box y_i +- reach: reach is the largest
  // pair radius (r_i + r_l) / 2 with that level, in level-0 cell units, plus a few ulps of the coordinates (the
  // rounding of x -> y must not drop a cell). With `once`, only j > i: the slots follow the level-0 cells in
  // lexicographic order (z, y, x), so the cells whose level-0 cell comes before i's hold only slots < i and are
  // skipped without being read (a level-l cell c lies in the level-0 cell c / 2^l); in i's own level-0 cell the
  // ranges are clipped at i + 1. Levels none of whose particles has a support radius in [r_low, r_high] are skipped.
  // f is taken by value: a local copy whose state the compiler can keep in registers.
  template <bool once, class F>
  void visit(std::size_t i, F f, T r_low = T(0), T r_high = std::numeric_limits<T>::infinity()) const {
    const Vector y = coordinates_[i];
    const T ri = radius_[i];
    const T slack = T(8) * std::numeric_limits<T>::epsilon() * (y.maxCoeff() + T(2));
    const std::size_t first = once ? i + 1 : 0;
    std::array<std::int64_t, Dim> own{};  // i's level-0 cell
    for (int d = 0; d < Dim; ++d) own[d] = std::clamp<std::int64_t>(floor_index(y[d]), 0, level_[0].cells[d] - 1);
    for (int l = 0; l < levels_; ++l) {
      const Level& level = level_[l];
      if (level.count == 0 || level.radius < r_low || level.min_radius > r_high) continue;
      const T reach = T(0.5) * (ri + level.radius) * inverse_coarse_cell_size_ + slack;
      const T scale = level.scale;
      // The box's cells, clipped to the cells the level occupies (a level confined to a region costs nothing to
      // the particles far from it).
      std::array<std::int64_t, Dim> lo{}, hi{};
      bool empty = false;
      for (int d = 0; d < Dim; ++d) {
        lo[d] = std::max(floor_index((y[d] - reach) * scale), level.first[d]);
        hi[d] = std::min(floor_index((y[d] + reach) * scale), level.last[d]);
        if constexpr (once) {
          if (d == Dim - 1) lo[d] = std::max(lo[d], own[d] << l);
        }
        empty = empty || lo[d] > hi[d];
      }
      if (empty) continue;
      // One row of cells along x; `own_row`: in the row of level-0 cells of i (skip the cells before i's). Cells
      // whose slot ranges follow each other (level-0 cells without finer particles, the level-l cells of a row
      // inside one level-0 cell) are scanned as one range, as the single grid scans a row of cells.
      const auto row = [&](std::size_t base, bool own_row) {
        const std::int64_t start = once && own_row ? std::max(lo[0], own[0] << l) : lo[0];
        std::size_t run_begin = 0, run_end = 0;
        for (std::int64_t cx = start; cx <= hi[0]; ++cx) {
          const std::size_t g = base + static_cast<std::size_t>(cx);
          const std::size_t begin = range_[2 * g], end = range_[2 * g + 1];
          if (begin == end) continue;
          if (begin != run_end) {
            for (std::size_t j = std::max(run_begin, first); j < run_end; ++j) f(j);
            run_begin = begin;
          }
          run_end = end;
        }
        for (std::size_t j = std::max(run_begin, first); j < run_end; ++j) f(j);
      };
      if constexpr (Dim == 2) {
        for (std::int64_t cy = lo[1]; cy <= hi[1]; ++cy)
          row(level.offset + static_cast<std::size_t>(cy * level.cells[0]), (cy >> l) == own[1]);
      } else {
        for (std::int64_t cz = lo[2]; cz <= hi[2]; ++cz) {
          const bool own_layer = (cz >> l) == own[2];
          const std::int64_t y_start = once && own_layer ? std::max(lo[1], own[1] << l) : lo[1];
          for (std::int64_t cy = y_start; cy <= hi[1]; ++cy)
            row(level.offset + static_cast<std::size_t>((cz * level.cells[1] + cy) * level.cells[0]),
                own_layer && (cy >> l) == own[1]);
        }
      }
    }
  }

  std::array<Level, max_levels> level_{};
  int levels_ = 1;
  T coarse_cell_size_{1}, inverse_coarse_cell_size_{1};  // level-0 cell edge r_max, m, and its inverse, 1/m
  std::vector<std::uint32_t> range_;                     // [begin, end) slots of every cell of every level
  std::vector<std::uint32_t> cell_;                      // flat cell of every slot
  std::vector<std::uint8_t> finer_near_;    // per level-0 cell: 1 finer particles in the 3^D cells, 2 in the cell
  std::vector<std::uint8_t> needs_levels_;  // per slot: needs_levels()
  std::vector<Vector> coordinates_;         // grid coordinates of every slot at the last build
  std::vector<T> radius_;                   // support radius of every slot, m
  std::vector<std::uint32_t> key_;          // build scratch, by storage order before the sort
  std::vector<Vector> scratch_coordinates_;
  std::vector<T> scratch_radius_;
};

}  // namespace sphfsi
