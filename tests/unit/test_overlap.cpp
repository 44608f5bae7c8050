// Overlapping bodies in a scene are rejected before the first step, naming both particles.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/scenes/builders.hpp>

#include <catch2/catch.hpp>

using namespace sphfsi;
using System = ParticleSystem<2, double, CubicSpline<2>, Tait<double>>;
using V = Vec<2, double>;

TEST_CASE("overlapping bodies are rejected with both particles named", "[robustness]") {
  const Resolution<double> res{0.01, 1.3};
  System ok(Domain<2, double>(V(-0.1, -0.1), V(0.5, 0.5)), Tait<double>(1000, 10));
  add_fluid_block(ok, V(0, 0), V(0.1, 0.1), res, 0.1);
  add_box_walls(ok, V(0, 0), V(0.3, 0.2), res, WallModel::dynamic, 3);
  Simulation<System, SymplecticVerlet> good(ok, FluidParameters<2, double>{});
  REQUIRE_NOTHROW(good.step());  // fluid at dp from the walls: no overlap

  System bad(Domain<2, double>(V(-0.1, -0.1), V(0.5, 0.5)), Tait<double>(1000, 10));
  add_fluid_block(bad, V(0, 0), V(0.1, 0.1), res, 0.1);
  add_box_walls(bad, V(0, 0), V(0.3, 0.2), res, WallModel::dynamic, 3);
  bad.particles().add(Kind::wall, V(0.054, 0.054), V::Zero(), 1000, 0.1, 0.013, 1);  // a post inside the water
  Simulation<System, SymplecticVerlet> sim(bad, FluidParameters<2, double>{});
  try {
    sim.step();
    FAIL("overlap not detected");
  } catch (const InputError& e) {
    const std::string message = e.what();
    CHECK(message.find("overlapping bodies") != std::string::npos);
    CHECK(message.find("wall particle id") != std::string::npos);
    CHECK(message.find("fluid particle id") != std::string::npos);
  }
}
