// Tests of the planar discrete elastic rod (solid/elastic_rod.hpp, issue 6): input validation, the elastica
// under a large tip load, the first bending frequency against Euler-Bernoulli, energy, momentum, rigid motions,
// sub-cycling with the external force held over the outer step, blade normals and checkpointing.
#include <sphfsi/analysis/elastica.hpp>
#include <sphfsi/analysis/reconfiguration.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/linear.hpp>
#include <sphfsi/io/checkpoint.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/solid/concepts.hpp>
#include <sphfsi/solid/elastic_rod.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace {

using System = sphfsi::ParticleSystem<2, double, sphfsi::WendlandC2<2>, sphfsi::LinearEos<double>>;
using Rod = sphfsi::ElasticRod<System>;
using V = sphfsi::Vec<2, double>;

static_assert(sphfsi::SolidModel<Rod, System>);

// A blade with L/t = 100: the axial strain of the largest tip load (alpha = 10) is alpha (t/L)^2 / 12 = 8e-5,
// so the extensible rod is the inextensible elastica to that relative accuracy.
constexpr double L = 0.1;       // m
constexpr double b = 0.01;      // m
constexpr double thick = 1e-3;  // m
const sphfsi::ElasticMaterial<double> blade{.density = 1000, .youngs_modulus = 1e7, .poisson_ratio = 0.3};
const sphfsi::RodSection<double> section{.thickness = thick, .width = b};
const double EI = blade.youngs_modulus * section.second_moment();                            // N m^2
const double rhoA = blade.density * section.area();                                          // kg/m
const double omega1 = 1.8751040687 * 1.8751040687 * std::sqrt(EI / (rhoA * L * L * L * L));  // rad/s

System make_system() {
  return System(sphfsi::Domain<2, double>(V(-1, -1), V(1, 1)), sphfsi::LinearEos<double>(1000, 10));
}

System make_blade(int edges) {
  System system = make_system();
  sphfsi::add_elastic_rod(system, V(0, 0), V(1, 0), L, edges + 1, blade, section, L / edges, 0);
  return system;
}

sphfsi::ElasticRodParameters<double> weightless(double damping = 0) {
  return {.section = section, .gravity = V::Zero(), .damping = damping};
}

using sphfsi::analysis::elastica_tip_load;

/// Static tip deflection and shortening (over L) of the rod with `edges` edges under the dead tip load alpha,
/// by dynamic relaxation (damping 2 omega1) until the largest node speed is below 1e-11 L omega1.
std::pair<double, double> rod_tip_load(int edges, double alpha) {
  System system = make_blade(edges);
  Rod rod(system, 0, blade, weightless(2 * omega1));
  rod.clamp_base();
  const double P = alpha * EI / (L * L);
  const std::uint32_t tip = rod.particle_ids().back();
  const double dt = 200 * rod.solid_time_step();
  double t = 0;
  for (int step = 0; t < 40 * 2 * std::numbers::pi / omega1; ++step) {
    system.particles().acceleration[system.particles().slot_of_id(tip)] = V(0, -P / rod.node_masses().back());
    rod.advance(system, t, dt);
    t += dt;
    double v_max = 0;
    for (const auto& v : rod.velocities()) v_max = std::max(v_max, v.norm());
    if (step > 10 && v_max < 1e-11 * L * omega1) break;
  }
  return {-rod.tip_position().y() / L, (L - rod.tip_position().x()) / L};
}

/// Period of the free vibration started in the first Euler-Bernoulli mode with tip speed v_tip, from the
/// up-crossings of the tip deflection over three periods (crossing times interpolated linearly).
double rod_period(int edges, double v_tip) {
  System system = make_blade(edges);
  const double kL = 1.8751040687;
  const double ratio = (std::cos(kL) + std::cosh(kL)) / (std::sin(kL) + std::sinh(kL));
  const auto mode = [&](double x) {
    const double k = kL / L;
    return (std::cos(k * x) - std::cosh(k * x)) - ratio * (std::sin(k * x) - std::sinh(k * x));
  };
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = V(0, v_tip * mode(p.position[i].x()) / mode(L));
  Rod rod(system, 0, blade, weightless());
  rod.clamp_base();
  const double period = 2 * std::numbers::pi / omega1;
  const double dt = period / 4000;
  double t = 0, y_old = 0;
  std::vector<double> up;
  while (t < 3.2 * period) {
    rod.advance(system, t, dt);
    t += dt;
    const double y = rod.tip_position().y();
    if (y_old < 0 && y >= 0) up.push_back(t - dt * y / (y - y_old));
    y_old = y;
  }
  REQUIRE(up.size() >= 3);
  return (up.back() - up.front()) / double(up.size() - 1);
}

}  // namespace

TEST_CASE("elastic rod: invalid input is rejected with the parameter named", "[rod]") {
  System system = make_blade(4);
  const auto message = [&](auto&& make) {
    try {
      make();
    } catch (const sphfsi::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no InputError");
  };
  auto params = weightless();
  params.section.thickness = 0;
  CHECK_THAT(message([&] { Rod(system, 0, blade, params); }), Catch::Contains("thickness"));
  params = weightless();
  params.section.width = -1;
  CHECK_THAT(message([&] { Rod(system, 0, blade, params); }), Catch::Contains("width"));
  params = weightless();
  params.cfl = 1.5;
  CHECK_THAT(message([&] { Rod(system, 0, blade, params); }), Catch::Contains("cfl"));
  params = weightless();
  params.damping = -1;
  CHECK_THAT(message([&] { Rod(system, 0, blade, params); }), Catch::Contains("damping"));
  params = weightless();
  params.stretch_limit = 0.5;
  CHECK_THAT(message([&] { Rod(system, 0, blade, params); }), Catch::Contains("stretch_limit"));
  params = weightless();
  params.ambient_density = -1;
  CHECK_THAT(message([&] { Rod(system, 0, blade, params); }), Catch::Contains("ambient_density"));
  auto soft = blade;
  soft.youngs_modulus = -1;
  CHECK_THAT(message([&] { Rod(system, 0, soft, weightless()); }), Catch::Contains("youngs_modulus"));
  soft = blade;
  soft.poisson_ratio = 0.5;
  CHECK_THAT(message([&] { Rod(system, 0, soft, weightless()); }), Catch::Contains("poisson_ratio"));
  CHECK_THAT(message([&] { Rod(system, 7, blade, weightless()); }), Catch::Contains("[3, inf)"));
  CHECK_THAT(message([&] { sphfsi::add_elastic_rod(system, V(0, 0), V(1, 0), L, 2, blade, section, 0.01, 1); }),
             Catch::Contains("node_count"));
  CHECK_THAT(message([&] { sphfsi::add_elastic_rod(system, V(0, 0), V(1, 0), -L, 5, blade, section, 0.01, 1); }),
             Catch::Contains("length"));
  System twice = make_system();
  twice.particles().add(sphfsi::Kind::solid, V(0, 0), V::Zero(), 1000, 1e-3, 0.01, 0);
  twice.particles().add(sphfsi::Kind::solid, V(0, 0), V::Zero(), 1000, 1e-3, 0.01, 0);
  twice.particles().add(sphfsi::Kind::solid, V(0.1, 0), V::Zero(), 1000, 1e-3, 0.01, 0);
  CHECK_THAT(message([&] { Rod(twice, 0, blade, weightless()); }), Catch::Contains("coincide"));
}

TEST_CASE("elastic rod: the reference elastica solver reproduces the small-load limit", "[rod]") {
  // Linear beam theory: deflection alpha/3, shortening (from the slope) alpha^2 / 15, relative corrections O(alpha^2).
  const auto [d, s] = elastica_tip_load(1e-3);
  CHECK(d == Approx(1e-3 / 3).epsilon(1e-5));
  CHECK(s == Approx(1e-6 / 15).epsilon(1e-4));
}

TEST_CASE("elastic rod: large-deflection cantilever under a tip load matches the elastica", "[rod]") {
  // Expected discretisation error: in the linear limit the discrete tip deflection is exactly the trapezoidal rule
  // of int_0^L (L - s)^2 ds / EI (clamp half cell D_0 = ds/2), i.e. +1/(2 n^2) relative for n edges; the scheme is
  // second order, so the error must fall by about 4 per doubling of n at any load.
  for (double alpha : {0.1, 1.0, 10.0}) {
    const auto [d_ref, s_ref] = elastica_tip_load(alpha);
    std::vector<double> error;
    for (int edges : {10, 20, 40}) {
      const auto [d, s] = rod_tip_load(edges, alpha);
      INFO("alpha = " << alpha << ", edges = " << edges << ": deflection " << d << " (elastica " << d_ref
                      << "), shortening " << s << " (elastica " << s_ref << ")");
      // Bound: twice the linear trapezoidal estimate 1/(2 n^2), plus 1e-4 for extensibility (strain 8e-5 at alpha 10).
      CHECK(std::abs(d - d_ref) / d_ref < 1.0 / (edges * edges) + 1e-4);
      CHECK(std::abs(s - s_ref) / s_ref < 2.0 / (edges * edges) + 2e-4);
      error.push_back(std::abs(d - d_ref) / d_ref);
    }
    INFO("alpha = " << alpha << ": errors " << error[0] << ", " << error[1] << ", " << error[2]);
    CHECK(std::log2(error[0] / error[1]) == Approx(2).margin(0.3));
    CHECK(std::log2(error[1] / error[2]) == Approx(2).margin(0.3));
  }
}

TEST_CASE("elastic rod: first bending frequency converges to Euler-Bernoulli", "[rod]") {
  // Small amplitude (tip 1e-3 L): geometric nonlinearity changes the period by O(amplitude^2) = 1e-6. Rotary
  // inertia, left out of Euler-Bernoulli and of the rod, would be (t/L)^2 = 1e-4. The discretisation is second
  // order: |error| < 1/n^2 (the static flexibility alone gives -1/(4 n^2) on the frequency) and falls ~4x per doubling.
  const double period_eb = 2 * std::numbers::pi / omega1;
  std::vector<double> error;
  for (int edges : {10, 20, 40}) {
    const double period = rod_period(edges, 1e-3 * L * omega1);
    error.push_back(period / period_eb - 1);
    INFO("edges = " << edges << ": period " << period << " s, Euler-Bernoulli " << period_eb << " s");
    CHECK(std::abs(error.back()) < 1.0 / (edges * edges));
  }
  INFO("errors " << error[0] << ", " << error[1] << ", " << error[2]);
  CHECK(std::log2(error[0] / error[1]) == Approx(2).margin(0.3));
  CHECK(std::log2(error[1] / error[2]) == Approx(2).margin(0.3));
}

TEST_CASE("elastic rod: undamped energy has no drift and its error is the integrator's O(dt^2)", "[rod]") {
  // Large amplitude (tip speed 0.5 L omega1, tip excursion about 0.5 L): kinetic + stored energy of velocity Verlet
  // oscillates about the conserved shadow energy with an amplitude proportional to dt^2; halving the rod's step
  // (cfl 0.8 -> 0.4) must divide the band by 4 (3 to 5 allowed), and the band stays below 1e-4 of the energy.
  const auto band = [](double cfl) {
    System system = make_blade(20);
    auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double s = p.position[i].x() / L;
      p.velocity[i] = V(0, 0.5 * L * omega1 * s * s);
    }
    auto params = weightless();
    params.cfl = cfl;
    Rod rod(system, 0, blade, params);
    rod.clamp_base();
    rod.compute_rates(system, 0);
    const double e0 = rod.kinetic_energy() + rod.strain_energy();
    const double dt = 2 * std::numbers::pi / omega1 / 500;
    double worst = 0, t = 0;
    for (int step = 0; step < 1500; ++step, t += dt) {
      rod.advance(system, t, dt);
      worst = std::max(worst, std::abs(rod.kinetic_energy() + rod.strain_energy() - e0) / e0);
    }
    return worst;
  };
  const double coarse = band(0.8), fine = band(0.4);
  INFO("relative energy band: cfl 0.8 " << coarse << ", cfl 0.4 " << fine);
  CHECK(coarse < 1e-4);
  CHECK(coarse / fine > 3);
  CHECK(coarse / fine < 5);
}

TEST_CASE("elastic rod: a free rod conserves linear and angular momentum", "[rod]") {
  System system = make_blade(12);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {  // bent and spinning, deterministic
    const double s = p.position[i].x() / L;
    p.position[i].y() += 0.2 * L * s * s;
    p.velocity[i] = V(0.3 * std::sin(7.0 * s), 0.5 * std::cos(5.0 * s));
  }
  Rod rod(system, 0, blade, weightless());
  rod.compute_rates(system, 0);
  const auto momenta = [&] {
    V linear = V::Zero();
    double angular = 0, scale = 0;
    for (std::size_t k = 0; k < rod.positions().size(); ++k) {
      const double m = rod.node_masses()[k];
      const V& x = rod.positions()[k];
      const V& v = rod.velocities()[k];
      linear += m * v;
      angular += m * (x.x() * v.y() - x.y() * v.x());
      scale += m * v.norm();
    }
    return std::tuple{linear, angular, scale};
  };
  const auto [p0, l0, scale] = momenta();
  double t = 0;
  const double dt = 2e-3;
  for (int step = 0; step < 200; ++step, t += dt) rod.advance(system, t, dt);
  const auto [p1, l1, unused] = momenta();
  CHECK(rod.sub_step_total() > 1000);
  CHECK((p1 - p0).norm() < 1e-12 * scale);
  CHECK(std::abs(l1 - l0) < 1e-10 * scale * L);
}

TEST_CASE("elastic rod: a rigid motion of a curved rod gives no internal force", "[rod]") {
  System system = make_system();
  const int n = 15;
  auto& p = system.particles();
  for (int i = 0; i < n; ++i) {  // a quarter circle at rest: the rest shape is curved
    const double a = 0.5 * std::numbers::pi * i / (n - 1);
    p.add(sphfsi::Kind::solid, V(L * std::cos(a), L * std::sin(a)), V::Zero(), blade.density, 1e-3, 0.01, 0);
  }
  Rod rod(system, 0, blade, weightless());
  const double angle = 0.7;
  const V shift(0.05, -0.02);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const V x = p.position[i];
    p.position[i] =
        V(std::cos(angle) * x.x() - std::sin(angle) * x.y(), std::sin(angle) * x.x() + std::cos(angle) * x.y()) + shift;
  }
  const std::vector<V> before = p.position;
  double t = 0;
  for (int step = 0; step < 50; ++step, t += 1e-3) rod.advance(system, t, 1e-3);
  CHECK(rod.sub_step_total() > 500);
  double moved = 0;
  for (std::size_t i = 0; i < p.size(); ++i) moved = std::max(moved, (p.position[i] - before[i]).norm());
  CHECK(moved < 1e-12 * L);
  CHECK(rod.strain_energy() < 1e-20);
  for (auto id : rod.particle_ids()) {
    CHECK(std::abs(rod.axial_force(id)) < 1e-9 * blade.youngs_modulus * section.area());
    CHECK(std::abs(rod.bending_moment(id)) < 1e-9 * EI / L);
  }
}

TEST_CASE("elastic rod: sub-cycling with the external force held over the outer step", "[rod]") {
  // A blade driven by a state-dependent external force, a normal drag towards a current U with relaxation rate k,
  // written into p.acceleration once per outer step as a coupling would. Outer step = 50 rod steps against outer
  // step = rod step. Holding the force for dt_outer is a first-order hold: it lags the force by dt_outer / 2, so the
  // tip paths may differ by about k dt_outer / 2 of the tip excursion; the test allows k dt_outer.
  const double k = 0.2 * omega1, U = 1.0;  // 1/s, m/s
  const int ratio = 50;
  const auto run = [&](int rod_steps_per_outer, double dt_rod) {
    System system = make_blade(20);
    Rod rod(system, 0, blade, weightless());
    rod.clamp_base();
    rod.compute_rates(system, 0);
    const double dt = rod_steps_per_outer * dt_rod;
    auto& p = system.particles();
    std::vector<V> path;
    for (int step = 0; step < 500 * ratio / rod_steps_per_outer; ++step) {
      for (auto id : rod.particle_ids()) {
        const std::size_t s = p.slot_of_id(id);
        const double u_n = (U * V(0, 1) - p.velocity[s]).dot(p.normal[s]);
        p.acceleration[s] = k * u_n * p.normal[s];
      }
      rod.advance(system, step * dt, dt);
      if ((step + 1) % (ratio / rod_steps_per_outer) == 0) path.push_back(rod.tip_position());
    }
    CHECK(rod.sub_step_total() == 500 * ratio);
    return path;
  };
  System probe = make_blade(20);
  const double dt_rod = Rod(probe, 0, blade, weightless()).solid_time_step();
  const auto sub_cycled = run(ratio, dt_rod), global = run(1, dt_rod);
  REQUIRE(sub_cycled.size() == global.size());
  double difference = 0, excursion = 0;
  for (std::size_t i = 0; i < global.size(); ++i) {
    difference = std::max(difference, (sub_cycled[i] - global[i]).norm());
    excursion = std::max(excursion, (global[i] - V(L, 0)).norm());
  }
  INFO("tip excursion " << excursion << " m, largest difference " << difference << " m, k dt_outer "
                        << k * ratio * dt_rod);
  CHECK(excursion > 0.1 * L);
  CHECK(difference < k * ratio * dt_rod * excursion);
}

TEST_CASE("elastic rod: nodes carry the blade normal, stress and checkpoint state", "[rod]") {
  System system = make_blade(10);
  Rod rod(system, 0, blade, weightless(2 * omega1));
  rod.clamp_base();
  auto& p = system.particles();
  const std::uint32_t tip = rod.particle_ids().back();
  double t = 0;
  for (int step = 0; step < 50; ++step, t += 1e-2) {
    p.acceleration[p.slot_of_id(tip)] = V(0, -2 * EI / (L * L) / rod.node_masses().back());
    rod.advance(system, t, 1e-2);
  }
  const auto& ids = rod.particle_ids();
  for (std::size_t k = 0; k + 1 < ids.size(); ++k) {  // unit normal, perpendicular to the blade at every node
    const V n = p.normal[p.slot_of_id(ids[k])];
    const V edge = (rod.positions()[k + 1] - rod.positions()[k]).normalized();
    CHECK(n.norm() == Approx(1).epsilon(1e-12));
    CHECK(std::abs(n.dot(edge)) < 0.2);              // the node normal averages its two edges (turning angle < 0.4 rad)
    CHECK(n.x() * edge.y() - n.y() * edge.x() < 0);  // left of the base-to-tip tangent
  }
  // Near the clamp, tension-free bending: fibre stress |M| (t/2) / I along the tangent.
  const auto sigma = rod.cauchy_stress(ids[1]);
  const double fibre = std::abs(rod.bending_moment(ids[1])) * 0.5 * thick / section.second_moment();
  CHECK(std::abs(sigma.trace()) == Approx(fibre).epsilon(0.02));
  CHECK(rod.max_stretch() > 1);
  CHECK(rod.max_stretch() < 1 + 1e-4);

  sphfsi::io::CheckpointWriter w;
  rod.save_checkpoint(w);
  System copy_system = make_blade(10);
  Rod copy(copy_system, 0, blade, weightless(2 * omega1));
  sphfsi::io::CheckpointReader r(w.bytes().data(), w.bytes().size(), "memory");
  copy.load_checkpoint(r);
  CHECK(r.at_end());
  CHECK(copy.sub_step_total() == rod.sub_step_total());
  CHECK((copy.tip_position() - rod.tip_position()).norm() == 0);
  CHECK(copy.strain_energy() == rod.strain_energy());
  System other = make_blade(11);
  Rod wrong(other, 0, blade, weightless());
  sphfsi::io::CheckpointReader r2(w.bytes().data(), w.bytes().size(), "memory");
  CHECK_THROWS_AS(wrong.load_checkpoint(r2), sphfsi::InputError);
}

TEST_CASE("elastic rod: a contact plane stops a blade folding onto the bed", "[rod]") {
  // A horizontal cantilever 1 cm above a bed, its tip loaded down far enough to reach it: no node crosses the
  // plane (nodes stay at >= the gap) and the clamped root is unaffected.
  System system = make_blade(20);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) p.position[i][1] += 0.01;
  sphfsi::ElasticRodParameters<double> params = weightless(50);  // damped to rest
  params.gravity = V(0, -9.81 * 40);  // sags L^4 q / (8 EI) = 0.16 m without the bed, far more than 1 cm
  Rod rod(system, 0, blade, params);
  rod.clamp_base();
  const double gap = 0.002;
  rod.set_contact_plane(V(0, 0), V(0, 1), gap);
  for (int k = 0; k < 400; ++k) rod.advance(system, k * 1e-3, 1e-3);
  double lowest = 1;
  for (std::size_t i = 0; i < p.size(); ++i) lowest = std::min(lowest, p.position[i][1]);
  CHECK(lowest >= gap - 1e-12);
  CHECK(lowest <= gap + 1e-3);  // the blade does rest on the bed
  CHECK_THROWS_WITH(rod.set_contact_plane(V(0, 0), V(0, 0), gap), Catch::Contains("set_contact_plane |normal|"));
}

TEST_CASE("elastic rod: damping relative to the towing carriage leaves a steadily towed blade straight", "[rod]") {
  // The cantilever towed normal to itself at a steady U (no fluid, no gravity). Damped relative to the carriage
  // (damping_relative_to_clamp) it moves rigidly: no deflection. Damped in absolute terms, the damping is a uniform
  // load q = c_d rho A U that bends it back by the cantilever's q L^4 / (8 EI) (small: 3 % of L, linear theory).
  const double U = 0.01, c_d = 2 * omega1;
  for (const bool relative : {true, false}) {
    System system = make_blade(20);
    auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = V(0, U);
    sphfsi::ElasticRodParameters<double> params = weightless(c_d);
    params.damping_relative_to_clamp = relative;
    Rod rod(system, 0, blade, params);
    rod.clamp_base();
    rod.set_clamp_motion([&](double t) { return V(0, U * t); }, [&](double) { return V(0, U); });
    const double dt = 200 * rod.solid_time_step();
    double t = 0;
    while (t < 40 * 2 * std::numbers::pi / omega1) {
      rod.advance(system, t, dt);
      t += dt;
    }
    const double deflection = rod.tip_position().y() - U * t;  // the base sits at U t
    INFO((relative ? "relative" : "absolute") << " damping: tip deflection " << deflection << " m");
    if (relative) {
      CHECK(std::abs(deflection) < 1e-12 * L);
    } else {
      const double q = c_d * rhoA * U;
      CHECK(deflection == Approx(-q * L * L * L * L / (8 * EI)).epsilon(0.02));
    }
  }
}

TEST_CASE("elastic rod: nodes added after other particles were removed (ids above the particle count)", "[rod]") {
  // A scene that takes fluid out before adding its blade (an inclined blade cut into a fluid block) leaves ids
  // above the particle count. The rod indexes its nodes by id: it must size that index by the id capacity, not by
  // the particle count (a heap overflow before, found by blade_in_current --inclinations).
  System system = make_system();
  auto& p = system.particles();
  for (int k = 0; k < 50; ++k) p.add(sphfsi::Kind::fluid, V(-0.5 + 0.01 * k, 0.5), V::Zero(), 1000, 0.1, 0.013);
  for (std::size_t k = p.size(); k-- > 5;) p.remove(k);
  sphfsi::add_elastic_rod(system, V(0, 0), V(1, 0), L, 11, blade, section, L / 10, 0);
  REQUIRE(p.size() == 16);
  REQUIRE(p.id_capacity() == 61);
  Rod rod(system, 0, blade, weightless());
  rod.clamp_base();
  CHECK(rod.particle_ids().size() == 11);
  CHECK(rod.particle_ids().back() == 60);
  CHECK(rod.tip_position()[0] == Approx(L).epsilon(1e-12));
  rod.advance(system, 0, rod.solid_time_step());  // reads and writes every node by its id
  CHECK(rod.tip_position()[0] == Approx(L).epsilon(1e-12));
}

TEST_CASE("reconfiguration: the static blade in a current, small-load limit and bad input", "[rod][reconfiguration]") {
  using sphfsi::analysis::luhar_nepf_reconfiguration;
  // Small Ca: the linear cantilever under a uniform load q: tip slope q l^3 / (6 EI) = Ca / 6, tip deflection Ca / 8,
  // l_e / l = 1 - O(Ca^2) (the load falls as cos^2 and its horizontal part as cos^3). Relative corrections O(Ca^2).
  const auto small = luhar_nepf_reconfiguration(1e-3);
  CHECK(small.tip_angle == Approx(1e-3 / 6).epsilon(1e-5));
  CHECK(small.tip_x == Approx(1e-3 / 8).epsilon(1e-5));
  CHECK(small.tip_z == Approx(1).epsilon(1e-5));
  CHECK(small.effective_length == Approx(1).epsilon(1e-5));
  // Rigid limit and large Ca: l_e falls as Ca^(-1/3) (Luhar & Nepf 2011's scaling): l_e Ca^(1/3) settles.
  CHECK(luhar_nepf_reconfiguration(0.0).effective_length == Approx(1).epsilon(1e-12));
  const double c4 = luhar_nepf_reconfiguration(1e4, 8000).effective_length * std::cbrt(1e4);
  const double c5 = luhar_nepf_reconfiguration(1e5, 8000).effective_length * std::cbrt(1e5);
  CHECK(std::abs(c5 / c4 - 1) < 0.01);
  // The tabulated law of cos^2 at 10-degree steps reproduces the exact law to the interpolation error (< 1 %).
  std::vector<double> angle, value;
  for (int d = 0; d < 90; d += 10) {
    angle.push_back(d * std::numbers::pi / 180);
    value.push_back(std::cos(angle.back()) * std::cos(angle.back()));
  }
  const sphfsi::analysis::TabulatedLoad<double> tabulated(angle, value, 0.0);
  for (double ca : {1.0, 30.0, 1000.0}) {
    const double exact = luhar_nepf_reconfiguration(ca).effective_length;
    const double table =
        sphfsi::analysis::static_reconfiguration(ca, tabulated, [](double) { return 0.0; }).effective_length;
    CHECK(std::abs(table / exact - 1) < 0.01);
  }
  CHECK_THROWS_WITH(luhar_nepf_reconfiguration(-1.0), Catch::Contains("Cauchy number"));
  CHECK_THROWS_WITH(sphfsi::analysis::static_reconfiguration(
                        1.0, [](double) { return 0.0; }, [](double) { return 0.0; }),
                    Catch::Contains("normal_load(0)"));
  CHECK_THROWS_WITH(sphfsi::analysis::TabulatedLoad<double>({0.0, 0.5, 0.4}, {1, 1, 1}, 0.0),
                    Catch::Contains("not above"));
  CHECK_THROWS_WITH(sphfsi::analysis::TabulatedLoad<double>({0.1}, {1}, 0.0), Catch::Contains("first angle must be 0"));
  CHECK_THROWS_WITH(sphfsi::analysis::TabulatedLoad<double>({0.0, 1.6}, {1, 1}, 0.0), Catch::Contains("pi/2"));
}

TEST_CASE("reconfiguration: the shooting solution equals the discrete rod relaxed under the same local load",
          "[rod][reconfiguration]") {
  // Two independent discretisations of the same static problem: the ODE shot from the tip
  // (analysis/reconfiguration.hpp, RK4) and the discrete elastic rod with 40 edges relaxed dynamically under the local
  // load, evaluated at every node from its own tangent (follower load, trapezoidal in s). They agree to the rod's
  // O(1/n^2) = 6e-4 (observed order 2 in the static tables of docs/thin-blades.md): bound 2e-3 on l_e / l and on the
  // tip position over l. The law is Luhar & Nepf's cos^2 plus a skin friction of 0.05 of the upright normal load, so
  // both load directions are used.
  const auto normal = [](double th) { return std::cos(th) * std::cos(th); };
  const auto tangential = [](double th) { return 0.05 * std::sin(th); };
  for (const double ca : {3.0, 30.0}) {
    const int edges = 40;
    System system = make_system();
    sphfsi::add_elastic_rod(system, V(0, 0), V(0, 1), L, edges + 1, blade, section, L / edges, 0);
    Rod rod(system, 0, blade, weightless(2 * omega1));
    rod.clamp_base();
    auto& p = system.particles();
    const auto& ids = rod.particle_ids();
    const double q = ca * EI / (L * L * L);  // the upright blade's load per unit length, N/m
    const double ds = L / edges, dt = 20 * rod.solid_time_step();
    double t = 0, load_x = 0;
    for (int step = 0; step < 200000; ++step) {
      load_x = 0;
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const auto x = [&](std::size_t k) { return p.position[p.slot_of_id(ids[k])]; };
        const V tangent = (i == 0                ? x(1) - x(0)
                           : i + 1 == ids.size() ? x(i) - x(i - 1)
                                                 : x(i + 1) - x(i - 1))
                              .normalized();
        const double th = std::atan2(tangent[0], tangent[1]);
        const V force = q * (i == 0 || i + 1 == ids.size() ? ds / 2 : ds) *
                        (normal(th) * V(tangent[1], -tangent[0]) + tangential(th) * tangent);
        p.acceleration[p.slot_of_id(ids[i])] = force / rod.node_masses()[i];
        load_x += force[0];
      }
      rod.advance(system, t, dt);
      t += dt;
      double v_max = 0;
      for (const auto& v : rod.velocities()) v_max = std::max(v_max, v.norm());
      if (step > 100 && v_max < 1e-10 * L * omega1) break;
    }
    const auto shot = sphfsi::analysis::static_reconfiguration(ca, normal, tangential);
    INFO("Ca = " << ca << ": rod l_e / l = " << load_x / (q * L) << ", shooting " << shot.effective_length);
    CHECK(std::abs(load_x / (q * L) - shot.effective_length) < 1e-3);
    CHECK(std::abs(rod.tip_position()[0] / L - shot.tip_x) < 1e-3);
    CHECK(std::abs(rod.tip_position()[1] / L - shot.tip_z) < 1e-3);
  }
}

namespace {
using System3 = sphfsi::ParticleSystem<3, double, sphfsi::WendlandC2<3>, sphfsi::LinearEos<double>>;
using Ribbon = sphfsi::ElasticRod<System3>;
using V3 = sphfsi::Vec<3, double>;
static_assert(sphfsi::SolidModel<Ribbon, System3>);
}  // namespace

TEST_CASE("elastic rod: a 3D ribbon bends as the planar rod under the same total load", "[rod][ribbon]") {
  // The same blade (10 edges) as a 2D rod and as a 3D ribbon with rows of 3 across its width b. A tip load P is put
  // on one particle of the ribbon's tip row only: the node sees the row's total. Both relax dynamically to rest.
  const int edges = 10, rows = 3;
  const double alpha = 3, P = alpha * EI / (L * L), dt_outer = 1e-4;
  System flat = make_blade(edges);
  Rod rod(flat, 0, blade, weightless(2 * omega1));
  rod.clamp_base();
  System3 space(sphfsi::Domain<3, double>(V3(-1, -1, -1), V3(1, 1, 1)), sphfsi::LinearEos<double>(1000, 10));
  const auto ids =
      sphfsi::add_elastic_ribbon(space, V(0, 0), V(1, 0), L, edges + 1, rows, 0.2, blade, section, L / edges, 0);
  REQUIRE(ids.size() == std::size_t((edges + 1) * rows));
  Ribbon ribbon(space, 0, blade, weightless(2 * omega1));
  CHECK(ribbon.node_count() == std::size_t(edges + 1));
  CHECK(ribbon.particles_per_node() == std::size_t(rows));
  CHECK(ribbon.clamp_where([](const V3& x) { return x.x() < 1e-12; }) == 1);  // the base row
  const auto [y_lo, y_hi] = ribbon.lateral_extent();
  CHECK(y_lo == Approx(0.2 - b / 2).margin(1e-15));
  CHECK(y_hi == Approx(0.2 + b / 2).margin(1e-15));
  // each particle carries b / rows of the width: the rows' masses sum to the rod's node masses
  double mass = 0;
  for (auto id : ids) mass += space.particles().mass[space.particles().slot_of_id(id)];
  CHECK(mass == Approx(blade.density * section.area() * L).epsilon(1e-12));
  auto& p3 = space.particles();
  const std::size_t loaded = p3.slot_of_id(ids.back());
  double t = 0;
  for (int step = 0; step < 3000; ++step) {
    flat.particles().acceleration[flat.particles().slot_of_id(rod.particle_ids().back())] =
        V(0, -P / rod.node_masses().back());
    for (auto id : ids) p3.acceleration[p3.slot_of_id(id)].setZero();
    p3.acceleration[loaded] = V3(0, 0, -P / p3.mass[loaded]);
    rod.advance(flat, t, dt_outer);
    ribbon.advance(space, t, dt_outer);
    t += dt_outer;
  }
  const double tip_dy = -rod.tip_position().y() / L;
  REQUIRE(tip_dy > 0.3);  // a large deflection: the comparison is not a small-load limit
  for (std::size_t k = 0; k < ribbon.node_count(); ++k) {
    CHECK((ribbon.positions()[k] - rod.positions()[k]).norm() < 1e-12 * L);
    CHECK((ribbon.velocities()[k] - rod.velocities()[k]).norm() < 1e-9 * L * omega1);
  }
  // every particle of a row sits at its node's (x, z), at its own y, moves in the x-z plane, and carries the normal
  std::array<int, 1> checked{0};
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const std::size_t s = p3.slot_of_id(ids[i]), k = i / rows;
    const V3 x = p3.position[s];
    CHECK(x.x() == ribbon.positions()[k].x());
    CHECK(x.z() == ribbon.positions()[k].y());
    CHECK(x.y() == Approx(0.2 + (double(i % rows) - 1) * b / rows).epsilon(1e-14));
    CHECK(p3.velocity[s].y() == 0);
    const V n2 = flat.particles().normal[flat.particles().slot_of_id(rod.particle_ids()[k])];
    CHECK((p3.normal[s] - V3(n2.x(), 0, n2.y())).norm() < 1e-9);
    ++checked[0];
  }
  CHECK(checked[0] == (edges + 1) * rows);
  // the total coupling force is the sum over the particles (here the tip load)
  CHECK((ribbon.coupling_force(p3) - V3(0, 0, -P)).norm() < 1e-12 * P);
}

TEST_CASE("elastic rod: a 3D ribbon with unequal rows is rejected", "[rod][ribbon]") {
  System3 space(sphfsi::Domain<3, double>(V3(-1, -1, -1), V3(1, 1, 1)), sphfsi::LinearEos<double>(1000, 10));
  sphfsi::add_elastic_ribbon(space, V(0, 0), V(0, 1), L, 6, 2, 0.0, blade, section, L / 5, 0);
  auto& p = space.particles();
  p.position[p.slot_of_id(5)].x() += 1e-3;  // the second particle of node 2's row leaves the row
  CHECK_THROWS_WITH(Ribbon(space, 0, blade, weightless()), Catch::Contains("ElasticRod: particle id 5"));
  p.remove(p.slot_of_id(5));  // a row one particle short
  CHECK_THROWS_WITH(Ribbon(space, 0, blade, weightless()),
                    Catch::Contains("has 11 particles, not a whole number of rows of 2"));
  CHECK_THROWS_WITH(sphfsi::add_elastic_ribbon(space, V(0, 0), V(0, 1), L, 6, 0, 0.0, blade, section, L / 5, 1),
                    Catch::Contains("width_particles"));
}
