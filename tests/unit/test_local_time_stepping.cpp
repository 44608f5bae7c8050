// Local time stepping (integrators/local_time_stepping.hpp; issue 9): with one smoothing length a macro step is two
// symplectic steps, bit for bit; two tanks of different resolutions in one scene each advance as with their own
// step; the still tank with nested APR boxes settles as with one global step for fewer particle-steps; bad input.
#include "../../examples/hydrostatic_tank/tank_scene.hpp"
#include "nested_apr_tank.hpp"

#include <sphfsi/fluid/adaptive_refinement.hpp>
#include <sphfsi/integrators/local_time_stepping.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <tuple>
#include <vector>

using namespace sphfsi;
namespace tank = sphfsi::examples::tank;

namespace {

using V2 = Vec<2, double>;
using LocalTankSimulation = Simulation<tank::System, LocalSymplecticVerlet>;

// A sloshing start: horizontal velocity U sin(pi z / (2 H)) cos(pi (x - x0) / L) in the block [x0, x0 + L] x [0, H].
void set_sloshing(tank::System& system, double x0, double x1, double depth, double speed) {
  auto& p = system.particles();
  const double pi = std::acos(-1.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid || p.position[i][0] < x0 || p.position[i][0] > x1) continue;
    const V2 x = p.position[i];
    p.velocity[i] = V2(speed * std::sin(0.5 * pi * x[1] / depth) * std::cos(pi * (x[0] - x0) / (x1 - x0)), 0);
  }
}

// A tank of width L and depth H at spacing dp with its left wall face at x0, in `system` (dynamic walls, masses
// rho dp^2 as tank::make_tank gives them).
void add_tank(tank::System& system, double x0, const tank::TankConfig& cfg, double dp) {
  const Resolution<double> res{dp, cfg.smoothing_ratio};
  const std::size_t first = system.particles().size();
  add_fluid_block(system, V2(x0, 0), V2(x0 + cfg.width, cfg.depth), res, cfg.depth, cfg.gravity);
  add_box_walls(system, V2(x0, 0), V2(x0 + cfg.width, cfg.wall_height), res, cfg.walls);
  set_hydrostatic_wall_density(system, cfg.depth, cfg.gravity);
  auto& p = system.particles();
  for (std::size_t i = first; i < p.size(); ++i) p.mass[i] = p.density[i] * dp * dp;
}

tank::System make_system(double x_max, const tank::TankConfig& cfg) {
  const double margin = 0.5 * cfg.depth;  // room for three wall layers at the coarsest spacing
  return tank::System(Domain<2, double>(V2(-margin, -margin), V2(x_max + margin, cfg.wall_height + margin)),
                      Tait<double>(cfg.rho0, cfg.sound_speed()));
}

// Largest |x_a - x_b| over the particles of `a` with ids in [first, first + count), matched by id in `b` shifted by
// `offset` (b's id = a's id - offset).
double largest_position_difference(const tank::System& a, const tank::System& b, std::uint32_t first,
                                   std::uint32_t count, std::uint32_t offset) {
  double largest = 0;
  for (std::uint32_t id = first; id < first + count; ++id) {
    const V2 xa = a.particles().position[a.particles().slot_of_id(id)];
    const V2 xb = b.particles().position[b.particles().slot_of_id(id - offset)];
    largest = std::max(largest, (xa - xb).norm());
  }
  return largest;
}

// Tank A at dp and tank B at dp / 2, side by side without contact (with same_resolution_pairs neither sees the
// other), both sloshing. dt is the macro step: the fine tank's acoustic limit is half the coarse one's, so dt / 2 is
// at CFL 0.2 of the fine tank.
struct TwoTanks {
  tank::TankConfig cfg = [] {
    tank::TankConfig c;
    c.particles_over_depth = 8;
    c.width = 0.4;
    return c;
  }();
  double dp = cfg.dp(), gap = 0.3, x_b = cfg.width + gap, x_max = x_b + cfg.width;
  double dt = 2 * 0.2 * 0.5 * dp * cfg.smoothing_ratio / cfg.sound_speed();
  FluidParameters<2, double> fluid = [this] {
    auto f = tank::fluid_parameters(cfg);
    f.same_resolution_pairs = true;
    return f;
  }();

  tank::System scene(bool with_a, bool with_b) const {
    tank::System s = make_system(x_max, cfg);
    if (with_a) add_tank(s, 0, cfg, dp);
    if (with_b) add_tank(s, x_b, cfg, 0.5 * dp);
    if (with_a) set_sloshing(s, 0, cfg.width, cfg.depth, 0.2);
    if (with_b) set_sloshing(s, x_b, x_max, cfg.depth, 0.2);
    return s;
  }
};

TimeStepParameters<double> fixed_step(double dt) {
  TimeStepParameters<double> s;
  s.fixed_dt = dt;
  return s;
}

}  // namespace

TEST_CASE("local time stepping: with one smoothing length a macro step is two symplectic steps, bit for bit",
          "[local_time_stepping]") {
  tank::TankConfig cfg;
  cfg.particles_over_depth = 16;
  cfg.width = 0.5;
  auto fluid = tank::fluid_parameters(cfg);
  tank::System plain_system = tank::make_tank(cfg), local_system = tank::make_tank(cfg);
  set_sloshing(plain_system, 0, cfg.width, cfg.depth, 0.2);
  set_sloshing(local_system, 0, cfg.width, cfg.depth, 0.2);
  const double dt = 0.1 * cfg.dp() * cfg.smoothing_ratio / cfg.sound_speed();
  TimeStepParameters<double> plain_step, local_step;
  plain_step.fixed_dt = dt;
  local_step.fixed_dt = 2 * dt;
  tank::TankSimulation plain(plain_system, fluid, plain_step);
  LocalTankSimulation local(local_system, fluid, local_step);
  for (int k = 0; k < 40; ++k) plain.step();
  for (int k = 0; k < 20; ++k) local.step();
  CHECK(local.coarse_particle_count() == 0);
  CHECK(local.particle_steps() == plain.particle_steps());
  const auto &a = plain_system.particles(), &b = local_system.particles();
  REQUIRE(a.size() == b.size());
  std::size_t differing = 0;
  double moved = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::size_t j = b.slot_of_id(a.id[i]);
    moved = std::max(moved, (a.position[i] - a.position_old[i]).norm());
    differing += a.position[i] != b.position[j] || a.velocity[i] != b.velocity[j] || a.density[i] != b.density[j];
  }
  INFO("largest displacement in the last step " << moved << " m");
  CHECK(moved > 0);  // the water moves: the comparison is not of a still state
  CHECK(differing == 0);
}

TEST_CASE("local time stepping: a coarse and a fine tank in one scene each advance as with their own step",
          "[local_time_stepping]") {
  // TwoTanks: A at dp, B at dp / 2. Under local time stepping with the macro step dt, A must follow a run of A alone
  // with dt and B a run of B alone with dt / 2, to round-off (the neighbour sums are added in another order).
  const TwoTanks tanks;
  const auto& [cfg, dp, gap, x_b, x_max, dt, fluid] = tanks;
  tank::System both = tanks.scene(true, true), only_a = tanks.scene(true, false), only_b = tanks.scene(false, true),
               a_half_step = tanks.scene(true, false);
  const auto count_a = static_cast<std::uint32_t>(only_a.particles().size());
  const auto count_b = static_cast<std::uint32_t>(only_b.particles().size());
  const int macro_steps = 30;
  LocalTankSimulation local(both, fluid, fixed_step(dt));
  tank::TankSimulation run_a(only_a, fluid, fixed_step(dt)), run_b(only_b, fluid, fixed_step(0.5 * dt)),
      run_a_half(a_half_step, fluid, fixed_step(0.5 * dt));
  for (int k = 0; k < macro_steps; ++k) {
    local.step();
    run_a.step();
    run_b.step();
    run_b.step();
    run_a_half.step();
    run_a_half.step();
  }
  CHECK(local.coarse_particle_count() == count_a);
  CHECK(local.particle_steps() == double(macro_steps) * (count_a + 2.0 * count_b));
  const double error_a = largest_position_difference(both, only_a, 0, count_a, 0);
  const double error_b = largest_position_difference(both, only_b, count_a, count_b, count_a);
  // The control: A with the fine step instead of its own differs from A with its own by the scheme's O(dt^2) error,
  // which a comparison at round-off must resolve (otherwise it could not tell the two steps apart).
  const double step_effect = largest_position_difference(only_a, a_half_step, 0, count_a, 0);
  const double tolerance = 1e-10 * dp;
  INFO("coarse tank: " << error_a << " m from its own run; fine tank: " << error_b
                       << " m; dt against dt / 2 moves A by " << step_effect << " m; tolerance " << tolerance << " m");
  CHECK(error_a <= tolerance);
  CHECK(error_b <= tolerance);
  CHECK(step_effect >= 100 * tolerance);
}

TEST_CASE("local time stepping: a still tank with nested boxes (dp, dp/2, dp/4) settles as with one global step",
          "[local_time_stepping][apr][tank]") {
  // The tank of the APR test in test_particle_refinement.cpp, stepped with the finest level's step (global) and with
  // the coarse levels at twice it (local): both settle to hydrostatic pressure within 2 % with the same kinetic
  // energy bound; the local run takes fewer particle-steps, by the fraction of particles in the coarse levels.
  using TankApr = AdaptiveRefinement<tank::System>;
  const tests::NestedAprTank apr_tank = tests::nested_apr_tank();
  const tank::TankConfig& cfg = apr_tank.cfg;
  const double zc = apr_tank.mid_depth, end_time = 0.5;
  struct Result {
    double energy = 0, mass_error = 0, p_mid = 0, p_theory = 0, particle_steps = 0;
    std::size_t steps = 0, lost = 0;
  };
  auto run = [&]<class Integrator>(Integrator) {
    using Sim = Simulation<tank::System, Integrator, TankApr>;
    tank::System system = tank::make_tank(cfg);
    Sim sim(system, apr_tank.fluid, {}, TankApr(system.domain(), apr_tank.boxes, apr_tank.params));
    auto& apr = sim.template model<0>();
    const double mass0 = apr.active_mass_momentum(system).first;
    apr.populate(system);
    Result r;
    std::size_t samples = 0;
    sim.run(end_time, [&](Sim& s) {
      r.lost = std::max(r.lost, tank::particles_outside(system, cfg));
      if (s.time() < end_time - 0.2) return;
      r.energy += tests::active_kinetic_energy(system);
      ++samples;
    });
    r.energy /= double(samples);
    r.mass_error = std::abs(apr.active_mass_momentum(system).first - mass0) / mass0;
    r.p_mid = tank::shepard_pressure(system, V2(0.5 * cfg.width, zc));
    r.p_theory = tank::hydrostatic_pressure(cfg, tests::active_volume(system) / cfg.width, zc);
    r.particle_steps = sim.particle_steps();
    r.steps = sim.step_count();
    return r;
  };
  const Result global = run(SymplecticVerlet{});
  const Result local = run(LocalSymplecticVerlet{});
  const double energy_bound = apr_tank.kinetic_energy_bound();
  INFO("global: " << global.steps << " steps, " << global.particle_steps << " particle-steps, kinetic energy "
                  << global.energy << " J/m, p_mid " << global.p_mid << " Pa (theory " << global.p_theory
                  << "); local: " << local.steps << " macro steps, " << local.particle_steps
                  << " particle-steps, kinetic energy " << local.energy << " J/m, p_mid " << local.p_mid
                  << " Pa (theory " << local.p_theory << "); bound " << energy_bound << " J/m");
  for (const Result* r : {&global, &local}) {
    CHECK(r->lost == 0);
    CHECK(r->mass_error <= 1e3 * std::numeric_limits<double>::epsilon());
    CHECK(std::abs(r->p_mid - r->p_theory) / r->p_theory <= 0.02);
    CHECK(r->energy <= energy_bound);
  }
  // The coarse levels (dp, dp / 2) hold most particles: they are stepped half as often.
  CHECK(local.particle_steps <= 0.75 * global.particle_steps);
}

TEST_CASE("local time stepping: a frozen particle's pairs give their share to its stepping neighbours only",
          "[local_time_stepping]") {
  // One resolution, the right half frozen (as a coarse particle outside a fine-step region is in a sub-step that
  // evaluates the fine level alone). With `mixed` the stepping half gets the rates of a full evaluation, to
  // round-off, and the frozen half keeps what it had, bit for bit. The control: without `mixed` the stepping
  // particles beside the frozen ones miss those pairs.
  tank::TankConfig cfg;
  cfg.particles_over_depth = 16;
  cfg.width = 0.5;
  auto params = tank::fluid_parameters(cfg);
  params.same_resolution_pairs = true;
  tank::System system = tank::make_tank(cfg);
  set_sloshing(system, 0, cfg.width, cfg.depth, 0.2);
  auto& p = system.particles();
  WcsphFluid<tank::System> fluid(params);
  system.update_neighbors(0);
  system.update_pressure();
  fluid.compute_rates(system);
  const std::vector<V2> full_acceleration = p.acceleration;
  const std::vector<double> full_density_rate = p.density_rate;
  std::vector<std::uint8_t> frozen(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) frozen[i] = p.position[i][0] > 0.5 * cfg.width;
  auto largest_errors = [&](bool mixed) {
    for (std::size_t i = 0; i < p.size(); ++i)
      if (frozen[i]) {
        p.acceleration[i] = V2(1234.5, -678.9);  // sentinels the evaluation must leave alone
        p.density_rate[i] = 42.0;
      }
    fluid.compute_rates(system, &frozen, mixed);
    double stepping = 0, scale = 0;
    bool kept = true;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::fluid) continue;
      if (frozen[i]) {
        kept = kept && p.acceleration[i] == V2(1234.5, -678.9) && p.density_rate[i] == 42.0;
        continue;
      }
      stepping = std::max(stepping, (p.acceleration[i] - full_acceleration[i]).norm());
      stepping = std::max(stepping, std::abs(p.density_rate[i] - full_density_rate[i]) * cfg.dp());
      scale = std::max(scale, full_acceleration[i].norm());
    }
    return std::tuple{stepping, scale, kept};
  };
  const auto [mixed_error, scale, mixed_kept] = largest_errors(true);
  const auto [unmixed_error, scale_b, unmixed_kept] = largest_errors(false);
  INFO("largest acceleration " << scale << " m/s^2; stepping half off the full evaluation by " << mixed_error
                               << " with mixed pairs, " << unmixed_error << " without");
  CHECK(mixed_kept);
  CHECK(unmixed_kept);
  CHECK(mixed_error <= 1e-12 * scale);
  CHECK(unmixed_error >= 1e-3 * scale);
}

TEST_CASE("local time stepping: coarse particles in a fine-step region step with the fine level",
          "[local_time_stepping]") {
  // The two tanks of the test above (A at dp, B at dp / 2). A region over all of A: both tanks advance as with the
  // fine step dt / 2, to round-off. A region over A's left half: that half steps at dt / 2 and the right half at dt,
  // the pairs across the split read the frozen partner at its midpoint; A then stays within the scheme's own step
  // error (A with dt against A with dt / 2) of the run with dt / 2, and its mass and particle-steps are counted.
  const TwoTanks tanks;
  const auto& [cfg, dp, gap, x_b, x_max, dt, fluid] = tanks;
  const int macro_steps = 30;
  tank::System only_a = tanks.scene(true, false), a_half_step = tanks.scene(true, false),
               only_b = tanks.scene(false, true);
  const auto count_a = static_cast<std::uint32_t>(only_a.particles().size());
  const auto count_b = static_cast<std::uint32_t>(only_b.particles().size());
  tank::TankSimulation run_a(only_a, fluid, fixed_step(dt)), run_a_half(a_half_step, fluid, fixed_step(0.5 * dt)),
      run_b(only_b, fluid, fixed_step(0.5 * dt));
  for (int k = 0; k < macro_steps; ++k) {
    run_a.step();
    run_a_half.step();
    run_a_half.step();
    run_b.step();
    run_b.step();
  }
  const double step_effect = largest_position_difference(only_a, a_half_step, 0, count_a, 0);
  const double below = -cfg.depth, above = 2 * cfg.wall_height;

  SECTION("a region over all of A") {
    tank::System both = tanks.scene(true, true);
    LocalTankSimulation local(both, fluid, fixed_step(dt));
    local.set_fine_step_regions({{V2(-cfg.depth, below), V2(cfg.width + 0.5 * gap, above)}});
    for (int k = 0; k < macro_steps; ++k) local.step();
    CHECK(local.coarse_particle_count() == 0);
    CHECK(local.particle_steps() == 2.0 * macro_steps * (count_a + count_b));
    const double error_a = largest_position_difference(both, a_half_step, 0, count_a, 0);
    const double error_b = largest_position_difference(both, only_b, count_a, count_b, count_a);
    const double tolerance = 1e-10 * dp;
    INFO("A " << error_a << " m from its run with dt / 2, B " << error_b
              << " m from its own; dt against dt / 2 moves A by " << step_effect << " m");
    CHECK(error_a <= tolerance);
    CHECK(error_b <= tolerance);
    CHECK(step_effect >= 100 * tolerance);
  }
  SECTION("a region over A's left half") {
    tank::System both = tanks.scene(true, true);
    LocalTankSimulation local(both, fluid, fixed_step(dt));
    local.set_fine_step_regions({{V2(-cfg.depth, below), V2(0.5 * cfg.width, above)}});
    std::size_t fast_a = 0;
    for (std::size_t i = 0; i < count_a; ++i) fast_a += both.particles().position[i][0] <= 0.5 * cfg.width;
    local.step();
    // the levels of the first macro step: B and A's left half fine, A's right half coarse
    CHECK(local.coarse_particle_count() == count_a - fast_a);
    CHECK(local.particle_steps() == 2.0 * (count_a + count_b) - double(count_a - fast_a));
    double mass0 = 0;
    for (std::size_t i = 0; i < count_a; ++i) mass0 += both.particles().mass[i];
    for (int k = 1; k < macro_steps; ++k) local.step();
    const double error_a = largest_position_difference(both, a_half_step, 0, count_a, 0);
    const double error_b = largest_position_difference(both, only_b, count_a, count_b, count_a);
    INFO("split A " << error_a << " m from its run with dt / 2; A with dt is " << step_effect << " m from it; B "
                    << error_b << " m from its own");
    CHECK(fast_a > 0);
    CHECK(fast_a < count_a);
    CHECK(error_a > 0);
    CHECK(error_a <= 2 * step_effect);
    CHECK(error_b <= 1e-10 * dp);  // B never meets A: untouched by the split
  }
  SECTION("bad regions") {
    tank::System both = tanks.scene(true, true);
    LocalTankSimulation local(both, fluid, fixed_step(dt));
    REQUIRE_THROWS_WITH(local.set_fine_step_regions({{V2(0.3, 0), V2(0.1, 1)}}),
                        Catch::Contains("set_fine_step_regions") && Catch::Contains("lower < upper"));
    tank::TankSimulation global(only_a, fluid, fixed_step(dt));
    REQUIRE_THROWS_WITH(global.set_fine_step_regions({{V2(0, 0), V2(1, 1)}}), Catch::Contains("local-time-stepping"));
  }
}

TEST_CASE("local time stepping: bad input gives an InputError naming the parameter and its valid range",
          "[local_time_stepping]") {
  tank::TankConfig cfg;
  cfg.particles_over_depth = 8;
  cfg.width = 0.4;
  const double x_b = cfg.width + 0.3, x_max = x_b + cfg.width;
  tank::System both = make_system(x_max, cfg);
  add_tank(both, 0, cfg, cfg.dp());
  add_tank(both, x_b, cfg, 0.5 * cfg.dp());
  SECTION("two resolutions that interact pair-wise cannot step at two rates") {
    auto fluid = tank::fluid_parameters(cfg);
    fluid.same_resolution_pairs = false;
    LocalTankSimulation local(both, fluid);
    REQUIRE_THROWS_WITH(local.step(), Catch::Contains("same_resolution_pairs") && Catch::Contains("valid"));
  }
  SECTION("a fixed macro step above the coarse level's limit") {
    auto fluid = tank::fluid_parameters(cfg);
    fluid.same_resolution_pairs = true;
    TimeStepParameters<double> s;
    s.fixed_dt = 2 * cfg.dp() * cfg.smoothing_ratio / cfg.sound_speed();  // 2 h / c of the coarse tank
    LocalTankSimulation local(both, fluid, s);
    REQUIRE_THROWS_WITH(local.step(), Catch::Contains("fixed_dt") && Catch::Contains("valid range"));
  }
}
