// The cell-linked list and ParticleSystem::for_each_neighbor against a brute-force O(N^2) search.
//
// The neighbour set of particle a is { b != a : |x_a - x_b| < support h_ab }, h_ab = (h_a + h_b) / 2. The cell
// list must find exactly that set: any particle missed is a lost interaction, any extra one a wasted pair. The
// sets are compared by stable particle id, because update_neighbors() re-sorts the particles by cell. The point
// sets are random, with mixed smoothing lengths, plus particles placed exactly on cell edges (and a few ulps to
// either side of them) and on the domain boundary, where a rounding in the cell index could skip a cell.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/linear.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/kernel/quintic_spline.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/builders.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace {

using namespace sphfsi;

template <int D, class T>
struct NeighborCase {
  static constexpr int dimension = D;
  using scalar = T;
};

/// Neighbour sets by id, by definition: every pair tested.
template <class System>
std::vector<std::set<std::uint32_t>> brute_force_neighbours(const System& system) {
  using T = typename System::scalar_type;
  const auto& p = system.particles();
  const T support = static_cast<T>(System::kernel_type::support);
  std::vector<std::set<std::uint32_t>> sets(p.size());
  for (std::size_t a = 0; a < p.size(); ++a)
    for (std::size_t b = 0; b < p.size(); ++b) {
      if (a == b) continue;
      const T radius = support * T(0.5) * (p.smoothing_length[a] + p.smoothing_length[b]);
      if ((p.position[a] - p.position[b]).squaredNorm() < radius * radius) sets[p.id[a]].insert(p.id[b]);
    }
  return sets;
}

/// Checks that the search found exactly the brute-force sets (by id), and that they are not vacuous: several
/// neighbours per particle on average.
inline void check_same_neighbours(const std::vector<std::set<std::uint32_t>>& found,
                                  const std::vector<std::set<std::uint32_t>>& expected) {
  const std::size_t n = expected.size();
  std::size_t missed = 0, spurious = 0, pairs = 0;
  for (std::size_t id = 0; id < n; ++id) {
    pairs += expected[id].size();
    for (std::uint32_t j : expected[id]) missed += !found[id].count(j);
    for (std::uint32_t j : found[id]) spurious += !expected[id].count(j);
  }
  CAPTURE(pairs);
  CHECK(pairs > 3 * n);
  CHECK(missed == 0);
  CHECK(spurious == 0);
}

/// Neighbour sets by id as ParticleSystem::for_each_neighbor reports them; also checks the arguments it passes.
template <class System>
std::vector<std::set<std::uint32_t>> cell_list_neighbours(const System& system) {
  using T = typename System::scalar_type;
  const auto& p = system.particles();
  std::vector<std::set<std::uint32_t>> sets(p.size());
  std::size_t bad_arguments = 0, duplicates = 0;
  for (std::size_t a = 0; a < p.size(); ++a)
    system.for_each_neighbor(a, [&](std::size_t b, const auto& dx, T r, T h_ab) {
      if (!(dx == p.position[a] - p.position[b]) || r != dx.norm() ||
          h_ab != T(0.5) * (p.smoothing_length[a] + p.smoothing_length[b]))
        ++bad_arguments;
      if (!sets[p.id[a]].insert(p.id[b]).second) ++duplicates;
    });
  CHECK(bad_arguments == 0);
  CHECK(duplicates == 0);
  return sets;
}

/// Index of the cell holding x (z slowest), as the cell list defines it: floor((x - lower) / cell size),
/// clamped to the grid.
template <int Dim, class T>
std::int64_t cell_key(const Vec<Dim, T>& x, const Domain<Dim, T>& domain, T cell_size) {
  std::int64_t key = 0;
  for (int d = Dim - 1; d >= 0; --d) {
    const T inverse = T(1) / cell_size;
    const auto cells = static_cast<std::int64_t>(std::floor((domain.upper[d] - domain.lower[d]) / cell_size)) + 1;
    auto c = static_cast<std::int64_t>(std::floor((x[d] - domain.lower[d]) * inverse));
    c = std::clamp<std::int64_t>(c, 0, cells - 1);
    key = key * (cells + 2) + c;
  }
  return key;
}

}  // namespace

// The dimension and scalar combinations of the brute-force comparisons. Under the sanitizers (tests/sanitizers) two of
// them, which still cover both dimensions and both scalars: each combination is a separate instantiation of the
// search, and at -O1 with ASan + UBSan the four took 153 s of compiling, the largest sanitized unit.
#ifdef SPHFSI_SANITIZED_UNIT_TESTS
#define SPHFSI_NEIGHBOR_CASES (NeighborCase<2, double>), (NeighborCase<3, float>)
#else
#define SPHFSI_NEIGHBOR_CASES \
  (NeighborCase<2, double>), (NeighborCase<3, double>), (NeighborCase<2, float>), (NeighborCase<3, float>)
#endif

TEMPLATE_TEST_CASE("cell list finds exactly the brute-force neighbour sets", "[neighbors]", SPHFSI_NEIGHBOR_CASES) {
  constexpr int Dim = TestType::dimension;
  using T = typename TestType::scalar;
  using Vector = Vec<Dim, T>;
  using Kernel = CubicSpline<Dim>;
  using System = ParticleSystem<Dim, T, Kernel, LinearEos<T>>;

  // An off-centre domain, so that lower != 0 exercises the offset in the cell index.
  const Vector lower = Vector::Constant(T(-0.37)), upper = Vector::Constant(T(0.61));
  const Domain<Dim, T> domain(lower, upper);
  const T h_max = T(0.05);  // cell size support * h_max = 0.1 m: about 10 cells per axis
  const T cell_size = static_cast<T>(Kernel::support) * h_max;
  const std::size_t random_count = Dim == 2 ? 800 : 4000;
  const auto seed = GENERATE(1u, 2u, 3u);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  CAPTURE(Dim, sizeof(T), seed);

  System system(domain, LinearEos<T>(T(1000), T(20)));
  auto& p = system.particles();
  auto add = [&](const Vector& x, T h) { p.add(Kind::fluid, x, Vector::Zero(), T(1000), T(1), h); };
  auto random_point = [&] {
    Vector x;
    for (int d = 0; d < Dim; ++d) x[d] = lower[d] + static_cast<T>(unit(rng)) * (upper[d] - lower[d]);
    return x;
  };

  // Random particles with smoothing lengths spread over a factor 4 (mixed resolution); one carries h_max.
  for (std::size_t i = 0; i < random_count; ++i) add(random_point(), h_max * static_cast<T>(0.25 + 0.75 * unit(rng)));
  add(random_point(), h_max);
  // Particles on cell edges (cell edges lie at lower + k * cell_size) and up to 3 ulps either side, all with
  // h = h_max so that their interaction radius equals the cell size: the tightest case for the 3^D stencil.
  const int edges = static_cast<int>(std::floor((upper[0] - lower[0]) / cell_size));
  for (int k = 1; k <= edges; ++k) {
    const T edge = lower[0] + T(k) * cell_size;
    T below = edge, above = edge;
    for (int ulp = 0; ulp <= 3; ++ulp) {
      for (T coordinate : {below, above}) {
        Vector x = random_point();
        x[0] = coordinate;
        add(x, h_max);
        x[Dim - 1] = coordinate;  // on an edge in two directions (a cell corner in 2D)
        add(x, h_max);
      }
      below = std::nextafter(below, -std::numeric_limits<T>::infinity());
      above = std::nextafter(above, std::numeric_limits<T>::infinity());
    }
  }
  // Pairs exactly one cell size apart across an edge: |dx| == radius is NOT a neighbour (strict <), and the
  // pair one ulp closer is.
  for (int k = 1; k < edges; ++k) {
    Vector x = random_point();
    x[0] = lower[0] + T(k - 1) * cell_size + cell_size * T(0.5);
    add(x, h_max);
    x[0] += cell_size;
    add(x, h_max);
    x[0] = std::nextafter(x[0], -std::numeric_limits<T>::infinity());
    add(x, h_max);
  }
  // Particles on the domain boundary: faces, and the two extreme corners.
  for (int d = 0; d < Dim; ++d)
    for (const Vector* face : {&lower, &upper}) {
      Vector x = random_point();
      x[d] = (*face)[d];
      add(x, h_max);
    }
  add(lower, h_max);
  add(upper, h_max);
  add(lower, T(0.3) * h_max);  // same position, different h
  const std::size_t n = p.size();
  std::vector<Vector> created_position(p.position);

  const auto expected = brute_force_neighbours(system);
  for (int pass = 0; pass < 2; ++pass) {
    CAPTURE(pass);
    system.update_neighbors();
    REQUIRE(p.size() == n);
    CHECK(system.cells().cell_size() == cell_size);

    // The particles are a permutation of the created ones; every field travelled with its id.
    std::vector<bool> seen(n, false);
    for (std::size_t i = 0; i < n; ++i) {
      REQUIRE(p.id[i] < n);
      REQUIRE_FALSE(seen[p.id[i]]);
      seen[p.id[i]] = true;
      REQUIRE(p.slot_of_id(p.id[i]) == i);
      REQUIRE(p.position[i] == created_position[p.id[i]]);
    }

    // Sorted by cell: the cell key never decreases along the particle array.
    std::size_t out_of_order = 0;
    for (std::size_t i = 1; i < n; ++i)
      out_of_order += cell_key(p.position[i], domain, cell_size) < cell_key(p.position[i - 1], domain, cell_size);
    CHECK(out_of_order == 0);

    check_same_neighbours(cell_list_neighbours(system), expected);

    // Second pass: shuffle the storage order (as if particles had moved) and search again.
    std::vector<std::uint32_t> order(n);
    for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    p.permute(order);
  }
}

TEMPLATE_TEST_CASE("a particle outside the domain stops update_neighbors with a BlowUpError naming it", "[neighbors]",
                   (NeighborCase<2, double>), (NeighborCase<3, float>)) {
  constexpr int Dim = TestType::dimension;
  using T = typename TestType::scalar;
  using Vector = Vec<Dim, T>;
  ParticleSystem<Dim, T, QuinticSpline<Dim>, LinearEos<T>> system(Domain<Dim, T>(Vector::Zero(), Vector::Ones()),
                                                                  LinearEos<T>(T(1000), T(20)));
  auto& p = system.particles();
  for (int i = 0; i < 20; ++i)
    p.add(Kind::fluid, Vector::Constant(T(0.04) * T(i + 1)), Vector::Zero(), T(1000), T(1), T(0.02));
  REQUIRE_NOTHROW(system.update_neighbors());

  // Particle id 13 drifts just past the upper face along the last axis.
  const std::size_t slot = p.slot_of_id(13);
  p.position[slot][Dim - 1] = std::nextafter(T(1), T(2));
  CHECK_THROWS_AS(system.update_neighbors(T(0.25)), BlowUpError);
  CHECK_THROWS_WITH(system.update_neighbors(T(0.25)),
                    Catch::Matchers::Contains("particle id 13") && Catch::Matchers::Contains("left the domain"));
  // A NaN position is reported as such.
  p.position[slot][0] = std::numeric_limits<T>::quiet_NaN();
  CHECK_THROWS_WITH(system.update_neighbors(),
                    Catch::Matchers::Contains("particle id 13") && Catch::Matchers::Contains("position"));
}

TEST_CASE("a cell grid too large for the 32-bit cell index is rejected with an InputError", "[neighbors]") {
  // 4000 cells per axis is within the per-axis limit, but 4002^3 cells (ghost layers included) overflow a
  // 32-bit cell index; the cell list must refuse before allocating the index.
  using Vector = Vec<3, double>;
  ParticleSystem<3, double, CubicSpline<3>, LinearEos<double>> system(
      Domain<3, double>(Vector::Zero(), Vector::Constant(3999.5)), LinearEos<double>(1000.0, 20.0));
  system.particles().add(Kind::fluid, Vector::Constant(1.0), Vector::Zero(), 1000.0, 1.0, 0.5);  // cell size 1 m
  CHECK_THROWS_AS(system.update_neighbors(), InputError);
  CHECK_THROWS_WITH(system.update_neighbors(), Catch::Matchers::Contains("32-bit cell index"));
}

// ---- The multi-level search (neighbors/multilevel_cell_list.hpp) -------------------------------------------------
//
// Scenes with sizes more than a factor 2 apart are searched with one nested grid per size level. Its neighbour sets
// must be exactly the brute-force ones for for_each_neighbor, and for_each_neighbor_once must visit every
// neighbour pair exactly once, from the particle with the smaller slot, within [i + 1, neighbor_once_end(i)).
// The point sets mix 2 and 3 levels (ratios 2 and 4, and a ratio-4 pair of sizes with the middle level empty),
// particles on the cell edges of every level (and a few ulps off), and pairs of different levels placed exactly
// at their pair radius support (h_a + h_b) / 2 and one ulp inside it.

namespace {

/// The unordered neighbour pairs (smaller id first) of neighbour sets by id.
std::set<std::pair<std::uint32_t, std::uint32_t>> unordered_pairs(const std::vector<std::set<std::uint32_t>>& sets) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::uint32_t a = 0; a < sets.size(); ++a)
    for (std::uint32_t b : sets[a]) pairs.emplace(std::min(a, b), std::max(a, b));
  return pairs;
}

struct MultilevelCase {
  const char* name;
  std::vector<double> sizes;  // smoothing lengths as fractions of the largest
  int levels;                 // levels the search must build
};

}  // namespace

TEMPLATE_TEST_CASE("multi-level search finds exactly the brute-force neighbours and each pair once",
                   "[neighbors][multilevel]", SPHFSI_NEIGHBOR_CASES) {
  constexpr int Dim = TestType::dimension;
  using T = typename TestType::scalar;
  using Vector = Vec<Dim, T>;
  using Kernel = CubicSpline<Dim>;
  using System = ParticleSystem<Dim, T, Kernel, LinearEos<T>>;

  const auto scene = GENERATE(MultilevelCase{"ratio 2", {1.0, 0.5}, 2}, MultilevelCase{"ratio 4", {1.0, 0.25}, 3},
                              MultilevelCase{"ratios 2 and 4", {1.0, 0.5, 0.25}, 3},
                              MultilevelCase{"spread 0.2 to 1", {1.0, 0.7, 0.45, 0.3, 0.2}, 3});
  const auto seed = GENERATE(1u, 2u);
  CAPTURE(Dim, sizeof(T), scene.name, seed);
  const Vector lower = Vector::Constant(T(-0.37)), upper = Vector::Constant(T(Dim == 2 ? 0.61 : 0.43));
  const Domain<Dim, T> domain(lower, upper);
  const T h_max = T(0.05);
  const T support = static_cast<T>(Kernel::support);
  const T coarse_cell = support * h_max;  // 0.1 m
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);

  System system(domain, LinearEos<T>(T(1000), T(20)));
  auto& p = system.particles();
  auto add = [&](const Vector& x, T h) { p.add(Kind::fluid, x, Vector::Zero(), T(1000), T(1), h); };
  auto random_point = [&] {
    Vector x;
    for (int d = 0; d < Dim; ++d) x[d] = lower[d] + static_cast<T>(unit(rng)) * (upper[d] - lower[d]);
    return x;
  };
  auto random_size = [&] {
    return h_max * static_cast<T>(scene.sizes[std::min<std::size_t>(
                       scene.sizes.size() - 1, static_cast<std::size_t>(unit(rng) * scene.sizes.size()))]);
  };
  // Random particles of the scene's sizes. In 3D, 3000 of them in 9^3 level-0 cells: enough for the cell budget
  // (16 (N + level-0 cells) fine cells) to allow level 1's 18^3 and level 2's 36^3 cells.
  const std::size_t random_count = Dim == 2 ? 1500 : 3000;
  for (std::size_t i = 0; i < random_count; ++i) add(random_point(), random_size());
  for (double s : scene.sizes) add(random_point(), h_max * static_cast<T>(s));  // every size present
  // On the cell edges of every level l (lower + k e_0 / 2^l), up to 2 ulps either side, in one and two directions.
  for (int level = 0; level < scene.levels; ++level) {
    const T edge_spacing = std::ldexp(coarse_cell, -level);
    double size = scene.sizes.back();  // the largest size of this level, else the smallest size
    for (double s : scene.sizes)
      if (s <= std::ldexp(1.0, -level) && s > std::ldexp(1.0, -level - 1)) size = std::max(size, s);
    const T h = h_max * static_cast<T>(size);
    const int edges = static_cast<int>(std::floor((upper[0] - lower[0]) / edge_spacing));
    for (int k = 1; k < edges; k += std::max(1, edges / 8)) {
      const T edge = lower[0] + T(k) * edge_spacing;
      T below = edge, above = edge;
      for (int ulp = 0; ulp <= 2; ++ulp) {
        for (T coordinate : {below, above}) {
          Vector x = random_point();
          x[0] = coordinate;
          add(x, h);
          x[Dim - 1] = coordinate;
          add(x, random_size());
        }
        below = std::nextafter(below, -std::numeric_limits<T>::infinity());
        above = std::nextafter(above, std::numeric_limits<T>::infinity());
      }
    }
  }
  // Pairs of different sizes exactly at their pair radius support (h_a + h_b) / 2 (not neighbours: strict <), and
  // one ulp inside (neighbours), along a random axis, across a cell edge of the coarse grid.
  for (std::size_t a = 0; a < scene.sizes.size(); ++a)
    for (std::size_t b = a + 1; b < scene.sizes.size(); ++b)
      for (int k = 1; k <= 6; ++k) {  // 6 level-0 cell edges inside the domain (7 or more in 2D and 3D)
        const T ha = h_max * static_cast<T>(scene.sizes[a]), hb = h_max * static_cast<T>(scene.sizes[b]);
        const T radius = support * (T(0.5) * (ha + hb));
        const int axis = static_cast<int>(unit(rng) * Dim) % Dim;
        Vector x = random_point();
        x[axis] = lower[axis] + T(k) * coarse_cell - T(0.5) * radius;
        add(x, ha);
        Vector y = x;
        y[axis] = x[axis] + radius;
        add(y, hb);
        y[axis] = std::nextafter(y[axis], -std::numeric_limits<T>::infinity());
        add(y, hb);
      }
  add(lower, h_max * static_cast<T>(scene.sizes.back()));
  add(upper, h_max * static_cast<T>(scene.sizes.back()));
  const std::size_t n = p.size();

  const auto expected = brute_force_neighbours(system);
  const auto expected_pairs = unordered_pairs(expected);
  for (int pass = 0; pass < 2; ++pass) {
    CAPTURE(pass);
    system.update_neighbors();
    REQUIRE(system.multilevel_search());
    CHECK(system.levels().levels() == scene.levels);
    CHECK(system.cells().cell_size() == coarse_cell);
    // Stored in level-0 cell order, as with the single grid.
    std::size_t out_of_order = 0;
    for (std::size_t i = 1; i < n; ++i)
      out_of_order += cell_key(p.position[i], domain, coarse_cell) < cell_key(p.position[i - 1], domain, coarse_cell);
    CHECK(out_of_order == 0);

    check_same_neighbours(cell_list_neighbours(system), expected);

    // Each pair once, from the smaller slot, below neighbor_once_end.
    std::set<std::pair<std::uint32_t, std::uint32_t>> once;
    std::size_t repeated = 0, not_after = 0, beyond_end = 0;
    for (std::size_t a = 0; a < n; ++a) {
      const std::size_t end = system.neighbor_once_end(a);
      system.for_each_neighbor_once(a, [&](std::size_t b, const auto&, T, T) {
        not_after += b <= a;
        beyond_end += b >= end;
        const std::uint32_t ia = p.id[a], ib = p.id[b];
        repeated += !once.emplace(std::min(ia, ib), std::max(ia, ib)).second;
      });
    }
    CHECK(repeated == 0);
    CHECK(not_after == 0);
    CHECK(beyond_end == 0);
    CHECK(once == expected_pairs);

    // Restricted to one size band (pair loops of one resolution, a particle's children): every brute-force
    // neighbour whose h lies within the band is visited (once per pair with the _once form, which asks for the
    // visiting particle's own size), and nothing visited is not a neighbour.
    for (const double tolerance : {1e-3, 0.25}) {
      CAPTURE(tolerance);
      std::set<std::pair<std::uint32_t, std::uint32_t>> same_size_once;
      std::size_t missed = 0, false_neighbours = 0, repeated_same = 0, missed_half = 0;
      for (std::size_t a = 0; a < n; ++a) {
        const T ha = p.smoothing_length[a];
        const auto in_band = [&](T h, T centre) { return std::abs(h - centre) <= T(tolerance) * centre; };
        std::set<std::uint32_t> own, half;
        system.for_each_neighbor_of_size(a, ha, T(tolerance), [&](std::size_t b, const auto&, T, T) {
          false_neighbours += !expected[p.id[a]].count(p.id[b]);
          own.insert(p.id[b]);
        });
        system.for_each_neighbor_of_size(a, T(0.5) * ha, T(tolerance), [&](std::size_t b, const auto&, T, T) {
          false_neighbours += !expected[p.id[a]].count(p.id[b]);
          half.insert(p.id[b]);
        });
        system.for_each_neighbor_once_of_size(a, ha, T(tolerance), [&](std::size_t b, const auto&, T, T) {
          if (!in_band(p.smoothing_length[b], ha)) return;
          repeated_same += !same_size_once.emplace(std::min(p.id[a], p.id[b]), std::max(p.id[a], p.id[b])).second;
        });
        for (std::uint32_t ib : expected[p.id[a]]) {
          const T hb = p.smoothing_length[p.slot_of_id(ib)];
          missed += in_band(hb, ha) && !own.count(ib);
          missed_half += in_band(hb, T(0.5) * ha) && !half.count(ib);
        }
      }
      std::set<std::pair<std::uint32_t, std::uint32_t>> expected_same;
      for (const auto& [ia, ib] : expected_pairs) {
        const T ha = p.smoothing_length[p.slot_of_id(ia)], hb = p.smoothing_length[p.slot_of_id(ib)];
        // the _once form is asked for the smaller slot's size: the pair is in band from whichever side visits it
        const bool a_first = p.slot_of_id(ia) < p.slot_of_id(ib);
        const T visitor = a_first ? ha : hb, partner = a_first ? hb : ha;
        if (std::abs(partner - visitor) <= T(tolerance) * visitor) expected_same.emplace(ia, ib);
      }
      CHECK(missed == 0);
      CHECK(missed_half == 0);
      CHECK(false_neighbours == 0);
      CHECK(repeated_same == 0);
      CHECK(same_size_once == expected_same);
    }

    std::vector<std::uint32_t> order(n);
    for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    p.permute(order);
  }
}

// Candidates tested per particle (distance computations) by the single grid and by the levels, in a block of fluid
// with half its length (x) at spacing dp and half at dp / 2 (h = 1.3 dp, Wendland C2: support radii e_0 = 2.6 dp
// and e_0 / 2). 2D block 0.4 x 0.4 m, 3D block 0.3 x 0.06 x 0.06 m, dp = 1 cm.
// Geometry: the single grid scans the 3^D cells of edge e_0 around every particle. The levels scan, for a fine
// particle, the 3^D level-1 cells of edge e_0 / 2 (reach e_0 / 2) and the level-0 cells within 3/4 e_0 (coarse
// particles only); for a coarse particle the 3^D level-0 cells (coarse particles only) and the level-1 cells within
// 3/4 e_0. Every box lies inside the single grid's 3^D cells (the grids are nested), so the candidates of the levels
// are a subset of the single grid's, particle by particle (checked exactly). Away from the jump a fine particle
// scans 2^D times less volume at the same density, a coarse particle the same (faces clip both searches alike):
// with 2^D fine particles per coarse one, each seeing 2^D times the candidates of a coarse one with one grid, the
// ratio is (1 + 2^D) / (1 + 4^D) = 0.29 (2D), 0.14 (3D). Within 2 e_0 of the jump (0.052 m: 26 % of the fine
// half in 2D, 35 % in 3D) both searches see both sizes; if the fine particles there gained nothing, the ratio would
// be (1 + 2^D (0.74 / 2^D + 0.26)) / (1 + 4^D) = 0.48 in 2D and (1 + 8 (0.65 / 8 + 0.35)) / 65 = 0.06 + 0.43 = 0.49
// in 3D. Asserted: ratio < 1/2, the fine particles' saving away from the jump is there.
TEMPLATE_TEST_CASE("multi-level search: candidates per particle against the single grid, half the area 2:1 finer",
                   "[neighbors][multilevel]", (NeighborCase<2, double>), (NeighborCase<3, double>)) {
  constexpr int Dim = TestType::dimension;
  using T = double;
  using Vector = Vec<Dim, T>;
  using Kernel = WendlandC2<Dim>;
  using System = ParticleSystem<Dim, T, Kernel, LinearEos<T>>;
  const T coarse = 0.01, fine = 0.005, length = Dim == 2 ? 0.4 : 0.3, width = Dim == 2 ? 0.4 : 0.06;  // m
  Vector size = Vector::Constant(width);
  size[0] = length;
  System system(Domain<Dim, T>(Vector::Constant(-0.05), size + Vector::Constant(0.05)), LinearEos<T>(1000, 20));
  // x < length / 2 at spacing `coarse`, x > length / 2 at `fine`; h = 1.3 dp.
  Vector middle = size, lower = Vector::Zero();
  middle[0] = lower[0] = length / 2;
  add_fluid_block(system, Vector::Zero(), middle, Resolution<T>{coarse, 1.3}, size[Dim - 1], 0);
  add_fluid_block(system, lower, size, Resolution<T>{fine, 1.3}, size[Dim - 1], 0);
  system.update_neighbors();
  REQUIRE(system.multilevel_search());
  REQUIRE(system.levels().levels() == 2);
  const auto& p = system.particles();
  const std::size_t n = p.size();

  // The single grid of the same particles (cell edge: the coarse support radius), on a copy.
  ParticleSet<Dim, T> copy = p;
  CellList<Dim, T> single;
  single.build(copy, system.domain(), system.cells().cell_size());
  REQUIRE(copy.id == p.id);  // the stable sort kept the level-0 cell order: same slots
  std::size_t single_candidates = 0, multilevel_candidates = 0, neighbours = 0, not_subset = 0;
  std::vector<std::size_t> old_set, new_set;
  for (std::size_t a = 0; a < n; ++a) {
    old_set.clear();
    new_set.clear();
    single.for_each_candidate(a, [&](std::size_t b) { old_set.push_back(b); });
    system.levels().for_each_candidate(a, [&](std::size_t b) { new_set.push_back(b); });
    system.for_each_neighbor(a, [&](std::size_t, const Vector&, T, T) { ++neighbours; });
    single_candidates += old_set.size();
    multilevel_candidates += new_set.size();
    std::sort(new_set.begin(), new_set.end());
    not_subset += !std::includes(old_set.begin(), old_set.end(), new_set.begin(), new_set.end());
  }
  const double old_per_particle = double(single_candidates) / double(n);
  const double new_per_particle = double(multilevel_candidates) / double(n);
  const double ratio = new_per_particle / old_per_particle;
  INFO(Dim << "D, " << n << " particles: " << old_per_particle << " candidates per particle with one grid, "
           << new_per_particle << " with the levels (ratio " << ratio << "), " << double(neighbours) / double(n)
           << " neighbours");
  CHECK(not_subset == 0);
  CHECK(ratio < 0.5);

  // Here the coarse particles more than a level-0 cell from any fine one keep the single grid's rows
  // (needs_levels() false; about 3/4 of the coarse particles, a fifth (2D) or a ninth (3D) of all: asserted, more
  // than 1/20 and less than 1/2, so that both paths are exercised), the others use the levels: both must find
  // exactly the brute-force neighbours, and each pair once.
  std::size_t single_grid_particles = 0;
  for (std::size_t a = 0; a < n; ++a) single_grid_particles += !system.levels().needs_levels(a);
  CAPTURE(single_grid_particles);
  CHECK(single_grid_particles > n / 20);
  CHECK(single_grid_particles < n / 2);
  const auto expected = brute_force_neighbours(system);
  const auto found = cell_list_neighbours(system);
  CHECK(found == expected);
  std::set<std::pair<std::uint32_t, std::uint32_t>> once;
  std::size_t repeated = 0, outside = 0;
  for (std::size_t a = 0; a < n; ++a) {
    const std::size_t end = system.neighbor_once_end(a);
    system.for_each_neighbor_once(a, [&](std::size_t b, const Vector&, T, T) {
      outside += b <= a || b >= end;
      repeated += !once.emplace(std::min(p.id[a], p.id[b]), std::max(p.id[a], p.id[b])).second;
    });
  }
  CHECK(repeated == 0);
  CHECK(outside == 0);
  CHECK(once == unordered_pairs(expected));
}
