// sphfsi: cell-linked list neighbour search (Hockney & Eastwood 1988; Monaghan & Lattanzio 1985), O(N).
//
// The domain is cut into cubic cells of edge >= the largest interaction radius. A counting sort assigns
// particles to cells; the particle set is then permuted into cell order so that the particles of a cell, and
// of a row of neighbouring cells, are contiguous in memory. The grid has one empty ghost layer on each side,
// so the 3^D stencil needs no bounds checks; in the cell-ordered set the three cells of one stencil row form
// one contiguous particle range (3 ranges per particle in 2D, 9 in 3D).
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_set.hpp>
#include <sphfsi/core/types.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

namespace sphfsi {

template <int Dim, Real T>
class CellList {
 public:
  using Vector = Vec<Dim, T>;

  /// Sorts `particles` into cells of edge >= cell_size covering `domain` and (re)builds the cell index.
  /// Particles outside the domain must have been rejected before (see ParticleSystem::check_state).
  void build(ParticleSet<Dim, T>& particles, const Domain<Dim, T>& domain, T cell_size) {
    set_grid(domain, cell_size);
    sort(particles, KeepOrder{});
  }

  /// Lays the grid of cells of edge >= cell_size over `domain` without sorting anything yet (sort() does): lets a
  /// caller compute grid_coordinates() of the particles first (neighbors/multilevel_cell_list.hpp).
  void set_grid(const Domain<Dim, T>& domain, T cell_size) {
    require_positive("CellList cell_size (m)", cell_size);
    lower_ = domain.lower;
    std::size_t total = 1;
    for (int d = 0; d < Dim; ++d) {
      const T extent = domain.upper[d] - domain.lower[d];
      const auto cells = static_cast<std::int64_t>(std::floor(extent / cell_size)) + 1;
      if (cells > (std::int64_t(1) << 24) || (Dim == 3 && cells > 4096) || (Dim == 2 && cells > 65536))
        throw InputError(
            fmt::format("CellList: the domain extent {} m over a cell size of {} m gives {} cells along "
                        "axis {}: use a smaller domain or larger particles",
                        extent, cell_size, cells, d));
      cells_[d] = static_cast<std::int32_t>(cells) + 2;  // ghost layer on each side
      total *= static_cast<std::size_t>(cells_[d]);
    }
    // Cell indices are 32-bit (cell_of_): a 3D grid within the per-axis limit can still overflow them.
    if (total > std::numeric_limits<std::uint32_t>::max() - 1)
      throw InputError(
          fmt::format("CellList: the domain over a cell size of {} m needs {} cells (ghost layers "
                      "included), more than the 32-bit cell index allows ({}): use a smaller domain or "
                      "larger particles",
                      cell_size, total, std::numeric_limits<std::uint32_t>::max() - 1));
    inverse_cell_size_ = T(1) / cell_size;
    cell_size_ = cell_size;
    total_cells_ = total;
  }

  /// Sorts `particles` into the cells of the grid laid by set_grid() and permutes them into cell order. Within a
  /// cell, `within_cell(first, last)` may reorder the original particle indices [first, last) (std::uint32_t*),
  /// which are in storage order when it is called.
  template <class WithinCell>
  void sort(ParticleSet<Dim, T>& particles, WithinCell&& within_cell) {
    const std::size_t n = particles.size();
    const std::size_t total = total_cells_;
    cell_of_.resize(n);
    for (std::size_t i = 0; i < n; ++i) cell_of_[i] = cell_index(particles.position[i]);
    // Counting sort by cell: O(N + cells).
    cell_start_.assign(total + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++cell_start_[cell_of_[i] + 1];
    for (std::size_t c = 0; c < total; ++c) cell_start_[c + 1] += cell_start_[c];
    order_.resize(n);
    cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order_[cursor_[cell_of_[i]]++] = static_cast<std::uint32_t>(i);
    if constexpr (!std::is_same_v<std::remove_cvref_t<WithinCell>, KeepOrder>) {
      for (std::size_t c = 0; c < total; ++c)
        if (cell_start_[c + 1] - cell_start_[c] > 1)
          within_cell(order_.data() + cell_start_[c], order_.data() + cell_start_[c + 1]);
    }
    particles.permute(order_);
    // Slots are now in cell order: the cell of slot i is the cell its particle was sorted into.
    for (std::size_t c = 0; c < total; ++c)
      for (std::uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) cell_of_[i] = static_cast<std::uint32_t>(c);
  }

  /// Calls f(j) for every particle j in the 3^D cells around particle i's cell (i itself included).
  template <class F>
  void for_each_candidate(std::size_t i, F&& f) const {
    const std::uint32_t c = cell_of_[i];
    if constexpr (Dim == 2) {
      const std::int64_t nx = cells_[0];
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const std::int64_t row = static_cast<std::int64_t>(c) + dy * nx;
        const std::uint32_t begin = cell_start_[row - 1], end = cell_start_[row + 2];
        for (std::uint32_t j = begin; j < end; ++j) f(static_cast<std::size_t>(j));
      }
    } else {
      const std::int64_t nx = cells_[0], nxy = std::int64_t(cells_[0]) * cells_[1];
      for (std::int64_t dz = -1; dz <= 1; ++dz)
        for (std::int64_t dy = -1; dy <= 1; ++dy) {
          const std::int64_t row = static_cast<std::int64_t>(c) + dy * nx + dz * nxy;
          const std::uint32_t begin = cell_start_[row - 1], end = cell_start_[row + 2];
          for (std::uint32_t j = begin; j < end; ++j) f(static_cast<std::size_t>(j));
        }
    }
  }

  /// Calls f(j) for every particle j > i of the half stencil of particle i's cell: the rest of i's own stencil
  /// row, the row above (and in 3D the whole layer above). Over all i every pair of particles in neighbouring
  /// cells is visited exactly once, so pair forces can be evaluated once and applied to both particles.
  template <class F>
  void for_each_candidate_once(std::size_t i, F&& f) const {
    const std::uint32_t c = cell_of_[i];
    const std::uint32_t own_end = cell_start_[c + 2];
    for (std::uint32_t j = static_cast<std::uint32_t>(i) + 1; j < own_end; ++j) f(static_cast<std::size_t>(j));
    const std::int64_t nx = cells_[0];
    if constexpr (Dim == 2) {
      const std::int64_t row = static_cast<std::int64_t>(c) + nx;
      const std::uint32_t begin = cell_start_[row - 1], end = cell_start_[row + 2];
      for (std::uint32_t j = begin; j < end; ++j) f(static_cast<std::size_t>(j));
    } else {
      const std::int64_t nxy = std::int64_t(cells_[0]) * cells_[1];
      // row (dy = +1, dz = 0), then the three rows of the layer dz = +1
      const std::int64_t rows[4] = {nx, nxy - nx, nxy, nxy + nx};
      for (std::int64_t offset : rows) {
        const std::int64_t row = static_cast<std::int64_t>(c) + offset;
        const std::uint32_t begin = cell_start_[row - 1], end = cell_start_[row + 2];
        for (std::uint32_t j = begin; j < end; ++j) f(static_cast<std::size_t>(j));
      }
    }
  }

  /// One past the largest slot for_each_candidate_once(i, f) can visit (the cells are in slot order).
  std::size_t candidate_once_end(std::size_t i) const {
    const std::int64_t c = cell_of_[i], nx = cells_[0];
    const std::int64_t last_row = Dim == 2 ? c + nx : c + nx + std::int64_t(cells_[0]) * cells_[1];
    return cell_start_[last_row + 2];
  }

  T cell_size() const noexcept { return cell_size_; }
  std::size_t cell_count() const noexcept { return cell_start_.empty() ? 0 : cell_start_.size() - 1; }
  /// Number of cells along axis d, ghost layers not counted.
  std::int64_t cells_along(int d) const noexcept { return cells_[d] - 2; }
  /// Position x in cell units from the domain's lower corner, (x - lower) / cell size: the cell of x along axis d
  /// is floor of component d (clamped to the grid). Every cell index of this class is computed from it.
  Vector grid_coordinates(const Vector& x) const { return (x - lower_) * inverse_cell_size_; }
  /// The permutation of the last sort(): slot s now holds the particle that was in slot order()[s] before.
  const std::vector<std::uint32_t>& order() const noexcept { return order_; }

 private:
  struct KeepOrder {};  // sort(): no reordering within a cell

  std::uint32_t cell_index(const Vector& x) const {
    const Vector y = grid_coordinates(x);
    std::int64_t index = 0, stride = 1;
    for (int d = 0; d < Dim; ++d) {
      auto c = static_cast<std::int64_t>(std::floor(y[d])) + 1;
      c = std::clamp<std::int64_t>(c, 1, cells_[d] - 2);
      index += c * stride;
      stride *= cells_[d];
    }
    return static_cast<std::uint32_t>(index);
  }

  Vector lower_ = Vector::Zero();
  T inverse_cell_size_{1}, cell_size_{1};
  std::size_t total_cells_{0};
  std::array<std::int32_t, Dim> cells_{};
  std::vector<std::uint32_t> cell_of_, cell_start_, cursor_, order_;
};

}  // namespace sphfsi
