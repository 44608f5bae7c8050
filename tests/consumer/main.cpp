// sphfsi packaging test: a user's program. A small 2D water column at rest in a box, advanced a few steps with the
// symplectic integrator. Returns nonzero when the package is broken or the result is wrong: particles lost or
// gained, mass not conserved, a non-finite state, or the column not staying (nearly) at rest.
#include <sphfsi/sphfsi.hpp>

#include <cmath>
#include <cstdio>
#include <exception>

#if defined(SPHFSI_CONSUMER_EXPECT_OPENMP)
#if SPHFSI_CONSUMER_EXPECT_OPENMP && !defined(_OPENMP)
#error "this consumer expects OpenMP through sphfsi::sphfsi, but _OPENMP is not defined"
#elif !SPHFSI_CONSUMER_EXPECT_OPENMP && defined(_OPENMP)
#error "this consumer was configured without OpenMP, but _OPENMP is defined"
#endif
#endif

namespace {

using Kernel = sphfsi::CubicSpline<2>;
using Eos = sphfsi::Tait<double>;
using System = sphfsi::ParticleSystem<2, double, Kernel, Eos>;
using Vector = sphfsi::Vec<2, double>;

double total_mass(const System& system) {
  double m = 0;
  for (double mi : system.particles().mass) m += mi;
  return m;
}

int run() {
  const sphfsi::Resolution<double> res{.dp = 0.01};
  System system(sphfsi::Domain<2, double>(Vector(-0.1, -0.1), Vector(0.3, 0.3)), Eos(1000.0, 20.0));
  const std::size_t fluid = sphfsi::add_fluid_block(system, Vector(0, 0), Vector(0.1, 0.05), res, 0.05);
  const std::size_t walls =
      sphfsi::add_box_walls(system, Vector(0, 0), Vector(0.1, 0.1), res, sphfsi::WallModel::dynamic);
  const std::size_t count = system.size();
  const double mass0 = total_mass(system);
  if (fluid != 50 || walls == 0 || count != fluid + walls) {
    std::fprintf(stderr, "unexpected particle counts: %zu fluid, %zu wall\n", fluid, walls);
    return 1;
  }

  sphfsi::Simulation<System, sphfsi::SymplecticVerlet> sim(system, sphfsi::FluidParameters<2, double>{});
  for (int n = 0; n < 20; ++n) sim.step();
  system.check_state(sim.time());  // throws on a non-finite state or a particle outside the domain

  const auto& p = system.particles();
  double max_speed = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p.position[i].allFinite() || !p.velocity[i].allFinite() || !std::isfinite(p.density[i])) {
      std::fprintf(stderr, "non-finite state of particle %zu\n", i);
      return 1;
    }
    max_speed = std::max(max_speed, p.velocity[i].norm());
  }
  const double mass = total_mass(system);
  std::printf(
      "sphfsi consumer: %zu particles (%zu fluid), %zu steps to t = %.3g s, %d thread(s), mass %.9g -> %.9g "
      "kg/m, max speed %.3g m/s\n",
      count, fluid, sim.step_count(), sim.time(), sphfsi::thread_count(), mass0, mass, max_speed);
  if (system.size() != count || sim.step_count() != 20 || !(sim.time() > 0)) {
    std::fprintf(stderr, "particle count or step count changed\n");
    return 1;
  }
  if (!(std::abs(mass - mass0) <= 1e-12 * mass0)) {
    std::fprintf(stderr, "mass not conserved\n");
    return 1;
  }
  if (!(max_speed < 0.1)) {  // a column at rest in hydrostatic balance must stay (nearly) at rest
    std::fprintf(stderr, "the column at rest moved: max speed %g m/s\n", max_speed);
    return 1;
  }
  return 0;
}

}  // namespace

int main() {
  try {
    return run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sphfsi consumer failed: %s\n", e.what());
    return 1;
  }
}
