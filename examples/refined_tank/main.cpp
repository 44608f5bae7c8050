// sphfsi example: the hydrostatic tank with a refined band (issue 9 part 3). The tank of examples/hydrostatic_tank
// (dynamic walls) at base spacing dp = H / N, with two nested refinement boxes over its width at mid-depth: level 1
// (dp/2) and level 2 (dp/4). The band's particles split at the first steps (fluid/particle_refinement.hpp); the
// column must settle to the hydrostatic pressure rho0 g (H_s - z) within 2 % at mid-depth (inside the finest band),
// keep its mass to round-off and come to rest. `--refine off` runs the same tank without the boxes.
// Writes <output>/probe.csv (error, kinetic energy, mass and counts over time), <output>/profile.csv (p(z) on the
// centre line at the end) and <output>/particles.csv (the final particles: x, z, level, pressure).
// docs/variable-resolution.md section 3 gives the results.
#include "refined_tank_scene.hpp"

#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>

#include <chrono>
#include <filesystem>

using namespace sphfsi;
using namespace sphfsi::examples;
using namespace sphfsi::examples::refined_tank;

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "refined_tank: still water in a 2D tank with a refined band (levels dp, dp/2, dp/4) at "
                      "mid-depth; checks p = rho0 g (H_s - z) within 2 % in the band and the mass.");
  RefinedTankConfig cfg;
  cfg.tank.particles_over_depth = static_cast<int>(cli.get_number("resolution", 20, "base particles over depth"));
  cfg.tank.width = cli.get_number("width", 0.3, "tank width, m");
  cfg.level1_rows = static_cast<int>(cli.get_number("level1-rows", cfg.level1_rows, "base rows of the level-1 box"));
  cfg.level2_rows = static_cast<int>(cli.get_number("level2-rows", cfg.level2_rows, "base rows of the level-2 box"));
  cfg.buffer_rows = cli.get_number("buffer", cfg.buffer_rows, "merge buffer width, base spacings");
  cfg.tank.smoothing_ratio = cli.get_number("smoothing-ratio", cfg.tank.smoothing_ratio, "h / spacing");
  cfg.wall_columns =
      static_cast<int>(cli.get_number("wall-columns", cfg.wall_columns, "coarse base columns next to each side wall"));
  const double end_time = cli.get_number("end-time", 1.0, "simulated time, s (settling)");
  const bool refine = cli.get_switch("refine", true, "refinement boxes: on | off (the uniform tank)");
  const std::string correction = cli.get("gradient-correction", "jumps",
                                         "pressure gradient: jumps (corrected difference form at resolution jumps) | "
                                         "none (symmetric) | everywhere (Bonet-Lok everywhere)");
  const double alpha = cli.get_number("alpha", 0.1, "artificial viscosity alpha");
  const std::filesystem::path output = cli.get("output", "refined_tank_output", "output folder");
  if (!cli.finish()) return 0;
  require_positive("--end-time (s)", end_time);
  if (correction != "jumps" && correction != "none" && correction != "everywhere")
    throw InputError(
        fmt::format("--gradient-correction = '{}' is invalid: valid values are jumps, none, everywhere", correction));

  System system = tank::make_tank(cfg.tank);
  auto boxes = refine ? refinement_boxes(cfg) : std::vector<RefinementBox<2, double>>{};
  auto fluid = tank::fluid_parameters(cfg.tank);
  fluid.artificial_viscosity = alpha;
  if (correction == "everywhere") fluid.gradient_correction = GradientCorrection::everywhere;
  if (correction == "jumps") fluid.gradient_correction = GradientCorrection::resolution_jumps;
  RefinedSimulation sim(system, fluid, {}, Refinement(system.domain(), boxes, refinement_parameters(cfg)));
  const auto& refinement = sim.model<0>();
  const double mass0 = fluid_mass(system);
  const Vector probe(0.5 * cfg.tank.width, cfg.band_centre());
  fmt::print("refined tank: H = {} m, L = {} m, dp = {:.4g} m, refinement {}, {} fluid + {} wall particles\n",
             cfg.tank.depth, cfg.tank.width, cfg.tank.dp(), refine ? "on" : "off",
             system.particles().count(Kind::fluid), system.particles().count(Kind::wall));

  io::CsvWriter probe_csv(output / "probe.csv",
                          {"t", "relative_error", "kinetic_energy", "max_speed", "mass_change", "level0", "level1",
                           "level2", "splits", "merges"},
                          fmt::format("refined tank ({}), probe at x = {} m, z = {} m; relative_error of the Shepard "
                                      "pressure against rho0 g (H_s - z); mass_change relative to t = 0",
                                      refine ? "on" : "off", probe[0], probe[1]));
  double next_sample = 0;
  auto sample = [&](RefinedSimulation& s) {
    if (s.time() < next_sample - 1e-12) return;
    next_sample += 0.01;
    const double surface = tank::free_surface_height(system, cfg.tank);
    const double p_th = tank::hydrostatic_pressure(cfg.tank, surface, probe[1]);
    const auto levels = particles_per_level(system, refinement);
    probe_csv.write_row({s.time(), (tank::shepard_pressure(system, probe) - p_th) / p_th,
                         tank::fluid_kinetic_energy(system), tank::max_fluid_speed(system),
                         (fluid_mass(system) - mass0) / mass0, double(levels[0]), double(levels[1]), double(levels[2]),
                         double(refinement.total_counts().splits), double(refinement.total_counts().merges)});
  };
  const auto start = std::chrono::steady_clock::now();
  sample(sim);
  sim.run(end_time, sample);
  const double wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const double surface = tank::free_surface_height(system, cfg.tank);
  io::CsvWriter profile_csv(
      output / "profile.csv", {"z", "p_sph", "p_theory"},
      fmt::format("pressure at x = {} m, t = {} s; surface H_s = {} m", probe[0], sim.time(), surface));
  for (double z = 0.125 * cfg.tank.dp(); z < surface; z += 0.125 * cfg.tank.dp())
    profile_csv.write_row(
        {z, tank::shepard_pressure(system, Vector(probe[0], z)), tank::hydrostatic_pressure(cfg.tank, surface, z)});
  {
    io::CsvWriter particles_csv(output / "particles.csv", {"x", "z", "level", "pressure", "speed"},
                                fmt::format("fluid particles at t = {} s", sim.time()));
    const auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid)
        particles_csv.write_row({p.position[i][0], p.position[i][1],
                                 refinement.halvings(p.mass[i], system.eos().reference_density()) / 2.0, p.pressure[i],
                                 p.velocity[i].norm()});
  }
  const double p_th = tank::hydrostatic_pressure(cfg.tank, surface, probe[1]);
  const double error = (tank::shepard_pressure(system, probe) - p_th) / p_th;
  const auto levels = particles_per_level(system, refinement);
  fmt::print("t = {:.3f} s after {} steps; particles per level {} / {} / {}; {} splits, {} merges\n", sim.time(),
             sim.step_count(), levels[0], levels[1], levels[2], refinement.total_counts().splits,
             refinement.total_counts().merges);
  fmt::print("mid-depth pressure error {:+.3f} %, kinetic energy {:.3e} J/m, max speed {:.3e} m/s\n", 100 * error,
             tank::fluid_kinetic_energy(system), tank::max_fluid_speed(system));
  for (const double zf : {0.2, 0.4, 0.6, 0.8}) {
    const double z = zf * cfg.tank.depth;
    const auto band = tank::band_average_pressure(system, cfg.tank, z, 0.5 * cfg.tank.dp());
    const double th = tank::hydrostatic_pressure(cfg.tank, surface, band.elevation);
    fmt::print("  band z = {:.3f} m ({} particles): error {:+.3f} %\n", band.elevation, band.particles,
               100 * (band.pressure - th) / th);
  }
  fmt::print("mass change {:.3e} (relative), particles lost {}\n", (fluid_mass(system) - mass0) / mass0,
             tank::particles_outside(system, cfg.tank));
  fmt::print("wall time {:.2f} s\n", wall_time);
  return std::abs(error) <= 0.02 ? 0 : 1;
} catch (const std::exception& e) {
  fmt::print(stderr, "refined_tank: {}\n", e.what());
  return 2;
}
