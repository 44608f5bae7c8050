// sphfsi: neighbour lists inside one solid body (internal).
//
// A compressed (CSR) list of the particles within support * h_ab + skin of each particle of a small point set,
// found with a uniform grid of cell size >= that radius. Solid models keep their own lists because only particles
// of the same body interact in the solid sums, and because sub-steps run between the system's neighbour updates.
#pragma once

#include <sphfsi/core/types.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace sphfsi::detail {

/// Neighbours of particle i are neighbor[offset[i]] .. neighbor[offset[i + 1] - 1] (i itself excluded).
struct PairList {
  std::vector<std::uint32_t> offset;
  std::vector<std::uint32_t> neighbor;

  std::size_t size() const noexcept { return offset.empty() ? 0 : offset.size() - 1; }
  template <class F>
  void for_each(std::size_t i, F&& f) const {
    for (std::uint32_t k = offset[i]; k < offset[i + 1]; ++k) f(neighbor[k]);
  }
};

/// Builds the list of pairs with |x_i - x_j| < support * (h_i + h_j) / 2 + skin.
template <int Dim, class T>
PairList build_pair_list(const std::vector<Vec<Dim, T>>& x, const std::vector<T>& h, T support, T skin) {
  PairList list;
  const std::size_t n = x.size();
  list.offset.assign(n + 1, 0);
  if (n == 0) return list;
  const T h_max = *std::max_element(h.begin(), h.end());
  const T cell = support * h_max + skin;
  Vec<Dim, T> lo = x[0], hi = x[0];
  for (const auto& xi : x) {
    lo = lo.cwiseMin(xi);
    hi = hi.cwiseMax(xi);
  }
  std::array<std::int64_t, Dim> count{};
  for (int d = 0; d < Dim; ++d) count[d] = std::int64_t((hi[d] - lo[d]) / cell) + 1;
  auto cell_of = [&](const Vec<Dim, T>& xi) {
    std::array<std::int64_t, Dim> c{};
    for (int d = 0; d < Dim; ++d) c[d] = std::min<std::int64_t>(count[d] - 1, std::int64_t((xi[d] - lo[d]) / cell));
    return c;
  };
  auto flat = [&](const std::array<std::int64_t, Dim>& c) {
    std::int64_t k = 0;
    for (int d = Dim - 1; d >= 0; --d) k = k * count[d] + c[d];
    return k;
  };
  std::int64_t cells = 1;
  for (int d = 0; d < Dim; ++d) cells *= count[d];
  std::vector<std::uint32_t> start(static_cast<std::size_t>(cells) + 1, 0), order(n);
  std::vector<std::int64_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    key[i] = flat(cell_of(x[i]));
    ++start[static_cast<std::size_t>(key[i]) + 1];
  }
  for (std::size_t c = 0; c < static_cast<std::size_t>(cells); ++c) start[c + 1] += start[c];
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n; ++i) order[fill[static_cast<std::size_t>(key[i])]++] = static_cast<std::uint32_t>(i);

  for (std::size_t i = 0; i < n; ++i) {
    const auto ci = cell_of(x[i]);
    std::array<std::int64_t, Dim> off{};
    off.fill(-1);
    while (true) {
      std::array<std::int64_t, Dim> c{};
      bool inside = true;
      for (int d = 0; d < Dim; ++d) {
        c[d] = ci[d] + off[d];
        inside = inside && c[d] >= 0 && c[d] < count[d];
      }
      if (inside) {
        const auto k = static_cast<std::size_t>(flat(c));
        for (std::uint32_t s = start[k]; s < start[k + 1]; ++s) {
          const std::uint32_t j = order[s];
          if (j == i) continue;
          const T radius = support * T(0.5) * (h[i] + h[j]) + skin;
          if ((x[i] - x[j]).squaredNorm() < radius * radius) list.neighbor.push_back(j);
        }
      }
      int d = 0;
      while (d < Dim && off[d] == 1) off[d++] = -1;
      if (d == Dim) break;
      ++off[d];
    }
    list.offset[i + 1] = static_cast<std::uint32_t>(list.neighbor.size());
  }
  return list;
}

}  // namespace sphfsi::detail
