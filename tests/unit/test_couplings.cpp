// Tests of the three FSI coupling policies: each conserves the linear momentum of the fluid-solid pair to round-off.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/coupling/blade_drag.hpp>
#include <sphfsi/coupling/coupled_body.hpp>
#include <sphfsi/coupling/interface_pressure.hpp>
#include <sphfsi/coupling/repulsive_force.hpp>
#include <sphfsi/coupling/stress_continuity.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/scenes/antoci_gate.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/scenes/gate_tip_comparison.hpp>
#include <sphfsi/scenes/meadow.hpp>
#include <sphfsi/scenes/solid_builders.hpp>
#include <sphfsi/solid/elastic_rod.hpp>
#include <sphfsi/solid/total_lagrangian.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>

using namespace sphfsi;
using Catch::Matchers::WithinRel;

namespace {

using System = ParticleSystem<2, double, CubicSpline<2>, Tait<double>>;
using V = Vec<2, double>;
using Solid = TotalLagrangianSolid<System>;

// The Antoci et al. (2007) rubber of Table 2 (scenes/antoci_gate.hpp).
ElasticMaterial<double> rubber() { return scenes::AntociGate<double>{}.solid_material(); }

// A free fluid block pressing on a free elastic plate, in vacuum (no walls, no gravity), with random velocities:
// every force in the scene is an internal pair force, so total momentum must stay constant.
System make_scene() {
  System system(Domain<2, double>(V(-0.2, -0.2), V(0.3, 0.3)), Tait<double>(1000, 20));
  const Resolution<double> res{0.005, 1.3};
  add_fluid_block(system, V(0, 0), V(0.05, 0.06), res, 0.06, 9.81);  // hydrostatic density: pressure pushes
  add_solid_block(system, V(0.05, 0), V(0.07, 0.06), res, rubber(), 1);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (auto& v : system.particles().velocity) v = V(u(rng), u(rng));
  return system;
}

V momentum(const System& s) {
  V p = V::Zero();
  for (std::size_t i = 0; i < s.size(); ++i) p += s.particles().mass[i] * s.particles().velocity[i];
  return p;
}

template <class Coupling>
void check_coupling(const Coupling& coupling) {
  System system = make_scene();
  TotalLagrangianParameters<2, double> params;
  params.gravity = V::Zero();
  Solid solid(system, 1, rubber(), params);
  FluidParameters<2, double> fluid;
  fluid.gravity = V::Zero();
  using Body = CoupledBody<Coupling, Solid>;
  Simulation<System, SymplecticVerlet, Body> sim(system, fluid, {}, Body(coupling, std::move(solid)));

  // 1. Instantaneous: the coupling's forces alone sum to zero.
  sim.evaluate_rates(0.0);
  auto& p = system.particles();
  std::vector<V> before(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) before[i] = p.acceleration[i];
  for (std::size_t i = 0; i < p.size(); ++i) p.acceleration[i] = V::Zero();
  coupling.apply(system, sim.template model<0>().solid(), 0.0);
  V total = V::Zero();
  double scale = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    total += p.mass[i] * p.acceleration[i];
    scale += p.mass[i] * p.acceleration[i].norm();
  }
  INFO(Coupling::name << ": sum m a = " << total.transpose() << ", sum |m a| = " << scale);
  REQUIRE(scale > 0);  // the coupling acts
  CHECK(total.norm() <= 1e-12 * scale);
  for (std::size_t i = 0; i < p.size(); ++i) p.acceleration[i] = before[i];

  // 2. Over 30 steps of the coupled run (fluid pairs, coupling, sub-cycled solid): momentum kept to round-off.
  const V p0 = momentum(system);
  double scale_p = 0;
  for (std::size_t i = 0; i < p.size(); ++i) scale_p += p.mass[i] * p.velocity[i].norm();
  for (int k = 0; k < 30; ++k) sim.step();
  const V p1 = momentum(system);
  INFO(Coupling::name << ": momentum drift " << (p1 - p0).transpose() << " of sum |m v| " << scale_p);
  CHECK((p1 - p0).norm() <= 1e-12 * scale_p);
}

}  // namespace

TEST_CASE("stress continuity conserves fluid-solid momentum", "[coupling]") {
  check_coupling(StressContinuity<double>{});
}
TEST_CASE("interface pressure conserves fluid-solid momentum", "[coupling]") {
  check_coupling(InterfacePressure<double>{});
}
TEST_CASE("repulsive force conserves fluid-solid momentum", "[coupling]") {
  RepulsiveForce<double> c;
  check_coupling(c);
}

TEST_CASE("repulsive force with the normal dashpot conserves fluid-solid momentum", "[coupling]") {
  RepulsiveForce<double> c;
  c.normal_damping = 0.5;
  check_coupling(c);
}

TEST_CASE("normal dashpot: opposes the normal relative velocity both ways, ignores the tangential one, dissipates",
          "[coupling]") {
  const double h = 0.01, c0 = 10, q = 0.3, beta = 0.5;
  RepulsiveForceParameters<double> params;
  params.boundary_spacing = 0.005;
  params.strength = 1e-4;
  params.velocity_factor = false;  // eq. 23 off: the dashpot is then the only velocity-dependent term
  params.normal_damping = beta;
  const V n(0, 1), t(1, 0);
  const V dx = 2 * h * q * n + 0.3 * params.boundary_spacing * t;  // inside the range, off the node's normal
  const double P = 0.5 * (1 + std::cos(std::numbers::pi * 0.3));   // eq. 20 at xi = 0.3 db
  const V at_rest = repulsive_force<2, double>(dx, V::Zero(), n, h, c0, 0.0, params);
  const double u = 0.2;
  const V receding = repulsive_force<2, double>(dx, u * n, n, h, c0, 0.0, params) - at_rest;
  const V approaching = repulsive_force<2, double>(dx, -u * n, n, h, c0, 0.0, params) - at_rest;
  const V sliding = repulsive_force<2, double>(dx, u * t, n, h, c0, 0.0, params) - at_rest;
  // a = -beta (c0 / h) (1 - q) P (dv . n) n: symmetric (not one-sided like eq. 23), normal, of known size
  const double expected = beta * (c0 / h) * (1 - q) * P * u;
  CHECK_THAT(approaching.dot(n), WithinRel(expected, 1e-12));
  CHECK_THAT(receding.dot(n), WithinRel(-expected, 1e-12));
  CHECK(std::abs(approaching.dot(t)) <= 1e-15 * expected);
  CHECK(sliding.norm() <= 1e-15 * expected);
  // the pair's power, a_f . (v_f - v_s) (the solid receives -m_f a_f), is never positive
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> w(-1, 1);
  for (int k = 0; k < 100; ++k) {
    const V dv(w(rng), w(rng));
    CHECK((repulsive_force<2, double>(dx, dv, n, h, c0, 0.0, params) - at_rest).dot(dv) <= 0);
  }
  // off (beta = 0): the force of eqs 17-22 does not depend on the velocity
  params.normal_damping = 0;
  CHECK((repulsive_force<2, double>(dx, V(0.3, -0.4), n, h, c0, 0.0, params) -
         repulsive_force<2, double>(dx, V::Zero(), n, h, c0, 0.0, params))
            .norm() == 0);
}

TEST_CASE("solid surface normals point out of a block", "[coupling]") {
  System system = make_scene();
  Solid solid(system, 1, rubber());
  system.update_neighbors();
  std::vector<char> surface;
  update_solid_surface(system, solid.particle_ids(), 1, surface);
  const auto& p = system.particles();
  std::size_t n_surface = 0;
  for (std::size_t k = 0; k < surface.size(); ++k) {
    const std::size_t s = p.slot_of_id(solid.particle_ids()[k]);
    const V x = p.position[s];
    // The block [0.05, 0.07] x [0, 0.06] has 4 columns: the two outer ones and the top/bottom rows are surface.
    const bool edge = x[0] < 0.055 || x[0] > 0.065 || x[1] < 0.005 || x[1] > 0.055;
    CHECK(static_cast<bool>(surface[k]) == edge);
    if (surface[k]) {
      ++n_surface;
      CHECK(std::abs(p.normal[s].norm() - 1) < 1e-12);
      const V centre(0.06, 0.03);
      CHECK(p.normal[s].dot(x - centre) > 0);  // outward
    }
  }
  CHECK(n_surface == 2 * 12 + 2 * 2);
}

TEST_CASE("Antoci gate scene: a gate finer than the fluid keeps its mass, clamp plane and tip row",
          "[coupling][scene]") {
  using Scene = scenes::AntociGate<double>;
  for (const int r : {1, 2, 4}) {
    Scene scene;
    scene.particles_across = 60;  // dp = 1.67 mm: three gate rows at r = 1, twelve at r = 4
    scene.solid_refinement = r;
    System system(scene.domain(), Tait<double>(1000, 20));
    const auto ids = scenes::build_antoci_gate(system, scene);
    const auto& p = system.particles();
    double mass = 0, h = 0, lowest = 1;
    std::size_t n = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::solid) continue;
      mass += p.mass[i];
      h = p.smoothing_length[i];
      lowest = std::min(lowest, p.position[i][1]);
      ++n;
    }
    INFO("solid_refinement " << r);
    const double ds = scene.dp() / r;
    const double gate_height = scene.clamp_height() + scene.clamp_rows * scene.dp() - scene.gap();
    CHECK(mass == Approx(scene.solid_density * scene.gate_thickness * gate_height).epsilon(1e-9));
    CHECK(h == Approx(scene.smoothing_ratio * ds));
    CHECK(lowest == Approx(scene.gap() + 0.5 * ds));
    CHECK(ids.tip.size() == static_cast<std::size_t>(std::lround(scene.gate_thickness / ds)));
    CHECK(n == ids.tip.size() * static_cast<std::size_t>(std::lround(gate_height / ds)));
  }
  Scene thin;
  thin.particles_across = 40;  // two fluid spacings across the gate: too few rows unless the gate is finer
  CHECK_THROWS_WITH(thin.validate(), Catch::Contains("needs >= 3 particle rows (has 2)"));
  thin.solid_refinement = 2;
  CHECK_NOTHROW(thin.validate());
  Scene bad;
  bad.solid_refinement = 3;
  CHECK_THROWS_WITH(bad.validate(),
                    Catch::Contains("AntociGate::solid_refinement = 3") && Catch::Contains("1, 2 and 4"));
}

// ---- thin structures: the repulsive coupling of a blade made of one line of nodes (solid/elastic_rod.hpp) ----

namespace {

using Rod = ElasticRod<System>;

ElasticMaterial<double> blade_material() {
  ElasticMaterial<double> m;
  m.density = 920;  // LDPE
  m.youngs_modulus = 3e8;
  m.poisson_ratio = 0.4;
  return m;
}

RodSection<double> blade_section() { return RodSection<double>{.thickness = 4e-4, .width = 0.01}; }

// A free blade (no clamp, no gravity) between two fluid blocks with random velocities: every force is a pair force.
System blade_between_blocks(unsigned seed) {
  System system(Domain<2, double>(V(-0.2, -0.2), V(0.3, 0.3)), Tait<double>(1000, 20));
  const Resolution<double> res{0.005, 1.3};
  add_fluid_block(system, V(0, 0), V(0.05, 0.06), res, 0.06, 9.81);
  add_fluid_block(system, V(0.055, 0), V(0.1, 0.06), res, 0.06, 9.81);
  add_elastic_rod(system, V(0.0525, 0.0), V(0, 1), 0.06, 25, blade_material(), blade_section(), res.h(), 1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (auto& v : system.particles().velocity) v = V(u(rng), u(rng));
  return system;
}

// The free blade's rod, without added inertia (with it, sum m v would not be the conserved momentum).
Rod free_blade(const System& system) {
  Rod::Parameters params;
  params.section = blade_section();
  params.gravity = V::Zero();
  return Rod(system, 1, blade_material(), params);
}

// 30 coupled steps with the sub-cycled blade keep the total momentum to round-off.
template <class Sim>
void check_momentum_over_steps(Sim& sim, const System& system) {
  const V p0 = momentum(system);
  double scale_p = 0;
  for (std::size_t i = 0; i < system.size(); ++i)
    scale_p += system.particles().mass[i] * system.particles().velocity[i].norm();
  for (int k = 0; k < 30; ++k) sim.step();
  CHECK((momentum(system) - p0).norm() <= 1e-12 * scale_p);
}

using BladeBody = CoupledBody<RepulsiveForce<double>, Rod>;

FluidParameters<2, double> weightless_fluid() {
  FluidParameters<2, double> fluid;
  fluid.gravity = V::Zero();
  return fluid;
}

}  // namespace

TEST_CASE("repulsive force on a thin blade: pushes on both faces and conserves momentum", "[coupling][thin]") {
  System system = blade_between_blocks(3);
  Simulation<System, SymplecticVerlet, BladeBody> sim(system, weightless_fluid(), {},
                                                      BladeBody(RepulsiveForce<double>{}, free_blade(system)));
  sim.evaluate_rates(0.0);
  auto& p = system.particles();
  // Both faces: fluid particles on either side of the blade are pushed away from it.
  for (std::size_t i = 0; i < p.size(); ++i) p.acceleration[i] = V::Zero();
  RepulsiveForce<double>{}.apply(system, sim.template model<0>().solid(), 0.0);
  double left = 0, right = 0, total_x = 0, scale = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    total_x += p.mass[i] * p.acceleration[i][0];
    scale += p.mass[i] * p.acceleration[i].norm();
    if (p.kind[i] != Kind::fluid) continue;
    if (p.position[i][0] < 0.0525) left += p.mass[i] * p.acceleration[i][0];
    else right += p.mass[i] * p.acceleration[i][0];
  }
  INFO("push on the left fluid " << left << " N/m, on the right fluid " << right << " N/m");
  CHECK(left < 0);
  CHECK(right > 0);
  CHECK(std::abs(total_x) <= 1e-12 * scale);
  check_momentum_over_steps(sim, system);
}

TEST_CASE("repulsive force on a thin blade with the normal dashpot conserves momentum", "[coupling][thin]") {
  // The blade is 50 times lighter than the fluid particles: the dashpot's own step limit
  // (RepulsiveForce::stable_time_step) keeps it stable.
  System system = blade_between_blocks(5);
  RepulsiveForce<double> coupling;
  coupling.normal_damping = 0.5;
  Simulation<System, SymplecticVerlet, BladeBody> sim(system, weightless_fluid(), {},
                                                      BladeBody(coupling, free_blade(system)));
  check_momentum_over_steps(sim, system);
}

TEST_CASE("repulsive force on a thin blade: a jet does not cross it", "[coupling][thin]") {
  // A held blade spanning a closed box; the water on its left moves at 0.5 m/s towards it. The blade is
  // far thinner than a particle (0.4 mm against 5 mm): only the coupling keeps the water on its side.
  System system(Domain<2, double>(V(-0.05, -0.05), V(0.25, 0.5)), Tait<double>(1000, 20));
  const Resolution<double> res{0.005, 1.3};
  add_fluid_block(system, V(0, 0), V(0.1, 0.08), res, 0.08, 9.81);
  add_box_walls(system, V(0, 0), V(0.2, 0.3), res, WallModel::dynamic);
  const double x_blade = 0.1025;
  add_elastic_rod(system, V(x_blade, 0.0), V(0, 1), 0.3, 121, blade_material(), blade_section(), res.h(), 1);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid) p.velocity[i] = V(0.5, 0);
  Rod::Parameters params;
  params.section = blade_section();
  Rod rod(system, 1, blade_material(), params);
  rod.clamp_where([](const V&) { return true; });  // a rigid thin wall
  using Body = CoupledBody<RepulsiveForce<double>, Rod>;
  Simulation<System, SymplecticVerlet, Body> sim(system, FluidParameters<2, double>{}, {},
                                                 Body(RepulsiveForce<double>{}, std::move(rod)));
  std::size_t crossed = 0;
  double closest = 1;
  sim.run(0.1, [&](auto& s) {
    const auto& q = s.system().particles();
    for (std::size_t i = 0; i < q.size(); ++i) {
      if (q.kind[i] != Kind::fluid) continue;
      if (q.position[i][0] > x_blade) ++crossed;
      closest = std::min(closest, x_blade - q.position[i][0]);
    }
  });
  INFO("closest approach " << closest << " m, steps " << sim.step_count());
  CHECK(crossed == 0);
  CHECK(closest > 0.1 * res.dp);  // the jet is stopped well before the blade line
}

// ---- a 3D ribbon (solid/elastic_rod.hpp in a 3D system): the strip of a blade in a 3D flow ----

namespace {

using System3 = ParticleSystem<3, double, CubicSpline<3>, Tait<double>>;
using V3 = Vec<3, double>;
using Ribbon = ElasticRod<System3>;
using RibbonBody = CoupledBody<RepulsiveForce<double>, Ribbon>;

// A strip of width 1 cm and length 3 cm standing in the plane x = 0.0325 m between two weightless fluid blocks 3 cm
// wide (y in [-0.015, 0.015]), rows of 4 particles across the strip; the fluid moves at random.
System3 ribbon_between_blocks(unsigned seed) {
  System3 system(Domain<3, double>(V3(-0.1, -0.1, -0.1), V3(0.2, 0.1, 0.2)), Tait<double>(1000, 20));
  const Resolution<double> res{0.005, 1.3};
  add_fluid_block(system, V3(0, -0.015, 0), V3(0.03, 0.015, 0.04), res, 0.04, 0.0);
  add_fluid_block(system, V3(0.035, -0.015, 0), V3(0.065, 0.015, 0.04), res, 0.04, 0.0);
  add_elastic_ribbon(system, V(0.0325, 0.005), V(0, 1), 0.03, 13, 4, 0.0, blade_material(), blade_section(), res.h(),
                     1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i)  // a row across the strip moves as one node, in the x-z plane
    p.velocity[i] = p.kind[i] == Kind::fluid ? V3(u(rng), u(rng), u(rng)) : V3::Zero();
  return system;
}

V3 momentum3(const System3& s) {
  V3 sum = V3::Zero();
  for (std::size_t i = 0; i < s.size(); ++i) sum += s.particles().mass[i] * s.particles().velocity[i];
  return sum;
}

}  // namespace

TEST_CASE("repulsive force on a 3D ribbon: pushes on both faces, only in them, and conserves momentum",
          "[coupling][thin][ribbon]") {
  System3 system = ribbon_between_blocks(7);
  Ribbon::Parameters params;
  params.section = blade_section();
  params.gravity = V::Zero();
  FluidParameters<3, double> fluid;
  fluid.gravity = V3::Zero();
  Simulation<System3, SymplecticVerlet, RibbonBody> sim(
      system, fluid, {}, RibbonBody(RepulsiveForce<double>{}, Ribbon(system, 1, blade_material(), params)));
  sim.evaluate_rates(0.0);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) p.acceleration[i] = V3::Zero();
  RepulsiveForce<double>{}.apply(system, sim.template model<0>().solid(), 0.0);
  double left = 0, right = 0, lateral = 0, beside = 0, scale = 0;
  V3 total = V3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    total += p.mass[i] * p.acceleration[i];
    scale += p.mass[i] * p.acceleration[i].norm();
    if (p.kind[i] != Kind::fluid) continue;
    lateral += std::abs(p.acceleration[i][1]);
    if (std::abs(p.position[i][1]) > 0.005 + 0.005) beside += p.acceleration[i].norm();  // a spacing past the edges
    if (p.position[i][0] < 0.0325) left += p.mass[i] * p.acceleration[i][0];
    else right += p.mass[i] * p.acceleration[i][0];
  }
  INFO("push on the left fluid " << left << " N, on the right fluid " << right << " N");
  CHECK(left < 0);
  CHECK(right > 0);
  CHECK(lateral == 0);  // along the strip's normal only
  CHECK(beside == 0);   // the push reaches dp / 2 past the strip's side edges (P(xi)), not a whole spacing
  CHECK(total.norm() <= 1e-12 * scale);
  // 30 coupled steps of the free ribbon keep the total momentum (the row's force is its node's; every particle of a
  // row moves with the node)
  const V3 p0 = momentum3(system);
  double scale_p = 0;
  for (std::size_t i = 0; i < system.size(); ++i) scale_p += p.mass[i] * p.velocity[i].norm();
  for (int k = 0; k < 30; ++k) sim.step();
  CHECK((momentum3(system) - p0).norm() <= 1e-12 * scale_p);
}

TEST_CASE(
    "repulsive force on a 3D ribbon: a jet at a strip spanning the channel does not cross it, and a narrow "
    "strip lets the water pass its sides",
    "[coupling][thin][ribbon]") {
  // Water 4 cm deep moving at 0.5 m/s along x towards a held strip standing across the whole 3D channel (width 3 cm),
  // or a strip 1 cm wide in its middle. Full width: no particle reaches the strip's plane. Narrow: water passes it
  // beside the strip and none through it (BladeCrossingCounter, the strip's own swept test).
  for (const double width : {0.03, 0.01}) {
    System3 system(Domain<3, double>(V3(-0.05, -0.05, -0.05), V3(0.2, 0.05, 0.15)), Tait<double>(1000, 20));
    const Resolution<double> res{0.005, 1.3};
    add_fluid_block(system, V3(0, -0.015, 0), V3(0.06, 0.015, 0.04), res, 0.04, 9.81);
    add_box_walls(system, V3(0, -0.015, 0), V3(0.12, 0.015, 0.06), res, WallModel::dynamic);
    const double x_blade = 0.0625;
    const RodSection<double> section{.thickness = 4e-4, .width = width};
    add_elastic_ribbon(system, V(x_blade, 0.0), V(0, 1), 0.06, 25, int(std::lround(width / 0.0025)), 0.0,
                       blade_material(), section, res.h(), 1);
    auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid) p.velocity[i] = V3(0.5, 0, 0);
    Ribbon::Parameters params;
    params.section = section;
    Ribbon rod(system, 1, blade_material(), params);
    rod.clamp_where([](const V3&) { return true; });  // a rigid thin wall
    Simulation<System3, SymplecticVerlet, RibbonBody> sim(system, FluidParameters<3, double>{}, {},
                                                          RibbonBody(RepulsiveForce<double>{}, std::move(rod)));
    struct OneRibbon {
      const Ribbon& only;
      std::size_t size() const noexcept { return 1; }
      const Ribbon& rod(std::size_t) const noexcept { return only; }
    };
    scenes::BladeCrossingCounter<System3> crossings(1.5 * res.dp);
    std::size_t past = 0;
    sim.run(0.04, [&](auto& s) {
      crossings.update(s.system(), OneRibbon{s.template model<0>().solid()});
      const auto& q = s.system().particles();
      past = 0;
      for (std::size_t i = 0; i < q.size(); ++i)
        if (q.kind[i] == Kind::fluid && q.position[i][0] > x_blade) ++past;
    });
    INFO("strip width " << width << " m: " << past << " particles past the strip's plane, " << crossings.total()
                        << " crossed it, " << sim.step_count() << " steps");
    CHECK(crossings.total() == 0);
    if (width > 0.02) CHECK(past == 0);
    else CHECK(past > 20);  // round the sides
  }
}

// ---- porous blades: the Morison drag coupling (coupling/blade_drag.hpp) ----

namespace {

using DragBody = CoupledBody<BladeDrag<double>, Rod>;

// A straight free blade of length 0.04 m at 30 degrees from the vertical, from (0.05, 0.03), inside (or, with
// `top` below its tip, sticking out of) a weightless fluid block of width 0.1 m.
System blade_in_block(double top) {
  System system(Domain<2, double>(V(-0.2, -0.2), V(0.3, 0.3)), Tait<double>(1000, 20));
  const Resolution<double> res{0.005, 1.3};
  add_fluid_block(system, V(0, 0), V(0.1, top), res, top, 0.0);
  add_elastic_rod(system, V(0.05, 0.03), V(0.5, std::sqrt(3.0) / 2), 0.04, 17, blade_material(), blade_section(),
                  res.h(), 1);
  return system;
}

// Evaluates the rates (neighbours, the rod's normals) and returns the drag's accelerations alone.
void drag_only(System& system, const BladeDrag<double>& drag) {
  Simulation<System, SymplecticVerlet, DragBody> sim(system, weightless_fluid(), {},
                                                     DragBody(drag, free_blade(system)));
  sim.evaluate_rates(0.0);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) p.acceleration[i] = V::Zero();
  drag.apply(system, sim.template model<0>().solid(), 0.0);
}

}  // namespace

TEST_CASE("blade drag: the Morison force of a uniform stream on an inclined blade, momentum, dissipation",
          "[coupling][thin]") {
  BladeDrag<double> drag;
  drag.friction_coefficient = 0.05;
  const double U = 0.2, l = 0.04, rho = 1000, angle = std::numbers::pi / 6;  // blade 30 degrees from the vertical
  System system = blade_in_block(0.1);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = p.kind[i] == Kind::fluid ? V(U, 0) : V::Zero();
  drag_only(system, drag);
  V on_blade = V::Zero(), total = V::Zero();
  double scale = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    total += p.mass[i] * p.acceleration[i];
    scale += p.mass[i] * p.acceleration[i].norm();
    if (p.kind[i] == Kind::solid) on_blade += p.mass[i] * p.acceleration[i];
  }
  // Shepard interpolation of a uniform velocity is exact, and the nodes' shares ds_k add up to l: the total is the
  // Morison force of the whole blade, (1/2) rho l (C_D u_n^2 n + C_f u_t^2 t).
  const V tangent(std::sin(angle), std::cos(angle)), normal(std::cos(angle), -std::sin(angle));
  const double un = U * std::cos(angle), ut = U * std::sin(angle);
  const V expected =
      0.5 * rho * l * (drag.drag_coefficient * un * un * normal + drag.friction_coefficient * ut * ut * tangent);
  INFO("force on the blade (" << on_blade.transpose() << ") N/m, Morison (" << expected.transpose() << ")");
  CHECK((on_blade - expected).norm() <= 1e-12 * expected.norm());
  CHECK(total.norm() <= 1e-12 * scale);  // the fluid receives exactly the opposite
  const Rod rod = free_blade(system);    // the relative velocity the drag acts on: the stream's, blade at rest
  for (std::size_t k = 0; k < rod.particle_ids().size(); ++k)
    CHECK((drag.relative_velocity(system, rod, k) - V(U, 0)).norm() <= 1e-12 * U);

  // Random velocities of fluid and blade: momentum to round-off, and the coupling only dissipates.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int trial = 0; trial < 20; ++trial) {
    for (auto& v : p.velocity) v = V(u(rng), u(rng));
    drag_only(system, drag);
    V sum = V::Zero();
    double power = 0, magnitude = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      sum += p.mass[i] * p.acceleration[i];
      power += p.mass[i] * p.acceleration[i].dot(p.velocity[i]);
      magnitude += std::abs(p.mass[i] * p.acceleration[i].dot(p.velocity[i]));
    }
    CHECK(sum.norm() <= 1e-12 * magnitude / 0.3);
    CHECK(power <= 1e-12 * magnitude);
    CHECK(power < 0);
  }

  // A blade covering a share phi of the scene's width: the node's force unchanged, the fluid feels phi of it, so
  // phi sum_nodes m a + sum_fluid m a = 0 (the rod counted per unit width of the scene).
  BladeDrag<double> sparse = drag;
  sparse.frontal_fraction = 0.25;
  for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = p.kind[i] == Kind::fluid ? V(U, 0) : V::Zero();
  drag_only(system, sparse);
  V node_force = V::Zero(), fluid_force = V::Zero();
  for (std::size_t i = 0; i < p.size(); ++i)
    (p.kind[i] == Kind::solid ? node_force : fluid_force) += p.mass[i] * p.acceleration[i];
  CHECK((node_force - expected).norm() <= 1e-12 * expected.norm());
  CHECK((0.25 * node_force + fluid_force).norm() <= 1e-12 * expected.norm());
}

TEST_CASE("blade drag: nodes above the free surface exchange nothing; 30 coupled steps keep momentum",
          "[coupling][thin]") {
  System system = blade_in_block(0.045);  // the blade reaches z = 0.03 + 0.04 cos 30 = 0.065 m
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = p.kind[i] == Kind::fluid ? V(0.2, 0.05) : V::Zero();
  drag_only(system, BladeDrag<double>{});
  const double reach = 2 * 1.3 * 0.005;  // the cubic spline's support radius
  int dry = 0, wet = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::solid) continue;
    if (p.position[i][1] > 0.045 - 0.0025 + reach) {  // beyond the support of the top fluid row
      ++dry;
      CHECK(p.acceleration[i].norm() == 0.0);
    } else if (p.position[i][1] < 0.04) {
      ++wet;
      CHECK(p.acceleration[i][0] > 0);  // pushed downstream
    }
  }
  CHECK(dry >= 3);
  CHECK(wet >= 3);

  System moving = blade_in_block(0.1);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (auto& v : moving.particles().velocity) v = V(u(rng), u(rng));
  Simulation<System, SymplecticVerlet, DragBody> sim(moving, weightless_fluid(), {},
                                                     DragBody(BladeDrag<double>{}, free_blade(moving)));
  check_momentum_over_steps(sim, moving);
}

TEST_CASE("blade drag: passive fluid particles (a refined region's other resolution) are left out",
          "[coupling][thin]") {
  // The drag of a uniform stream, then the same block with a passive copy of every fluid particle, offset by half a
  // spacing and moving against the stream: the blade's force and the active fluid's reaction are unchanged, and the
  // passive particles receive nothing (fluid/adaptive_refinement.hpp sets their velocity; the drag acts on the
  // integrated fluid).
  const double U = 0.2;
  System system = blade_in_block(0.1);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = p.kind[i] == Kind::fluid ? V(U, 0) : V::Zero();
  drag_only(system, BladeDrag<double>{});
  std::vector<V> alone(p.id_capacity(), V::Zero());
  for (std::size_t i = 0; i < p.size(); ++i) alone[p.id[i]] = p.acceleration[i];
  const std::size_t n = p.size();
  REQUIRE(p.count(Kind::wall) == 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    const std::size_t c = p.add(Kind::fluid, V(p.position[i] + V(0.0025, 0.0025)), V(-U, 0.3), p.density[i], p.mass[i],
                                p.smoothing_length[i]);
    p.passive[c] = 1;
  }
  drag_only(system, BladeDrag<double>{});
  double largest = 0, passive_largest = 0;
  std::size_t passive = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.passive[i]) {
      ++passive;
      passive_largest = std::max(passive_largest, p.acceleration[i].norm());
    } else {
      largest = std::max(largest, (p.acceleration[i] - alone[p.id[i]]).norm() / (alone[p.id[i]].norm() + 1e-30));
      if (p.kind[i] == Kind::solid) CHECK(alone[p.id[i]].norm() > 0);
    }
  }
  CHECK(passive == n - p.count(Kind::solid));  // one copy per fluid particle
  CHECK(largest <= 1e-12);
  CHECK(passive_largest == 0.0);
}

TEST_CASE("blade drag: bad coefficients are rejected with the valid range", "[coupling][thin]") {
  BladeDrag<double> drag;
  drag.drag_coefficient = -1;
  CHECK_THROWS_WITH(drag.validate(), Catch::Contains("BladeDrag::drag_coefficient") && Catch::Contains("[0, 10]"));
  drag.drag_coefficient = 1.95;
  drag.friction_coefficient = 2;
  CHECK_THROWS_WITH(drag.validate(), Catch::Contains("BladeDrag::friction_coefficient"));
  drag.friction_coefficient = 0;
  drag.fluid_density = -1;
  CHECK_THROWS_WITH(drag.validate(), Catch::Contains("BladeDrag::fluid_density"));
  drag.fluid_density = 0;
  for (double phi : {0.0, -0.5, 1.5}) {
    drag.frontal_fraction = phi;
    CHECK_THROWS_WITH(drag.validate(), Catch::Contains("BladeDrag::frontal_fraction"));
  }
}

namespace {

// A still water column (H = 0.1 m, W = 0.05 m, dp = H / 40) in a tank with dynamic walls, held on its right by a
// clamped rubber block (4 rows): the fluid's hydrostatic load on the block is rho0 g H^2 / 2 per unit depth.
struct HeldColumn {
  static constexpr double H = 0.1, W = 0.05, dp = 0.0025, thickness = 4 * dp, g = 9.81, rho0 = 1000;
  System system{Domain<2, double>(V(-0.02, -0.02), V(0.09, 0.14)), Tait<double>(rho0, 20)};
  HeldColumn() {
    const Resolution<double> res{dp, 1.3};
    add_fluid_block(system, V(0, 0), V(W, H), res, H, g);
    add_box_walls(system, V(0, 0), V(W + thickness, H + 0.02), res, WallModel::dynamic, 3, 0);
    add_solid_block(system, V(W, 0), V(W + thickness, H + 0.01), res, rubber(), 1);
  }
  static double hydrostatic_load() { return 0.5 * rho0 * g * H * H; }
};

template <class Coupling>
auto held_column_simulation(HeldColumn& scene, const Coupling& coupling) {
  TotalLagrangianParameters<2, double> params;
  params.gravity = V::Zero();
  Solid solid(scene.system, 1, rubber(), params);
  solid.clamp_where([](const V&) { return true; });  // a rigid wall made of solid particles
  FluidParameters<2, double> fluid;
  fluid.gravity = V(0, -HeldColumn::g);
  fluid.minimum_pressure = 0;
  using Body = CoupledBody<Coupling, Solid>;
  return Simulation<System, SymplecticVerlet, Body>(scene.system, fluid, {}, Body(coupling, std::move(solid)));
}

// Horizontal force of the coupling on the solid block, N per unit depth (after evaluate_rates).
double load_on_block(const System& system) {
  const auto& p = system.particles();
  double fx = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::solid) fx += p.mass[i] * p.acceleration[i][0];
  return fx;
}

}  // namespace

TEST_CASE("interface pressure: a still column loads a solid wall hydrostatically and stays out of it", "[coupling]") {
  HeldColumn scene;
  auto sim = held_column_simulation(scene, InterfacePressure<double>{});
  sim.evaluate_rates(0.0);
  const double load0 = load_on_block(scene.system);
  INFO("initial load " << load0 << " N/m against rho0 g H^2 / 2 = " << HeldColumn::hydrostatic_load());
  // Tolerance dp / H: the load of the column's top half row, where the free surface cuts the kernel.
  const double tolerance = HeldColumn::dp / HeldColumn::H;
  CHECK(load0 == Approx(HeldColumn::hydrostatic_load()).epsilon(tolerance));
  // The column starts from the lattice and rings acoustically (period 4 H / c0 = 0.02 s): average the load over
  // the second 0.1 s, ten acoustic periods.
  sim.run(0.1);
  double load_sum = 0;
  int samples = 0;
  sim.run(0.2, [&](auto& s) {
    s.evaluate_rates(s.time());
    load_sum += load_on_block(s.system());
    ++samples;
  });
  const double load1 = load_sum / samples;
  double x_max = 0;
  const auto& p = scene.system.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid) x_max = std::max(x_max, p.position[i][0]);
  INFO("mean load over 0.1-0.2 s " << load1 << " N/m; rightmost fluid particle at x = " << x_max);
  CHECK(scenes::fluid_particles_inside_solid(scene.system, 1) == 0);
  CHECK(x_max < HeldColumn::W);
  CHECK(load1 == Approx(HeldColumn::hydrostatic_load()).epsilon(tolerance));
}

TEST_CASE("interface pressure, eqs 10-16 as printed (surface row, mirror points): conserves momentum", "[coupling]") {
  InterfacePressure<double> c;
  c.form = InterfaceForm::surface_mirror;
  check_coupling(c);
  // The surface row alone carries only part of the column's load (the reason the integral form is the default).
  HeldColumn scene;
  auto sim = held_column_simulation(scene, c);
  sim.evaluate_rates(0.0);
  const double load = load_on_block(scene.system);
  INFO("surface-mirror load " << load << " N/m against rho0 g H^2 / 2 = " << HeldColumn::hydrostatic_load());
  CHECK(load < 0.75 * HeldColumn::hydrostatic_load());
}
