// sphfsi example: the empty 2D numerical wave flume: generated wave height and its decay along the flume.
//
// Still-water depth h = 0.16 m, period T = 1.4286 s, target height H = 0.028 m: the flume and waves of Luhar,
// Infantes & Nepf (2017) case H1 (validation-cases.md sections 4-5), kh = 0.593, L = 1.695 m. A piston (or flap)
// paddle at x = 0 driven through Biesel's transfer function with a 2-period ramp, gauges one to five wavelengths
// from the paddle, a damping zone (and/or beach) at the far end. Heights come from zero up-crossing analysis of
// each gauge once the wave train there has settled (ramp time + x / c_g + 4 periods: the SPH wave train builds up
// more slowly than linear theory's, docs/flume.md). Checks: the height one wavelength from the paddle within 5 % of
// the target, and the decay along the gauges from one wavelength on below 2 % per wavelength (fit of ln H against
// x / L). No artificial viscosity by default (--alpha 0; delta-SPH 0.1 keeps the pressure smooth); when it is
// given, it acts between fluid particles only (--wall-viscosity off: no viscous Stokes layer on bed and paddle). The
// wave has Ursell number 20, so the piston is driven with Madsen's (1971) second-order signal by default (--order 2): a
// first-order signal sheds a free second harmonic whose beating with the bound one modulates H(x) by up to 9 %
// (waves/second_order.hpp). Each gauge's height is also compared with second-order theory for the paddle signal used
// (the beating included for --order 1). See docs/flume.md.
#include <sphfsi/analysis/line_fit.hpp>
#include <sphfsi/analysis/wave_reflection.hpp>
#include <sphfsi/analysis/zero_crossing.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/io/progress.hpp>
#include <sphfsi/io/vtk_writer.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/wave_flume.hpp>
#include <sphfsi/waves/gauges.hpp>
#include <sphfsi/waves/wavemaker.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

using namespace sphfsi;

struct Options {
  scenes::WaveFlumeGeometry<double> scene;
  FluidParameters<2, double> fluid;
  int gauges{5};
  double gauge_spacing{1};
  double waves_analysed{3};
  double settle_periods{4};
  double end_time{0};
  double window_from{0};
  double snapshots{0};
  double height_tolerance{0.05};
  double decay_tolerance{0.02};
  double period_tolerance{0.01};
  bool reflection{false};  // three more gauges in front of the absorber: incident and reflected waves separated
  std::filesystem::path out;
};

template <class T>
int run(const Options& o) {
  using System = ParticleSystem<2, T, WendlandC2<2>, Tait<T>>;
  using Solver = Simulation<System, SymplecticVerlet, waves::DampingZone<T>>;
  scenes::WaveFlumeGeometry<T> g;
  const auto& s = o.scene;
  g.wave = {s.wave.paddle,     T(s.wave.wave_height),  T(s.wave.period), T(s.wave.depth),
            T(s.wave.gravity), T(s.wave.ramp_periods), s.wave.order};
  g.particles_per_depth = T(s.particles_per_depth);
  g.smoothing_ratio = T(s.smoothing_ratio);
  g.sound_speed_factor = T(s.sound_speed_factor);
  g.length_wavelengths = T(s.length_wavelengths);
  g.absorber = s.absorber;
  g.damping_wavelengths = T(s.damping_wavelengths);
  g.damping_rate = T(s.damping_rate);
  g.beach_slope = T(s.beach_slope);

  System system(scenes::wave_flume_domain(g), Tait<T>(1000, g.sound_speed()));
  const auto layout = scenes::build_wave_flume(system, g);
  FluidParameters<2, T> fluid = scenes::wave_flume_fluid(g);
  fluid.artificial_viscosity = T(o.fluid.artificial_viscosity);
  fluid.density_diffusion = T(o.fluid.density_diffusion);
  fluid.kinematic_viscosity = T(o.fluid.kinematic_viscosity);
  fluid.wall_artificial_viscosity = o.fluid.wall_artificial_viscosity;
  // a damping zone with zero rate when the flume has none, so one Simulation type serves all absorbers
  waves::DampingZone<T> damping = g.damping_zone();
  if (!g.has_damping_zone()) damping.relaxation_rate = T(0);
  Solver sim(system, fluid, {}, damping);
  const waves::Wavemaker<T> maker(g.wave);
  if (g.wave.paddle == waves::PaddleType::piston)
    sim.set_wall_motion(layout.paddle_body, maker.template piston_motion<2>());
  else sim.set_wall_kinematics(layout.paddle_body, maker.template flap_kinematics<2>(layout.paddle_x, T(0)));

  const auto wave = maker.wave();
  sim.set_expected_flow_speed(wave.surface_orbital_velocity(g.wave.wave_height));  // for the c0 check
  const std::vector<T> gauge_x = scenes::wave_flume_gauges(g, o.gauges, T(o.gauge_spacing));
  const double x_last = double(gauge_x.back());
  // Reflection array (--reflection on): gauges at x_r, x_r + L / 10, x_r + L / 4 with x_r half a wavelength before
  // the absorber (the damping zone's entrance, or the beach toe), in the spacings Mansard & Funke (1980) recommend;
  // analysed once the full-amplitude wave reflected by the absorber has settled there.
  const double L = double(wave.wavelength), c_g = double(wave.group_velocity), Tw = double(wave.period);
  const double absorber_x = g.has_damping_zone() ? double(g.damping_zone().x_start) : double(g.beach_toe());
  const double x_r = absorber_x - 0.5 * L;
  const std::vector<T> array_x{T(x_r), T(x_r + 0.1 * L), T(x_r + 0.25 * L)};
  const double reflected_from = double(maker.ramp_time()) + (2 * absorber_x - x_r) / c_g + o.settle_periods * Tw;
  const double reflected_to = reflected_from + o.waves_analysed * Tw;
  double end_time = o.end_time > 0
                        ? o.end_time
                        : double(maker.ramp_time()) + x_last / c_g + (o.waves_analysed + o.settle_periods + 0.5) * Tw;
  if (o.reflection && o.end_time <= 0) end_time = std::max(end_time, reflected_to + 0.25 * Tw);
  if (o.reflection && x_r < 0.5 * L)
    throw InputError(
        fmt::format("--reflection on: the array at x = {:.3f} m is within half a wavelength of the "
                    "paddle (valid: an absorber at least one wavelength, {:.3f} m, from the paddle)",
                    x_r, L));
  fmt::print(
      "wave flume ({}): h = {:.4g} m, T = {:.5g} s, target H = {:.4g} m; kh = {:.3f}, L = {:.3f} m, c_g = {:.3f} m/s; "
      "{} "
      "stroke S = {:.4f} m, order {} (X_2 = {:.5f} m); Ursell number {:.1f} (second-order limit {:.1f})\n",
      sizeof(T) == 4 ? "float" : "double", double(g.depth()), double(g.wave.period), double(g.wave.wave_height),
      double(wave.kh()), double(wave.wavelength), double(wave.group_velocity),
      g.wave.paddle == waves::PaddleType::piston ? "piston" : "flap", double(maker.stroke()), g.wave.order,
      double(maker.second_harmonic()), double(waves::ursell_number(wave, g.wave.wave_height)),
      waves::second_order_ursell_limit<double>());
  fmt::print(
      "resolution: dp = {:.5f} m, h/dp = {:.1f}, H/dp = {:.2f}, L/dp = {:.0f}; flume {:.2f} m; {} fluid + {} "
      "wall particles; c0 = {:.2f} m/s; alpha = {:.4g} (walls: {}), delta = {:.4g}, nu = {:.3g} m^2/s; end time "
      "{:.2f} s\n",
      double(g.dp()), double(g.particles_per_depth), double(g.wave.wave_height / g.dp()),
      double(wave.wavelength / g.dp()), double(g.length()), layout.fluid_particles,
      layout.wall_particles + layout.paddle_particles + layout.beach_particles, double(g.sound_speed()),
      double(fluid.artificial_viscosity), fluid.wall_artificial_viscosity ? "on" : "off",
      double(fluid.density_diffusion), double(fluid.kinematic_viscosity), end_time);

  std::filesystem::create_directories(o.out);
  waves::WaveGauges<T> gauges(gauge_x, layout.still_level, g.dp());
  gauges.open(
      o.out / "gauges.csv",
      fmt::format("wave_flume: free-surface elevation eta (m) at x (m) = column suffix; h = {:.4g} m, T = {:.5g} s, "
                  "target H = {:.4g} m, h/dp = {:.4g}",
                  double(g.depth()), double(g.wave.period), double(g.wave.wave_height), double(g.particles_per_depth)));
  io::CsvWriter paddle_csv(o.out / "paddle.csv", {"t", "X", "dXdt"});
  waves::WaveGauges<T> array(array_x, layout.still_level, g.dp());
  if (o.reflection)
    array.open(o.out / "reflection_gauges.csv",
               fmt::format("wave_flume: reflection array, eta (m) at x (m) = column suffix; absorber from x = {:.4f} m",
                           absorber_x));
  io::VtkSeriesWriter vtk(o.out, "wave_flume");
  const double sample_every = double(g.wave.period) / 40;
  double next_sample = 0, next_snapshot = 0;
  io::ProgressReporter progress(end_time);
  const auto start = std::chrono::steady_clock::now();
  gauges.sample(system, T(0));
  if (o.reflection) array.sample(system, T(0));
  sim.run(T(end_time), [&](Solver& sm) {
    progress(sm);
    if (double(sm.time()) >= next_sample) {
      gauges.sample(sm.system(), sm.time());
      if (o.reflection) array.sample(sm.system(), sm.time());
      paddle_csv.write_row(
          {double(sm.time()), double(maker.displacement(sm.time())), double(maker.velocity(sm.time()))});
      next_sample += sample_every;
    }
    if (o.snapshots > 0 && double(sm.time()) >= next_snapshot) {
      vtk.write(sm.system().particles(), sm.time());
      next_snapshot += end_time / o.snapshots;
    }
  });
  progress.finish(sim);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("{} steps, {:.1f} s wall, {:.2f} million particle-steps/s\n", sim.step_count(), wall,
             double(system.size()) * double(sim.step_count()) / wall * 1e-6);

  // zero up-crossing heights after the full-amplitude waves have arrived at each gauge
  std::vector<double> t(gauges.times().begin(), gauges.times().end());
  io::CsvWriter heights(o.out / "wave_heights.csv",
                        {"x", "x_over_L", "H", "H_std", "H_over_target", "T", "waves", "H_theory_over_target"});
  std::vector<double> xs, log_h, log_h_error;
  double h_first = 0, t_first = 0;
  // the gauge nearest one wavelength from the paddle is the "generated height" gauge
  std::size_t first = 0;
  for (std::size_t i = 1; i < gauge_x.size(); ++i)
    if (std::abs(double(gauge_x[i]) - double(wave.wavelength)) <
        std::abs(double(gauge_x[first]) - double(wave.wavelength)))
      first = i;
  const waves::LinearWave<double> wave_d =
      waves::linear_wave(double(g.wave.period), double(g.depth()), double(g.wave.gravity));
  auto theory_height = [&](double x) {  // zero up-crossing height of second-order theory over two periods
    std::vector<double> tt, ee;
    for (int k = 0; k <= 800; ++k) {
      tt.push_back(2 * wave_d.period * k / 800.0);
      ee.push_back(waves::piston_wave_elevation(wave_d, double(g.wave.wave_height), g.wave.order == 2, x, tt.back()));
    }
    return analysis::zero_crossing_analysis(tt, ee, 0, tt.back()).heights.front();
  };
  fmt::print("gauge   x (m)   x/L   waves   H (m)    H/H_target   T (s)   H_theory/H_target\n");
  for (std::size_t i = 0; i < gauge_x.size(); ++i) {
    std::vector<double> eta(gauges.series(i).begin(), gauges.series(i).end());
    const double arrival = double(maker.ramp_time()) + double(gauge_x[i]) / double(wave.group_velocity) +
                           o.settle_periods * double(wave.period);
    const double from = o.window_from > 0 ? o.window_from : arrival;
    try {
      const auto w = analysis::zero_crossing_analysis(t, eta, from, end_time);
      const double x = double(gauge_x[i]), ratio = w.mean_height / double(g.wave.wave_height);
      const double theory = theory_height(x) / double(g.wave.wave_height);
      fmt::print("{:5d}  {:6.3f}  {:4.2f}  {:5d}  {:.5f}  {:10.4f}  {:6.4f}  {:8.4f}\n", i, x,
                 x / double(wave.wavelength), w.count(), w.mean_height, ratio, w.mean_period, theory);
      heights.write_row({x, x / double(wave.wavelength), w.mean_height, w.height_std, ratio, w.mean_period,
                         double(w.count()), theory});
      if (i == first) h_first = w.mean_height, t_first = w.mean_period;
      if (i >= first) {
        xs.push_back(x / double(wave.wavelength));
        log_h.push_back(std::log(w.mean_height));
        // standard error of ln H from the wave-to-wave scatter (waves treated as independent)
        log_h_error.push_back(w.count() > 1 ? w.height_std / (w.mean_height * std::sqrt(double(w.count()))) : 0.0);
      }
    } catch (const InputError& e) {
      fmt::print("{:5d}  {:6.3f}  no complete wave after t = {:.2f} s ({})\n", i, double(gauge_x[i]), from, e.what());
    }
  }
  // decay per wavelength from the least-squares slope of ln H against x / L, its error from the wave-to-wave scatter
  double decay = std::numeric_limits<double>::quiet_NaN(), decay_error = decay;
  if (xs.size() >= 2) {
    const analysis::LineFit fit = analysis::fit_line(xs, log_h, log_h_error);
    decay = 1 - std::exp(fit.slope);
    decay_error = std::exp(fit.slope) * fit.slope_error;
  }
  const double generated_error = h_first / double(g.wave.wave_height) - 1;
  fmt::print("generated height {:.2f} wavelengths from the paddle: {:+.1f} % of the target\n",
             double(gauge_x[first] / wave.wavelength), 100 * generated_error);
  fmt::print(
      "decay along the flume ({} gauges over {:.0f} wavelengths): {:.2f} +- {:.2f} % per wavelength (standard error "
      "from the wave-to-wave scatter at each gauge)\n",
      xs.size(), xs.empty() ? 0.0 : xs.back() - xs.front(), 100 * decay, 100 * decay_error);
  const std::string plot =
      fmt::format("/usr/bin/python3 {}/examples/wave_flume/plot.py {}", SPHFSI_SOURCE_DIR, o.out.string());
  std::fflush(stdout);
  if (std::system(plot.c_str()) != 0) fmt::print("(plot skipped: /usr/bin/python3 with matplotlib not available)\n");
  if (o.reflection) {  // Mansard & Funke (1980): incident and reflected amplitudes at the paddle's frequency
    const std::vector<double> ta(array.times().begin(), array.times().end());
    std::vector<std::vector<double>> eta(array_x.size());
    std::vector<double> xa;
    for (std::size_t i = 0; i < array_x.size(); ++i) {
      eta[i].assign(array.series(i).begin(), array.series(i).end());
      xa.push_back(double(array_x[i]));
    }
    const auto sep = analysis::separate_incident_reflected<double>(ta, eta, xa, double(wave.angular_frequency),
                                                                   double(wave.wave_number), reflected_from,
                                                                   std::min(reflected_to, ta.back()));
    fmt::print(
        "reflection (gauges at x = {:.3f}, {:.3f}, {:.3f} m, {:.2f}-{:.2f} s, Mansard & Funke 1980): incident "
        "amplitude {:.5f} m, reflected {:.5f} m, K_r = {:.3f} (fit residual {:.3f} of the incident amplitude)\n",
        xa[0], xa[1], xa[2], reflected_from, std::min(reflected_to, ta.back()), sep.incident_amplitude,
        sep.reflected_amplitude, sep.reflection_coefficient, sep.residual);
    io::CsvWriter csv(o.out / "reflection.csv",
                      {"absorber_x", "from", "to", "incident_amplitude", "reflected_amplitude", "K_r", "residual"});
    csv.write_row({absorber_x, reflected_from, std::min(reflected_to, ta.back()), sep.incident_amplitude,
                   sep.reflected_amplitude, sep.reflection_coefficient, sep.residual});
  }
  const double period_error = t_first / double(g.wave.period) - 1;
  const bool height_ok = h_first > 0 && std::abs(generated_error) <= o.height_tolerance;
  const bool period_ok = h_first > 0 && std::abs(period_error) <= o.period_tolerance;
  const bool decay_ok = xs.size() < 2 || (xs.size() == gauge_x.size() - first && decay <= o.decay_tolerance);
  fmt::print("{}: generated height within {:.3g} % of the target\n", height_ok ? "PASS" : "FAIL",
             100 * o.height_tolerance);
  fmt::print("{}: period one wavelength from the paddle within {:.3g} % of the paddle's ({:+.2f} %)\n",
             period_ok ? "PASS" : "FAIL", 100 * o.period_tolerance, 100 * period_error);
  if (xs.size() >= 2)
    fmt::print("{}: decay below {:.3g} % per wavelength\n", decay_ok ? "PASS" : "FAIL", 100 * o.decay_tolerance);
  return height_ok && period_ok && decay_ok ? 0 : 2;
}

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "wave_flume: empty 2D numerical wave flume (piston or flap paddle, damping zone or beach); "
                      "generated wave height and its decay along the flume against linear theory.");
  Options o;
  auto& g = o.scene;
  g.wave.wave_height = cli.get_number("height", 0.028, "target wave height H, m");
  g.wave.period = cli.get_number("period", 1.4286, "wave period T, s");
  g.wave.depth = cli.get_number("depth", 0.16, "still-water depth h, m");
  g.wave.ramp_periods = cli.get_number("ramp", 2, "paddle start-up ramp, periods");
  g.wave.order =
      int(cli.get_number("order", 2, "paddle signal: 1 (Biesel) | 2 (with Madsen's second-order correction)"));
  const std::string paddle = cli.get("paddle", "piston", "paddle: piston | flap");
  g.particles_per_depth = cli.get_number("resolution", 16, "particles over the depth, h/dp");
  g.smoothing_ratio =
      cli.get_number("smoothing", g.smoothing_ratio, "smoothing length over particle spacing, h_sph / dp");
  g.sound_speed_factor = cli.get_number("sound-speed", 7, "c0 / sqrt(g h)");
  // 9 L: the damping zone (the last 1.5 L) starts 2.5 L past the last gauge; at 7 L its upstream influence lowered
  // the gauge at 5 L by about 1.5 % (docs/flume.md, session 4).
  g.length_wavelengths = cli.get_number("length", 9, "flume length (paddle to end wall), wavelengths");
  const std::string absorber = cli.get("absorber", "damping", "absorber: damping | beach | both");
  g.damping_wavelengths = cli.get_number("damping-length", 1.5, "damping zone length, wavelengths");
  g.damping_rate = cli.get_number("damping-rate", 10, "damping zone relaxation rate beta, 1/s");
  g.beach_slope = cli.get_number("beach-slope", 0.1, "beach slope, rise/run");
  // alpha = 0: the artificial viscosity nu = alpha h_sph c0 / 8 takes 2 nu k^2 / c_g, about 1 % of the height per
  // wavelength at alpha = 0.01; delta-SPH alone keeps the pressure smooth (docs/flume.md, session 5).
  o.fluid.artificial_viscosity = cli.get_number("alpha", 0, "artificial viscosity alpha");
  o.fluid.density_diffusion = cli.get_number("delta", 0.1, "delta-SPH coefficient");
  o.fluid.kinematic_viscosity = cli.get_number("viscosity", 0, "laminar kinematic viscosity nu, m^2/s");
  o.fluid.wall_artificial_viscosity =
      cli.get_switch("wall-viscosity", false, "artificial viscosity between fluid and wall particles: on | off");
  o.gauges = int(cli.get_number("gauges", 5, "number of gauges, at 1, 2, ... n gauge spacings from the paddle"));
  o.gauge_spacing = cli.get_number("gauge-spacing", 1, "gauge spacing, wavelengths");
  o.waves_analysed = cli.get_number("waves", 3, "full-amplitude waves recorded at the last gauge");
  o.settle_periods =
      cli.get_number("settle", 4, "periods after the linear arrival (ramp + x / c_g) before a gauge is analysed");
  o.end_time = cli.get_number("end-time", 0, "end time, s (0: from the waves to analyse at the last gauge)");
  o.window_from = cli.get_number("window-from", 0,
                                 "analyse every gauge from this time, s (0: from the arrival of the full-amplitude "
                                 "waves, ramp + x / c_g + T, at each gauge)");
  o.snapshots = cli.get_number("snapshots", 0, "number of VTK snapshots (0: none)");
  o.height_tolerance = cli.get_number("height-tolerance", 0.05, "pass: |H(1 L) / H_target - 1| at most this");
  o.decay_tolerance = cli.get_number("decay-tolerance", 0.02, "pass: decay per wavelength at most this");
  o.period_tolerance = cli.get_number("period-tolerance", 0.01, "pass: |T(1 L) / T - 1| at most this");
  o.reflection = cli.get_switch("reflection", false,
                                "on: three gauges half a wavelength before the absorber separate the incident and "
                                "reflected waves (Mansard & Funke 1980) and give the absorber's K_r | off");
  const std::string precision = cli.get("precision", "float", "scalar type: float | double");
  o.out = cli.get("output", "out/wave_flume", "output folder");
  if (!cli.finish()) return 0;
  if (paddle != "piston" && paddle != "flap")
    throw InputError(fmt::format("--paddle '{}': valid are piston, flap", paddle));
  g.wave.paddle = paddle == "piston" ? waves::PaddleType::piston : waves::PaddleType::flap;
  if (absorber == "damping") g.absorber = scenes::FlumeAbsorber::damping_zone;
  else if (absorber == "beach") g.absorber = scenes::FlumeAbsorber::beach;
  else if (absorber == "both") g.absorber = scenes::FlumeAbsorber::both;
  else throw InputError(fmt::format("--absorber '{}': valid are damping, beach, both", absorber));
  if (precision == "float") return run<float>(o);
  if (precision == "double") return run<double>(o);
  throw InputError(fmt::format("--precision '{}': valid are float, double", precision));
} catch (const std::exception& e) {
  fmt::print(stderr, "wave_flume: error: {}\n", e.what());
  return 1;
}
