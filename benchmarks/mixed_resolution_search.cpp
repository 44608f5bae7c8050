// sphfsi benchmark: the neighbour search with two particle sizes, single grid against the multi-level search
// (neighbors/multilevel_cell_list.hpp).
//
//   bench_mixed_resolution_search --dimension 2 --band 0.2 --ratio 2 --search multilevel --evaluations 20
//
// The scene: water at rest with a random perturbation filling a box of length 1 m (height 0.5 m in 2D, 0.3 x 0.3 m
// in 3D) at spacing dp (4 mm in 2D, 2 cm in 3D), with a band of `band` times the length across its middle at
// dp / ratio (h = 1.3 dp everywhere, Wendland C2, Tait, WCSPH with delta-SPH, artificial viscosity and XSPH). Prints
// one CSV line: dimension,band,ratio,search,particles,candidates_once_per_particle,update_neighbors_ms,pairs_once_ms,
// all_neighbours_ms,rates_ms,spill_fraction: process CPU milliseconds (std::clock, best of 5 repeats) of one
// update_neighbors(), one sweep of for_each_neighbor_once and of for_each_neighbor over all particles with a
// trivial pair function, and one rates evaluation (update_neighbors, update_pressure, WcsphFluid::compute_rates);
// spill_fraction is the size of the per-thread spill buffers of compute_rates (8 slot ranges) over the particle
// count. Run with OMP_NUM_THREADS=1 to compare the searches on equal footing.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/builders.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <ctime>
#include <random>
#include <string>

using namespace sphfsi;

template <int Dim>
void run(double band, int ratio, bool multilevel, int evaluations) {
  using System = ParticleSystem<Dim, double, WendlandC2<Dim>, Tait<double>>;
  using V = Vec<Dim, double>;
  const double dp = Dim == 2 ? 0.004 : 0.02, length = 1.0, height = Dim == 2 ? 0.5 : 0.3;  // m
  V size = V::Constant(height);
  size[0] = length;
  System system(Domain<Dim, double>(V::Constant(-0.05), size + V::Constant(0.05)), Tait<double>(1000, 20));
  system.enable_multilevel_search(multilevel);
  const double x0 = 0.5 * length * (1 - band), x1 = 0.5 * length * (1 + band);
  V lower = V::Zero(), upper = size;
  upper[0] = x0;
  if (x0 > 0) add_fluid_block(system, lower, upper, Resolution<double>{dp, 1.3}, height, 0);
  lower[0] = x0;
  upper[0] = x1;
  if (x1 > x0) add_fluid_block(system, lower, upper, Resolution<double>{dp / ratio, 1.3}, height, 0);
  lower[0] = x1;
  upper = size;
  if (x1 < length) add_fluid_block(system, lower, upper, Resolution<double>{dp, 1.3}, height, 0);
  auto& p = system.particles();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (int d = 0; d < Dim; ++d) p.velocity[i][d] = 0.1 * u(rng);  // m/s
    p.density[i] = 1000 * (1 + 0.005 * u(rng));                     // kg/m^3
  }
  FluidParameters<Dim, double> params;
  params.xsph = 0.1;
  WcsphFluid<System> fluid(params);
  const std::size_t n = p.size();
  system.update_neighbors();

  std::size_t candidates = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (system.multilevel_search()) system.levels().for_each_candidate_once(i, [&](std::size_t) { ++candidates; });
    else system.cells().for_each_candidate_once(i, [&](std::size_t) { ++candidates; });
  }
  std::size_t spill = 0;
  for (std::size_t c = 0; c < 8; ++c) {
    const std::size_t begin = n * c / 8, end = n * (c + 1) / 8;
    std::size_t reach = end;
    for (std::size_t i = begin; i < end; ++i) reach = std::max(reach, system.neighbor_once_end(i));
    spill += reach - end;
  }

  // Best of 5 repeats of `evaluations` calls, CPU ms per call.
  double sink = 0;
  const auto best_ms = [&](auto&& work) {
    double best = 1e300;
    for (int repeat = 0; repeat < 5; ++repeat) {
      const std::clock_t start = std::clock();
      for (int k = 0; k < evaluations; ++k) work();
      best = std::min(best, 1e3 * double(std::clock() - start) / CLOCKS_PER_SEC / evaluations);
    }
    return best;
  };
  const double rebuild = best_ms([&] { system.update_neighbors(); });
  const double once = best_ms([&] {
    for (std::size_t i = 0; i < n; ++i)
      system.for_each_neighbor_once(i, [&](std::size_t, const V&, double r, double) { sink += r; });
  });
  const double all = best_ms([&] {
    for (std::size_t i = 0; i < n; ++i)
      system.for_each_neighbor(i, [&](std::size_t, const V&, double r, double) { sink += r; });
  });
  const double rates = best_ms([&] {
    system.update_neighbors();
    system.update_pressure();
    fluid.compute_rates(system);
  });
  fmt::print("{},{},{},{},{},{:.2f},{:.3f},{:.3f},{:.3f},{:.3f},{:.4f}\n", Dim, band, ratio,
             system.multilevel_search() ? "multilevel" : "single", n, double(candidates) / double(n), rebuild, once,
             all, rates, double(spill) / double(n));
  if (sink == 42.0) fmt::print(" ");  // keeps the sweeps from being optimised away
}

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "bench_mixed_resolution_search: single grid against multi-level search, fluid with a fine band.");
  const int dimension = static_cast<int>(cli.get_number("dimension", 2, "2 or 3"));
  const double band = cli.get_number("band", 0.2, "fraction of the length at half the spacing, [0, 1]");
  const int ratio = static_cast<int>(cli.get_number("ratio", 2, "spacing of the band: dp / ratio, 1 to 8"));
  const std::string search = cli.get("search", "multilevel", "multilevel | single");
  const int evaluations = static_cast<int>(cli.get_number("evaluations", 10, "calls per timed repeat"));
  if (!cli.finish()) return 0;
  require_in_range("--band", band, 0.0, 1.0);
  require_in_range("--ratio", ratio, 1, 8);
  require_in_range("--evaluations", evaluations, 1, 100000);
  if (search != "multilevel" && search != "single")
    throw InputError(fmt::format("--search = '{}' is invalid: valid values are multilevel, single", search));
  if (dimension == 2) run<2>(band, ratio, search == "multilevel", evaluations);
  else if (dimension == 3) run<3>(band, ratio, search == "multilevel", evaluations);
  else throw InputError(fmt::format("--dimension = {} is invalid: valid values are 2, 3", dimension));
  return 0;
} catch (const std::exception& e) {
  fmt::print(stderr, "bench_mixed_resolution_search: error: {}\n", e.what());
  return 1;
}
