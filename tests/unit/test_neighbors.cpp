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

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
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

TEMPLATE_TEST_CASE("cell list finds exactly the brute-force neighbour sets", "[neighbors]", (NeighborCase<2, double>),
                   (NeighborCase<3, double>), (NeighborCase<2, float>), (NeighborCase<3, float>)) {
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

    const auto found = cell_list_neighbours(system);
    std::size_t missed = 0, spurious = 0, pairs = 0;
    for (std::uint32_t id = 0; id < n; ++id) {
      pairs += expected[id].size();
      for (std::uint32_t j : expected[id]) missed += !found[id].count(j);
      for (std::uint32_t j : found[id]) spurious += !expected[id].count(j);
    }
    CAPTURE(pairs);
    CHECK(pairs > 3 * n);  // not vacuous: several neighbours per particle on average
    CHECK(missed == 0);
    CHECK(spurious == 0);

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
