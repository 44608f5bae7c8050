// sphfsi example: hydrostatic tank. Still water (0.5 m deep, 1 m wide) settles under gravity between dynamic
// boundary particles or Monaghan-Kos repulsive walls. After settling, the pressure at mid-depth must be within 2 %
// of rho0 g (H_s - z) (H_s: measured settled free surface, the water's SPH volume / tank width) and no fluid
// particle may leave the tank. docs/walls.md explains the choices and gives the results.
// Writes <output>/probe.csv (mid-depth pressure over time), <output>/profile.csv (p(z) vs theory at the end) and,
// when /usr/bin/python3 with matplotlib is there, <output>/hydrostatic_tank.png. Exit status 1 if a check fails.
#include "tank_scene.hpp"

#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>

#include <chrono>
#include <cstdlib>
#include <filesystem>

using namespace sphfsi;
using namespace sphfsi::examples::tank;

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "hydrostatic_tank: still water settling in a 2D tank; checks p = rho0 g (H_s - z) at mid-depth "
                      "(within 2 %) and that no particle leaves the tank.");
  TankConfig cfg;
  const std::string walls = cli.get("walls", "dynamic", "wall model: dynamic | repulsive");
  cfg.particles_over_depth = static_cast<int>(cli.get_number("resolution", 40, "particles over the water depth"));
  const double end_time = cli.get_number("end-time", 2.0, "simulated time, s (settling)");
  cfg.smoothing_ratio = cli.get_number("smoothing-ratio", cfg.smoothing_ratio, "smoothing length over spacing h/dp");
  const std::filesystem::path output = cli.get("output", "hydrostatic_tank_output", "output folder");
  cfg.depth_scaling =
      cli.get_switch("depth-scaling", true, "repulsive walls: eps(z) of eq. 22 with h0 = H, z0 = H (on | off)");
  const std::string correction = cli.get("gradient-correction", "near-walls",
                                         "kernel-gradient correction of the pressure gradient (Bonet & Lok 1999): "
                                         "none | near-walls (fluid next to repulsive walls) | everywhere");
  const std::string masses = cli.get("masses", "consistent",
                                     "particle masses: consistent (rho(z) dp^2: m / rho = dp^2) | uniform (rho0 dp^2)");
  if (!cli.finish()) return 0;
  if (masses != "consistent" && masses != "uniform")
    throw InputError(fmt::format("--masses = '{}' is invalid: valid values are consistent, uniform", masses));
  cfg.consistent_masses = masses == "consistent";
  if (correction == "none") cfg.gradient_correction = GradientCorrection::none;
  else if (correction == "near-walls") cfg.gradient_correction = GradientCorrection::near_repulsive_walls;
  else if (correction == "everywhere") cfg.gradient_correction = GradientCorrection::everywhere;
  else
    throw InputError(fmt::format(
        "--gradient-correction = '{}' is invalid: valid values are none, near-walls, everywhere", correction));
  if (walls != "dynamic" && walls != "repulsive")
    throw InputError(fmt::format("--walls = '{}' is invalid: valid values are dynamic, repulsive", walls));
  cfg.walls = walls == "dynamic" ? WallModel::dynamic : WallModel::repulsive;
  require_positive("--end-time (s)", end_time);

  System system = make_tank(cfg);
  TankSimulation sim(system, fluid_parameters(cfg));
  const Vector probe(0.5 * cfg.width, 0.5 * cfg.depth);
  fmt::print(
      "hydrostatic tank: {} walls, H = {} m, L = {} m, dp = {:.4g} m, {} fluid + {} wall particles, "
      "c0 = {:.3g} m/s, acoustic period 4H/c0 = {:.3g} s\n",
      walls, cfg.depth, cfg.width, cfg.dp(), system.particles().count(Kind::fluid),
      system.particles().count(Kind::wall), cfg.sound_speed(), cfg.acoustic_period());

  io::CsvWriter probe_csv(output / "probe.csv",
                          {"t", "p_probe", "p_theory", "relative_error", "band_error", "surface", "max_speed",
                           "kinetic_energy", "particles_lost"},
                          fmt::format("hydrostatic tank, {} walls, probe at x = {} m, z = {} m; p_theory = rho0 g "
                                      "(surface - z), surface = SPH volume / width",
                                      walls, probe[0], probe[1]));
  const double interval = 0.01;  // s between probe samples
  double next_sample = 0;
  auto sample = [&](TankSimulation& s) {
    if (s.time() < next_sample - 1e-12) return;
    next_sample += interval;
    const double surface = free_surface_height(system, cfg);
    const double p_sph = shepard_pressure(system, probe), p_th = hydrostatic_pressure(cfg, surface, probe[1]);
    const BandAverage band = band_average_pressure(system, cfg, probe[1], 0.1 * cfg.depth);
    const double band_th = hydrostatic_pressure(cfg, surface, band.elevation);
    probe_csv.write_row({s.time(), p_sph, p_th, (p_sph - p_th) / p_th, (band.pressure - band_th) / band_th, surface,
                         max_fluid_speed(system), fluid_kinetic_energy(system),
                         double(particles_outside(system, cfg))});
  };

  const auto start = std::chrono::steady_clock::now();
  sample(sim);
  sim.run(end_time, sample);
  const double wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Final state: pressure profile on the tank's centre line and the checks.
  const double surface = free_surface_height(system, cfg);
  io::CsvWriter profile_csv(
      output / "profile.csv", {"z", "p_sph", "p_theory"},
      fmt::format("pressure at x = {} m, t = {} s; surface H_s = {} m", probe[0], sim.time(), surface));
  for (double z = 0.5 * cfg.dp(); z < surface; z += 0.5 * cfg.dp())
    profile_csv.write_row({z, shepard_pressure(system, Vector(probe[0], z)), hydrostatic_pressure(cfg, surface, z)});
  const double p_sph = shepard_pressure(system, probe);
  const double error =
      (p_sph - hydrostatic_pressure(cfg, surface, probe[1])) / hydrostatic_pressure(cfg, surface, probe[1]);
  const double error_initial_h =
      (p_sph - hydrostatic_pressure(cfg, cfg.depth, probe[1])) / hydrostatic_pressure(cfg, cfg.depth, probe[1]);
  const std::size_t lost = particles_outside(system, cfg);
  fmt::print("t = {:.3f} s after {} steps ({:.1f} acoustic periods)\n", sim.time(), sim.step_count(),
             sim.time() / cfg.acoustic_period());
  fmt::print("settled surface H_s = {:.5f} m (initial H = {} m)\n", surface, cfg.depth);
  fmt::print(
      "mid-depth pressure: SPH {:.2f} Pa, rho0 g (H_s - z) = {:.2f} Pa, error {:+.3f} % "
      "(vs initial H: {:+.3f} %)\n",
      p_sph, hydrostatic_pressure(cfg, surface, probe[1]), 100 * error, 100 * error_initial_h);
  const BandAverage band = band_average_pressure(system, cfg, probe[1], 0.1 * cfg.depth);
  const double band_theory = hydrostatic_pressure(cfg, surface, band.elevation);
  fmt::print(
      "band average (|z - H/2| <= H/10, central half, {} particles): {:.2f} Pa at z = {:.4f} m, "
      "rho0 g (H_s - z) = {:.2f} Pa, error {:+.3f} %\n",
      band.particles, band.pressure, band.elevation, band_theory, 100 * (band.pressure - band_theory) / band_theory);
  fmt::print("max fluid speed {:.3e} m/s, kinetic energy {:.3e} J/m, particles lost {}\n", max_fluid_speed(system),
             fluid_kinetic_energy(system), lost);
  fmt::print("lowest fluid particle above the bed: {:.3f} dp\n", lowest_fluid_height(system, cfg) / cfg.dp());
  fmt::print("wall time {:.2f} s ({:.3g} particle-steps/s)\n", wall_time,
             double(system.size()) * double(sim.step_count()) / wall_time);

  if (std::filesystem::exists("/usr/bin/python3")) {
    const std::string cmd =
        fmt::format("/usr/bin/python3 '{}/examples/hydrostatic_tank/plot.py' '{}'", SPHFSI_SOURCE_DIR, output.string());
    if (std::system(cmd.c_str()) != 0) fmt::print("(plot skipped: plot.py failed)\n");
  }
  const bool pass = std::abs(error) <= 0.02 && lost == 0;
  fmt::print("{}: |error| {} 2 %, particles lost = {}\n", pass ? "PASS" : "FAIL", std::abs(error) <= 0.02 ? "<=" : ">",
             lost);
  return pass ? 0 : 1;
} catch (const std::exception& e) {
  fmt::print(stderr, "hydrostatic_tank: {}\n", e.what());
  return 2;
}
