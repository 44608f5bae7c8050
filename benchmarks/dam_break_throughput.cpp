// sphfsi benchmark: particle-steps per second of the 2D dam break (examples/dam_break scene, Martin & Moyce
// square column, cubic spline, Tait, dynamic walls, symplectic integrator, delta-SPH, artificial viscosity).
//
//   bench_dam_break_throughput --resolution 90 --threads 2 --precision float --steps 300
//
// prints one CSV line: precision,threads,particles,steps,seconds,million_particle_steps_per_s,cpu_seconds,
// million_particle_steps_per_cpu_s. The run starts from the column at rest, takes `warmup` steps untimed, then
// times `steps` steps. cpu_seconds is the process CPU time of the timed steps (all threads, std::clock): on a
// machine shared with other work it stays close to the work done while the wall time also counts the time the
// threads waited for a core.
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/scenes/dam_break.hpp>

#include <fmt/format.h>

#include <chrono>
#include <ctime>

using namespace sphfsi;

template <class Scalar>
void run(Scalar resolution, int threads, int warmup, int steps) {
  using System = ParticleSystem<2, Scalar, CubicSpline<2>, Tait<Scalar>>;
  scenes::DamBreakGeometry<Scalar> scene;
  scene.particles_across = resolution;
  System system(scenes::dam_break_domain(scene), Tait<Scalar>(1000, scene.sound_speed()));
  scenes::build_dam_break(system, scene);
  Simulation<System, SymplecticVerlet> sim(system, scenes::dam_break_fluid(scene));
  set_thread_count(threads);
  for (int i = 0; i < warmup; ++i) sim.step();
  const std::clock_t cpu_start = std::clock();
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) sim.step();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  const double particle_steps = double(system.size()) * steps;
  fmt::print("{},{},{},{},{:.4f},{:.3f},{:.4f},{:.3f}\n", sizeof(Scalar) == 4 ? "float" : "double", threads,
             system.size(), steps, seconds, particle_steps / seconds * 1e-6, cpu_seconds,
             particle_steps / cpu_seconds * 1e-6);
}

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv, "bench_dam_break_throughput: particle-steps per second of the 2D dam break.");
  const double resolution = cli.get_number("resolution", 90, "particles across the column (90: ~10k particles)");
  const int threads = static_cast<int>(cli.get_number("threads", thread_count(), "OpenMP threads"));
  const std::string precision = cli.get("precision", "float", "float | double");
  const int warmup = static_cast<int>(cli.get_number("warmup", 20, "untimed steps first"));
  const int steps = static_cast<int>(cli.get_number("steps", 200, "timed steps"));
  if (!cli.finish()) return 0;
  require_in_range("--threads", threads, 1, 1024);
  require_in_range("--steps", steps, 1, 100000000);
  if (precision == "float") run<float>(float(resolution), threads, warmup, steps);
  else if (precision == "double") run<double>(resolution, threads, warmup, steps);
  else throw InputError(fmt::format("--precision = '{}' is invalid: valid values are float, double", precision));
  return 0;
} catch (const std::exception& e) {
  fmt::print(stderr, "bench_dam_break_throughput: error: {}\n", e.what());
  return 1;
}
