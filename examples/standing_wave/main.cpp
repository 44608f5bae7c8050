// sphfsi example: a standing wave in a closed 2D tank, the flume's numerics without paddle and absorber.
//
// A tank one wavelength L long with still-water depth h holds the standing wave eta = a cos(k x) cos(omega t),
// k = 2 pi / L (the second sloshing mode of a tank of length L), released from rest with its surface displaced and
// hydrostatic pressure under the displaced surface. Linear theory: omega^2 = g k tanh(k h) and, in an inviscid
// fluid, no decay; a fluid of kinematic viscosity nu loses amplitude at the rate gamma = 2 nu k^2 (Lamb 1932,
// Hydrodynamics, art. 348; free-slip walls). The SPH wave's period and its amplitude decay rate gamma, fitted to the
// crests and troughs at the antinode x = L / 2, measure the scheme's own dissipation; the decay a progressive wave
// of the same k would suffer per wavelength of travel is 1 - exp(-gamma L / c_g). The defaults are the wave of
// examples/wave_flume (h = 0.16 m, T = 1.4286 s: L = 1.695 m, H = 2a = 0.028 m) with its scheme (Wendland C2,
// h_sph = 2 dp, c0 = 7 sqrt(g h), alpha = 0.01 between fluid particles, delta-SPH 0.1, dynamic walls), so that a
// sweep over the flags separates the causes of the flume's wave loss (docs/flume.md).
#include <sphfsi/analysis/line_fit.hpp>
#include <sphfsi/analysis/zero_crossing.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/io/progress.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/waves/gauges.hpp>
#include <sphfsi/waves/linear_theory.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <vector>

using namespace sphfsi;
using T = double;
using V = Vec<2, T>;

/// Least-squares fit of ln|extreme| = ln a0 - gamma t to the crests and troughs of eta(t) (local extremes of |eta|
/// between zero crossings). Returns {a0, gamma, number of extremes}.
struct EnvelopeFit {
  double amplitude{0}, decay_rate{0};
  std::size_t extremes{0};
};

EnvelopeFit fit_envelope(const std::vector<double>& t, const std::vector<double>& eta) {
  std::vector<double> te, ln_a;
  std::size_t start = 0;
  for (std::size_t i = 1; i <= eta.size(); ++i) {
    const bool crossing = i == eta.size() || (eta[i] > 0) != (eta[i - 1] > 0);
    if (!crossing) continue;
    if (i - start >= 3) {  // one half-wave: its extreme, refined by a parabola through the three samples around it
      std::size_t k = start;
      for (std::size_t j = start; j < i; ++j)
        if (std::abs(eta[j]) > std::abs(eta[k])) k = j;
      double tk = t[k], ak = std::abs(eta[k]);
      if (k > start && k + 1 < i) {
        const double y0 = std::abs(eta[k - 1]), y1 = ak, y2 = std::abs(eta[k + 1]);
        const double den = y0 - 2 * y1 + y2;
        if (den < 0) {
          const double s = 0.5 * (y0 - y2) / den;
          ak = y1 - 0.25 * (y0 - y2) * s;
          tk = t[k] + s * (t[k + 1] - t[k]);
        }
      }
      if (start > 0) {  // the first half-wave starts at t = 0 and is not a full one
        te.push_back(tk);
        ln_a.push_back(std::log(ak));
      }
    }
    start = i;
  }
  EnvelopeFit fit;
  fit.extremes = te.size();
  if (te.size() < 3) throw InputError("standing_wave: fewer than 3 crests and troughs recorded: run longer");
  const analysis::LineFit line = analysis::fit_line(te, ln_a);
  fit.decay_rate = -line.slope;
  fit.amplitude = std::exp(line.intercept);
  return fit;
}

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "standing_wave: a standing wave in a closed 2D tank; its period against linear theory and its "
                      "amplitude decay rate (the scheme's own wave dissipation, without paddle or absorber).");
  const T depth = cli.get_number("depth", 0.16, "still-water depth h, m");
  const T period = cli.get_number("period", 1.4286, "linear-theory period of the wave T, s (sets k)");
  const T amplitude = cli.get_number("amplitude", 0.014, "initial amplitude a at the antinodes, m");
  const T per_depth = cli.get_number("resolution", 16, "particles over the depth, h/dp");
  const T smoothing = cli.get_number("smoothing", 2.0, "h_sph / dp (the wave flume's)");
  const T c_factor = cli.get_number("sound-speed", 7, "c0 / sqrt(g h)");
  const T periods = cli.get_number("periods", 8, "simulated time, periods");
  FluidParameters<2, T> fluid;
  fluid.artificial_viscosity = cli.get_number("alpha", 0.01, "artificial viscosity alpha");
  fluid.density_diffusion = cli.get_number("delta", 0.1, "delta-SPH coefficient");
  fluid.kinematic_viscosity = cli.get_number("viscosity", 0, "laminar kinematic viscosity nu, m^2/s");
  fluid.wall_artificial_viscosity =
      cli.get_switch("wall-viscosity", false, "artificial viscosity between fluid and wall particles: on | off");
  fluid.xsph = cli.get_number("xsph", fluid.xsph, "XSPH coefficient epsilon");
  const double max_period_error =
      cli.get_number("period-tolerance", 0, "pass: |period / linear theory - 1| at most this (0: no check)");
  const double max_loss =
      cli.get_number("loss-tolerance", 0, "pass: amplitude loss per period at most this (0: no check)");
  const std::string start_mode = cli.get("start", "velocity", "initial state: velocity | elevation");
  const std::filesystem::path out = cli.get("output", "out/standing_wave", "output folder");
  const std::string kernel_name = cli.get("kernel", "wendland", "smoothing kernel: wendland (C2) | cubic (B-spline)");
  if (!cli.finish()) return 0;
  if (kernel_name != "wendland" && kernel_name != "cubic")
    throw InputError(fmt::format("--kernel '{}': valid are wendland, cubic", kernel_name));
  require_in_range("--amplitude / depth", amplitude / depth, T(0), T(0.5));
  // The scene and its analysis, for the kernel chosen at run time.
  auto run = [&]<class Kernel>() -> int {
    using System = ParticleSystem<2, T, Kernel, Tait<T>>;
    using Solver = Simulation<System, SymplecticVerlet>;
    const T g = 9.81;
    fluid.gravity = V(0, -g);
    fluid.walls = WallModel::dynamic;

    const auto wave = waves::linear_wave(period, depth, g);
    const T L = wave.wavelength, k = wave.wave_number, dp = depth / per_depth;
    const Resolution<T> res{dp, smoothing};
    const T c0 = c_factor * std::sqrt(g * depth), rho0 = 1000;
    const T layers = 3 * dp;
    System system(Domain<2, T>(V(-layers - 5 * dp, -layers - 5 * dp), V(L + layers + 5 * dp, 3 * depth)),
                  Tait<T>(rho0, c0));
    const Tait<T>& eos = system.eos();
    // Release: "velocity" starts a quarter period in, with a flat surface and linear theory's velocity field
    // u = a omega cosh(k z) / sinh(k h) sin(k x), w = -a omega sinh(k z) / sinh(k h) cos(k x) (then eta = -a cos(k x)
    // sin(omega t)); "elevation" starts from rest with the surface a cos(k x), which a particle lattice can only
    // represent as a staircase of rows (it excites other modes when a is not many dp).
    const bool from_elevation = start_mode == "elevation";
    if (!from_elevation && start_mode != "velocity")
      throw InputError(fmt::format("--start '{}': valid are velocity, elevation", start_mode));
    const T omega = wave.angular_frequency, s_kh = std::sinh(wave.kh());
    auto surface = [&](T x) { return depth + (from_elevation ? amplitude * std::cos(k * x) : T(0)); };
    std::size_t fluid_count = 0;
    for_each_lattice_point<2, T>(V(0, 0), V(L, depth + amplitude), dp, [&](const V& x) {
      if (x[1] >= surface(x[0])) return;
      const T rho = eos.density(rho0 * g * (surface(x[0]) - x[1]));
      const V v = from_elevation ? V::Zero()
                                 : V(amplitude * omega * std::cosh(k * x[1]) / s_kh * std::sin(k * x[0]),
                                     -amplitude * omega * std::sinh(k * x[1]) / s_kh * std::cos(k * x[0]));
      system.particles().add(Kind::fluid, x, v, rho, rho0 * dp * dp, res.h());
      ++fluid_count;
    });
    const std::size_t wall_count = add_box_walls(system, V(0, 0), V(L, 2 * depth), res, WallModel::dynamic);
    set_hydrostatic_wall_density(system, depth, g);
    Solver sim(system, fluid);
    sim.set_expected_flow_speed(amplitude * wave.angular_frequency / std::tanh(wave.kh()));

    const T end_time = periods * period;
    const T nu_art = fluid.artificial_viscosity * res.h() * c0 / 8;  // 2D: alpha h c0 / (2 (d + 2))
    fmt::print(
        "standing wave: h = {} m, L = {:.4f} m, kh = {:.3f}, a = {} m, T_linear = {:.4f} s; h/dp = {}, H/dp = {:.2f}, "
        "{} fluid + {} wall particles; c0 = {:.2f} m/s, alpha = {} (walls {}), delta = {}, nu = {} m^2/s, xsph = {}\n",
        depth, L, wave.kh(), amplitude, period, per_depth, 2 * amplitude / dp, fluid_count, wall_count, c0,
        fluid.artificial_viscosity, fluid.wall_artificial_viscosity ? "on" : "off", fluid.density_diffusion,
        fluid.kinematic_viscosity, fluid.xsph);

    std::filesystem::create_directories(out);
    const std::vector<T> gauge_x{L / 2, L / 4, 3 * dp};
    waves::WaveGauges<T> gauges(gauge_x, depth, dp);
    gauges.open(
        out / "gauges.csv",
        fmt::format("standing_wave: eta (m) at x (m) = column suffix; L = {:.5g} m, h = {} m, a = {} m, h/dp = {}", L,
                    depth, amplitude, per_depth));
    io::ProgressReporter progress(end_time);
    const T sample_every = period / 80;
    T next_sample = 0;
    const auto start = std::chrono::steady_clock::now();
    gauges.sample(system, T(0));
    sim.run(end_time, [&](Solver& s) {
      progress(s);
      if (s.time() >= next_sample) {
        gauges.sample(s.system(), s.time());
        next_sample += sample_every;
      }
    });
    progress.finish(sim);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    const std::vector<double> t(gauges.times().begin(), gauges.times().end());
    const std::vector<double> eta(gauges.series(0).begin(), gauges.series(0).end());
    const EnvelopeFit fit = fit_envelope(t, eta);
    const auto waves_seen = analysis::zero_crossing_analysis(t, eta, 0.5 * double(period), double(end_time));
    const double per_period = 1 - std::exp(-fit.decay_rate * double(period));
    const double per_wavelength = 1 - std::exp(-fit.decay_rate * double(L / wave.group_velocity));
    const double gamma_art = 2 * double(nu_art) * double(k * k),
                 gamma_lam = 2 * double(fluid.kinematic_viscosity * k * k);
    fmt::print("{} steps, {:.1f} s wall\n", sim.step_count(), wall);
    fmt::print("period {:.4f} s ({:+.2f} % of linear theory), {} waves\n", waves_seen.mean_period,
               100 * (waves_seen.mean_period / double(period) - 1), waves_seen.count());
    fmt::print("amplitude: fitted a0 = {:.5f} m ({:.3f} a), decay rate gamma = {:.4f} 1/s from {} crests and troughs\n",
               fit.amplitude, fit.amplitude / double(amplitude), fit.decay_rate, fit.extremes);
    fmt::print("  loss {:.2f} % per period; a progressive wave would lose {:.2f} % per wavelength travelled\n",
               100 * per_period, 100 * per_wavelength);
    fmt::print(
        "  for comparison 2 nu k^2: artificial viscosity nu = alpha h c0 / 8 = {:.3g} m^2/s -> {:.4f} 1/s; "
        "laminar nu -> {:.4f} 1/s\n",
        double(nu_art), gamma_art, gamma_lam);
    io::CsvWriter summary(out / "summary.csv", {"h_over_dp", "alpha", "delta", "c0_factor", "period_error", "a0_over_a",
                                                "decay_rate", "loss_per_period", "loss_per_wavelength", "wall_s"});
    summary.write_row({double(per_depth), double(fluid.artificial_viscosity), double(fluid.density_diffusion),
                       double(c_factor), waves_seen.mean_period / double(period) - 1, fit.amplitude / double(amplitude),
                       fit.decay_rate, per_period, per_wavelength, wall});
    int status = 0;
    const double period_error = waves_seen.mean_period / double(period) - 1;
    if (max_period_error > 0) {
      const bool ok = std::abs(period_error) <= max_period_error;
      fmt::print("{}: period within {:.3g} % of linear theory ({:+.2f} %)\n", ok ? "PASS" : "FAIL",
                 100 * max_period_error, 100 * period_error);
      status = ok ? status : 2;
    }
    if (max_loss > 0) {
      const bool ok = per_period <= max_loss;
      fmt::print("{}: amplitude loss per period at most {:.3g} % ({:.2f} %)\n", ok ? "PASS" : "FAIL", 100 * max_loss,
                 100 * per_period);
      status = ok ? status : 2;
    }
    return status;
  };
  return kernel_name == "cubic" ? run.template operator()<CubicSpline<2>>() : run.template operator()<WendlandC2<2>>();
} catch (const std::exception& e) {
  fmt::print(stderr, "standing_wave: {}\n", e.what());
  return 1;
}
