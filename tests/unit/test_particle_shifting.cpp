// Fickian particle shifting (fluid/particle_shifting.hpp; Lind et al. 2012, Skillen et al. 2013): a disordered block
// becomes more regular, a free surface does not diffuse outwards, the cap holds, bad input is named.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/particle_shifting.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace sphfsi;

namespace {

using V2 = Vec<2, double>;
using ShiftSystem = ParticleSystem<2, double, WendlandC2<2>, Tait<double>>;
using Shifting = ParticleShifting<ShiftSystem>;

// A 24 x 24 block of water at dp = 0.01 m, h = 1.3 dp, no walls (its edges are free surfaces), every particle
// moving at 1 m/s along x (the shift scales with the speed; the particles are not advected here).
struct ShiftBlock {
  static constexpr double dp = 0.01;
  static constexpr int n = 24;
  ShiftSystem system{Domain<2, double>(V2(-0.1, -0.1), V2(0.34, 0.34)), Tait<double>(1000, 20)};
  ShiftBlock() {
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        system.particles().add(Kind::fluid, V2((i + 0.5) * dp, (j + 0.5) * dp), V2(1, 0), 1000, 1000 * dp * dp,
                               1.3 * dp);
    system.update_neighbors();
  }
  // Each particle displaced by up to 0.2 dp (deterministic).
  void disorder() {
    auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      p.position[i] += 0.2 * dp * V2(std::sin(12.9898 * double(i)), std::cos(78.233 * double(i)));
    system.update_neighbors();
  }
  bool interior(const V2& x) const {
    const double margin = 6 * dp;  // beyond the kernel support (2.6 dp) of the surface particles' own shifts
    return x[0] > margin && x[0] < n * dp - margin && x[1] > margin && x[1] < n * dp - margin;
  }
  // RMS over the interior particles of the kernel sum's deviation from its mean: zero on a perfect lattice.
  double concentration_spread() const {
    const auto& p = system.particles();
    const WendlandC2<2> kernel;
    double sum = 0, sum2 = 0;
    int count = 0;
    for (std::size_t a = 0; a < p.size(); ++a) {
      if (!interior(p.position[a])) continue;
      double c = p.mass[a] / p.density[a] * kernel.value(0.0, p.smoothing_length[a]);
      system.for_each_neighbor(
          a, [&](std::size_t b, const V2&, double r, double h) { c += p.mass[b] / p.density[b] * kernel.value(r, h); });
      sum += c;
      sum2 += c * c;
      ++count;
    }
    const double mean = sum / count;
    return std::sqrt(std::max(0.0, sum2 / count - mean * mean));
  }
};

}  // namespace

// The disordered block's interior kernel sums (a measure of the particles' disorder) spread by 0.10 with a jitter of
// 0.2 dp (0 on the lattice); 40 shifts of at most 0.02 h each must at least halve the spread (measured: to 0.013). The
// shift does not touch velocities.
TEST_CASE("particle shifting makes a disordered block more regular", "[shifting]") {
  ShiftBlock block;
  block.disorder();
  const double before = block.concentration_spread();
  ParticleShiftingParameters<double> params;
  params.enabled = true;
  Shifting shifting(params);
  for (int k = 0; k < 40; ++k) {
    shifting.advance(block.system, 0, 2e-4);
    block.system.update_neighbors();
  }
  const double after = block.concentration_spread();
  INFO("kernel-sum spread before " << before << ", after " << after);
  CHECK(before > 0.01);
  CHECK(after < 0.5 * before);
  CHECK(shifting.last_counts().shifted > 0);
  CHECK(shifting.last_counts().largest_shift < params.max_shift);
  for (const V2& v : block.system.particles().velocity) CHECK(v == V2(1, 0));
}

// On a perfect lattice the interior's concentration gradient vanishes, and at a flat free surface it is normal to the
// surface: with the surface treatment nothing there moves. Treated as interior (surface_deficit = 3: no divergence
// below 0), the surface rows move outwards: the test can tell the two apart. Measured away from the block's corners
// (more than 5 dp from both of its sides), where the surface is flat: at a corner the surface normal turns within a
// kernel support and the particles there do move along the rounded surface.
TEST_CASE("particle shifting: a free surface is not pushed outwards; the cap holds", "[shifting]") {
  auto largest_move = [](double surface_deficit, double detached_fraction, double dt, ParticleShiftingCounts& c) {
    ShiftBlock block;
    const auto start = block.system.particles().position;
    ParticleShiftingParameters<double> params;
    params.enabled = true;
    params.surface_deficit = surface_deficit;
    params.detached_fraction = detached_fraction;
    Shifting shifting(params);
    shifting.advance(block.system, 0, dt);
    c = shifting.last_counts();
    double largest = 0;
    for (std::size_t i = 0; i < start.size(); ++i)
      if (start[i][0] > 5 * ShiftBlock::dp && start[i][0] < (ShiftBlock::n - 5) * ShiftBlock::dp)
        largest = std::max(largest, (block.system.particles().position[i] - start[i]).norm());
    return largest / ShiftBlock::dp;
  };
  ParticleShiftingCounts counts;
  const double with_surface = largest_move(0.5, 0.5, 2e-3, counts);
  CHECK(with_surface < 1e-12);
  CHECK(counts.surface > 0);
  const double as_interior = largest_move(3.0, 0.0, 2e-3, counts);
  CHECK(as_interior > 0.01);
  CHECK(counts.surface == 0);
  // A step long enough for the cap: the outermost rows move max_shift h = 0.13 dp exactly.
  const double capped = largest_move(3.0, 0.0, 1.0, counts);
  CHECK(counts.capped > 0);
  CHECK(capped == Approx(0.1 * 1.3).epsilon(1e-12));
}

TEST_CASE("particle shifting: bad input gives an InputError naming the parameter and its valid range", "[shifting]") {
  auto message = [](auto edit) {
    ParticleShiftingParameters<double> params;
    edit(params);
    try {
      Shifting shifting(params);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  using Catch::Matchers::Contains;
  CHECK_THAT(message([](auto& s) { s.coefficient = 0; }), Contains("coefficient") && Contains("(0, 10]"));
  CHECK_THAT(message([](auto& s) { s.max_shift = 0.7; }), Contains("max_shift") && Contains("(0, 0.5]"));
  CHECK_THAT(message([](auto& s) { s.detached_fraction = 1.5; }), Contains("detached_fraction") && Contains("[0, 1]"));
  CHECK_THAT(message([](auto& s) { s.surface_deficit = -1; }), Contains("surface_deficit") && Contains("(0, 3]"));
  CHECK_THAT(message([](auto& s) { s.max_smoothing_length = 0; }), Contains("max_smoothing_length"));
  CHECK(message([](auto&) {}).empty());
}
