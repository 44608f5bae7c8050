// sphfsi example: a regular wave crossing a refined zone (issue 9 part 3). The flume of examples/wave_flume (piston,
// h = 0.16 m, T = 1.4286 s, target H = 0.028 m, kh = 0.593, L = 1.695 m, damping zone at the far end) at a coarse
// base resolution, with one refinement box (level 1, dp/2) over half a wavelength from two base rows above the bed
// to above the crests
// (fluid/particle_refinement.hpp: particles split where they enter it, merge beyond a buffer downstream).
// The flume has its own height deficit and decay (docs/flume.md), so the criteria compare the SAME flume run without
// the box (`--refine off`, written first; pass its output folder with `--compare`):
//   transmission: the zero up-crossing height downstream of the zone within 3 % of the uniform run's;
//   reflection: the amplitude at the wave frequency of eta_refined(t) - eta_uniform(t) at an upstream gauge (once a
//               wave reflected at the zone has arrived, over whole periods) below 2 % of the incident amplitude
//               H_uniform / 2 there; its second harmonic and the whole difference (sqrt(2) x its RMS: the spurious
//               waves the zone sends out at every frequency) are reported beside it.
// Writes <output>/gauges.csv, <output>/counts.csv (fluid particles per level, mass change, splits, merges over time)
// and, with --compare, <output>/comparison.csv. docs/variable-resolution.md section 3 gives the results.
#include <sphfsi/analysis/wave_reflection.hpp>
#include <sphfsi/analysis/zero_crossing.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/adaptive_refinement.hpp>
#include <sphfsi/fluid/particle_refinement.hpp>
#include <sphfsi/integrators/local_time_stepping.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/wave_flume.hpp>
#include <sphfsi/waves/gauges.hpp>
#include <sphfsi/waves/wavemaker.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <type_traits>
#include <utility>

using namespace sphfsi;
using T = double;
using V2 = Vec<2, T>;
using System = ParticleSystem<2, T, WendlandC2<2>, Tait<T>>;
using Refinement = ParticleRefinement<System>;
using Adaptive = AdaptiveRefinement<System>;

namespace {

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / double(v.size());
}

// Linear interpolation of (t, y) at time s (t increasing).
double interpolate(const std::vector<double>& t, const std::vector<double>& y, double s) {
  const auto it = std::lower_bound(t.begin(), t.end(), s);
  if (it == t.begin()) return y.front();
  if (it == t.end()) return y.back();
  const std::size_t k = std::size_t(it - t.begin());
  const double w = (s - t[k - 1]) / (t[k] - t[k - 1]);
  return (1 - w) * y[k - 1] + w * y[k];
}

}  // namespace

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "refined_wave: a regular wave crossing a refined zone (level 1 over half a wavelength, full "
                      "depth); run --refine off first, then --refine on --compare <that output>.");
  scenes::WaveFlumeGeometry<T> g;
  g.wave.wave_height = cli.get_number("wave-height", 0.028, "target wave height, m (1e-9: practically still water)");
  g.wave.period = 1.4286;
  g.wave.depth = 0.16;
  g.wave.order = 2;
  g.particles_per_depth = cli.get_number("resolution", 8, "base particles over the depth, h/dp");
  g.length_wavelengths = cli.get_number("length", 4.5, "flume length, wavelengths");
  g.sound_speed_factor = cli.get_number("sound-speed", 7, "c0 / sqrt(g h)");
  g.damping_wavelengths = 1.5;
  const double box_from = cli.get_number("box-from", 1.25, "refinement box start, wavelengths from the paddle");
  const double box_length = cli.get_number("box-length", 0.5, "refinement box length, wavelengths");
  const double buffer_dp = cli.get_number("buffer", 5, "merge buffer width, base spacings");
  const double upstream = cli.get_number("upstream-gauge", 0.75, "upstream gauge, wavelengths from the paddle");
  const double downstream = cli.get_number("downstream-gauge", 2.25, "downstream gauge, wavelengths");
  const double alpha = cli.get_number("alpha", 0.01, "artificial viscosity alpha (both runs)");
  const bool refine = cli.get_switch("refine", true, "refinement box: on | off (the uniform flume)");
  const std::string compare = cli.get("compare", "", "output folder of the --refine off run to compare with");
  const double settle = cli.get_number("settle", 4, "periods after the linear arrival before a gauge is analysed");
  const double waves_analysed = cli.get_number("waves", 3, "full waves analysed at the downstream gauge");
  const std::filesystem::path out = cli.get("output", "out/refined_wave", "output folder");
  const double bed_rows = cli.get_number("bed-rows", 2, "base rows kept coarse above the bed");
  const double top_rows = cli.get_number(
      "top-rows", 0, "base rows kept coarse below the still surface (0: the box reaches above the crests)");
  const bool wall_viscosity =
      cli.get_switch("wall-viscosity", false, "artificial viscosity with wall particles: on | off");
  const bool fine_bed = cli.get_switch("fine-bed", false,
                                       "bed under the box built at the fine spacing: on | off (then use --bed-rows 0)");
  const double end_override = cli.get_number("end-time", 0, "end time, s (0: from the waves to analyse)");
  const std::string method =
      cli.get("method", "split",
              "refinement method: split (splitting and merging, fluid/particle_refinement.hpp) | apr (overlapping "
              "resolutions, fluid/adaptive_refinement.hpp)");
  const double transition_dp =
      cli.get_number("transition", 4, "apr: transition zone width, base spacings (>= the fine kernel support)");
  const double bunched = cli.get_number(
      "bunched", 0.3, "apr: a passive fine particle closer than this fraction of its spacing to another is removed");
  const bool own_level = cli.get_switch(
      "own-level", true, "apr: passive particles interpolated from active ones of their own level too: on | off");
  const bool linear = cli.get_switch("linear", true, "apr: passive values by a linear MLS fit: on | off");
  const bool limit_fit = cli.get_switch("limit-fit", false,
                                        "apr: the linear fit limited to the range of its neighbours' values: on | off");
  const double hysteresis = cli.get_number("hysteresis", 0,
                                           "apr: a particle keeps its status within this distance of a box edge, base "
                                           "spacings, [0, transition - h/dp] (h/dp = 2 here)");
  const bool lagrangian = cli.get_switch(
      "lagrangian", false,
      "apr: statuses fixed at the start and carried by the particles (the fine patch moves with the water): on | off");
  const bool follow_flow = cli.get_switch(
      "follow-flow", false,
      "apr: the box moves along x with the mean velocity of the fine water in it (at most transition - h/dp base "
      "spacings): on | off");
  const bool account = cli.get_switch("account", true, "apr: the mass account: on | off");
  const bool momentum_account = cli.get_switch("momentum-account", true, "apr: the momentum account: on | off");
  const std::string account_region =
      cli.get("account-region", "edges",
              "apr: the accounts hand their changes to the active particles near the box edges "
              "(edges) or to all active fluid (all)");
  const double account_relaxation =
      cli.get_number("account-relaxation", 0,
                     "apr: relaxation time of the mass account, s (0: each pass hands back its change at once), >= 0");
  require_in_range("--account-relaxation (s)", account_relaxation, 0.0, 1e6);
  if (account_region != "edges" && account_region != "all")
    throw InputError(fmt::format("--account-region '{}': valid are edges, all", account_region));
  const bool volume_mass =
      cli.get_switch("volume-mass", true, "apr: passive masses from their SPH volume (else nominal): on | off");
  const bool shift = cli.get_switch("shift", false, "apr: particle shifting of the fine particles: on | off");
  const bool local_steps = cli.get_switch(
      "local-steps", false, "apr: local time stepping, the coarse level at twice the fine step: on | off");
  const double fine_step_margin = cli.get_number(
      "fine-step-margin", -1,
      "with --local-steps on: the coarse fluid within this distance (m) of the box's transition zone steps at the fine "
      "step too, so that the time levels meet inside the coarse fluid (< 0: at the resolution boundary)");
  const double shift_coefficient =
      cli.get_number("shift-coefficient", 2, "apr: A of the shift -A h |v| dt grad C, (0, 10]");
  const bool shift_passive =
      cli.get_switch("shift-passive", false, "apr: shift the passive fine particles too: on | off");
  const bool uniform_viscosity = cli.get_switch(
      "uniform-viscosity", false,
      "alpha applies at the base smoothing length and scales as h_base / h in the box, so the refined fluid has the "
      "unrefined flume's viscosity (nu proportional to alpha h c0): on | off");
  if (!cli.finish()) return 0;
  if (method != "split" && method != "apr")
    throw InputError(fmt::format("--method = '{}' is invalid: valid values are split, apr", method));
  const bool apr = method == "apr";

  System system(scenes::wave_flume_domain(g), Tait<T>(1000, g.sound_speed()));
  const auto layout = scenes::build_wave_flume(system, g);
  FluidParameters<2, T> fluid = scenes::wave_flume_fluid(g);
  const double L = g.wavelength(), dp = g.dp();
  // The box's ends lie on base-lattice cell edges, so the daughters tile their parents' cells.
  const double x0 = std::round(box_from * L / dp) * dp, x1 = std::round((box_from + box_length) * L / dp) * dp;
  if (fine_bed && refine) {
    // The bed under the box at the fine spacing (same thickness). split: it replaces the coarse bed there, so no fine
    // fluid particle sees a coarse wall; apr: it lies beside the coarse bed (each resolution sees only its own), over
    // the box and its transition zone.
    auto& p = system.particles();
    const double margin = apr ? transition_dp * dp : 0;
    if (!apr)
      for (std::size_t i = p.size(); i-- > 0;)
        if (p.kind[i] == Kind::wall && p.body[i] == layout.wall_body && p.position[i][1] < 0 && p.position[i][0] > x0 &&
            p.position[i][0] < x1)
          p.remove(i);
    scenes::add_fine_bed(system, g, x0 - margin, x1 + margin, 0.5 * dp);
  }
  fluid.artificial_viscosity = alpha;
  if (uniform_viscosity) fluid.viscosity_reference_smoothing_length = g.smoothing_ratio * dp;  // the base level's h
  fluid.wall_artificial_viscosity = wall_viscosity;  // off: the flume's default (docs/flume.md)
  // split: the difference form at the jump (inert without resolution jumps); apr: no pair spans a jump.
  fluid.gradient_correction = apr ? GradientCorrection::none : GradientCorrection::resolution_jumps;
  fluid.same_resolution_pairs = apr;
  std::vector<RefinementBox<2, T>> boxes;
  // From two base rows above the bed to above the crests: the bed is built at the base spacing, and fine particles
  // against a coarse dynamic wall are sucked onto it (measured: a blow-up within 0.1 s with the box down to the bed).
  // top_rows > 0: the box ends top_rows base rows below the still surface (a submerged zone); 0: above the crests.
  const double z1 = top_rows > 0 ? g.depth() - top_rows * dp : g.wall_height();
  if (refine) boxes.push_back({V2(x0, bed_rows * dp), V2(x1, z1), 1});
  RefinementParameters<T> params;
  params.base_spacing = dp;
  params.buffer_width = buffer_dp * dp;
  params.smoothing_ratio = g.smoothing_ratio;
  waves::DampingZone<T> damping = g.damping_zone();
  AdaptiveRefinementParameters<T> apr_params;
  apr_params.base_spacing = dp;
  apr_params.transition_width = transition_dp * dp;
  apr_params.smoothing_ratio = g.smoothing_ratio;
  apr_params.bunched_fraction = bunched;
  apr_params.interpolate_from_own_level = own_level;
  apr_params.linear_interpolation = linear;
  apr_params.limit_fit = limit_fit;
  apr_params.status_hysteresis = hysteresis;
  apr_params.lagrangian_statuses = lagrangian;
  apr_params.boxes_follow_flow = follow_flow;
  apr_params.conserve_mass = account;
  apr_params.conserve_momentum = momentum_account;
  apr_params.account_over_all_fluid = account_region == "all";
  apr_params.mass_account_relaxation = account_relaxation;
  apr_params.passive_mass_from_volume = volume_mass;
  apr_params.shifting.enabled = shift;
  apr_params.shifting.coefficient = shift_coefficient;
  apr_params.shifting.include_passive = shift_passive;

  // The same flume run with either refinement model.
  // The integrator: SymplecticVerlet, or LocalSymplecticVerlet (--local-steps on, apr: the coarse level at twice the
  // fine step).
  auto run = [&](auto model, auto integrator) -> int {
    constexpr bool adaptive = std::is_same_v<decltype(model), Adaptive>;
    using Solver = Simulation<System, decltype(integrator), waves::DampingZone<T>, decltype(model)>;
    Solver sim(system, fluid, {}, damping, std::move(model));
    auto& refinement = sim.template model<1>();
    if constexpr (adaptive) refinement.populate(system);
    if constexpr (Solver::local_time_stepping) {
      if (fine_step_margin >= 0 && !boxes.empty()) {  // the box and its transition zone, grown along x, all depths
        const T grow = apr_params.transition_width + T(fine_step_margin);
        const V2 lower(boxes.front().lower[0] - grow, -g.wave.depth);
        const V2 upper(boxes.front().upper[0] + grow, T(3) * g.wave.depth);
        sim.set_fine_step_regions({{lower, upper}});
        fmt::print("local steps: the fine step over x [{:.3f}, {:.3f}] m (the box, its transition and {:.3f} m)\n",
                   double(lower[0]), double(upper[0]), fine_step_margin);
      }
    }
    // A fluid particle's level, and whether it is part of the integrated fluid (apr: the active particles).
    auto level_of = [&](std::size_t i) {
      if constexpr (adaptive) return refinement.level_of(system.particles().smoothing_length[i]);
      else return refinement.halvings(system.particles().mass[i], 1000) >= 2 ? 1 : 0;
    };
    auto integrated = [&](std::size_t i) {
      const auto& p = system.particles();
      return p.kind[i] == Kind::fluid && !p.passive[i];
    };
    auto created_removed = [&]() -> std::pair<double, double> {
      if constexpr (adaptive)
        return {double(refinement.total_counts().created), double(refinement.total_counts().removed)};
      else return {double(refinement.total_counts().splits), double(refinement.total_counts().merges)};
    };
    const waves::Wavemaker<T> maker(g.wave);
    sim.set_wall_motion(layout.paddle_body, maker.piston_motion<2>());
    const auto wave = maker.wave();
    sim.set_expected_flow_speed(wave.surface_orbital_velocity(g.wave.wave_height));

    const std::vector<T> gauge_x{upstream * L, downstream * L};
    const double c_g = wave.group_velocity, period = g.wave.period;
    const double end_time = end_override > 0
                                ? end_override
                                : maker.ramp_time() + gauge_x[1] / c_g + (settle + waves_analysed + 0.5) * period;
    fmt::print(
        "refined wave (refine {}): dp = {:.4f} m (h/dp = {:.0f}, H/dp = {:.2f}), L = {:.3f} m, box [{:.3f}, {:.3f}] m "
        "(level 1, buffer {:.3f} m), gauges at {:.3f} and {:.3f} m, {} fluid + {} wall particles, alpha = {}, end "
        "{:.2f} s\n",
        refine ? "on" : "off", dp, g.particles_per_depth, g.wave.wave_height / dp, L, x0, x1, params.buffer_width,
        gauge_x[0], gauge_x[1], layout.fluid_particles, system.size() - layout.fluid_particles, alpha, end_time);

    std::filesystem::create_directories(out);
    waves::WaveGauges<T> gauges(gauge_x, layout.still_level, dp);
    gauges.open(out / "gauges.csv",
                fmt::format("refined_wave (refine {}): eta (m) at x (m) = column suffix", refine ? "on" : "off"));
    io::CsvWriter counts_csv(
        out / "counts.csv", {"t", "fluid", "level0", "level1", "mass_change", "splits", "merges", "kinetic_energy"},
        adaptive ? "fluid particles per level (active and passive), relative change of the active "
                   "mass; apr: 'splits' = children created, 'merges' = particles removed; kinetic "
                   "energy of the integrated fluid, J/m"
                 : "fluid particles per level (intermediate masses with the coarser), relative mass "
                   "change, kinetic energy of the fluid, J/m");
    auto fluid_mass = [&] {
      double m = 0;
      const auto& p = system.particles();
      for (std::size_t i = 0; i < p.size(); ++i)
        if (integrated(i)) m += p.mass[i];
      return m;
    };
    const double mass0 = fluid_mass();
    auto write_counts = [&](double t) {
      const auto& p = system.particles();
      std::size_t n = 0, level[2] = {0, 0};
      double kinetic = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kind[i] != Kind::fluid) continue;
        ++n;
        ++level[std::min(level_of(i), 1)];
        if (integrated(i)) kinetic += 0.5 * p.mass[i] * p.velocity[i].squaredNorm();
      }
      const auto [made, unmade] = created_removed();
      counts_csv.write_row(
          {t, double(n), double(level[0]), double(level[1]), (fluid_mass() - mass0) / mass0, made, unmade, kinetic});
    };
    const double sample_every = period / 80;
    double next_sample = 0, next_count = 0;
    gauges.sample(system, 0);
    write_counts(0);
    const auto start = std::chrono::steady_clock::now();
    sim.run(end_time, [&](Solver& s) {
      if (s.time() >= next_sample) {
        gauges.sample(s.system(), s.time());
        next_sample += sample_every;
      }
      if (s.time() >= next_count) {
        write_counts(s.time());
        next_count += 0.05;
      }
    });
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_counts(sim.time());
    const auto [made, unmade] = created_removed();
    fmt::print(
        "{} steps ({}), {:.4g} particle-steps, {:.1f} s wall; {} {}, {} {}; {}mass change {:.2e}; {} fluid "
        "particles at the end\n",
        sim.step_count(), decltype(integrator)::name, sim.particle_steps(), wall, made,
        adaptive ? "children created" : "splits", unmade, adaptive ? "removed" : "merges", adaptive ? "active " : "",
        (fluid_mass() - mass0) / mass0, system.particles().count(Kind::fluid));
    if constexpr (adaptive)
      fmt::print(
          "mass account: largest correction of the edge particles' masses {:.2e} (one pass); momentum account: largest "
          "velocity shift {:.2e} m/s; status changes: {} activated, {} deactivated; largest pending mass of the "
          "relaxed account {:.2e} of the active mass ({:.2e} at the end)\n",
          refinement.total_counts().mass_correction, refinement.total_counts().momentum_correction,
          refinement.total_counts().activated, refinement.total_counts().deactivated,
          refinement.total_counts().pending_mass, refinement.pending_mass() / fluid_mass());

    {
      io::CsvWriter particles_csv(out / "particles.csv", {"x", "z", "level", "pressure", "speed", "passive"},
                                  fmt::format("fluid particles at t = {} s", sim.time()));
      const auto& p = system.particles();
      for (std::size_t i = 0; i < p.size(); ++i)
        if (p.kind[i] == Kind::fluid)
          particles_csv.write_row({p.position[i][0], p.position[i][1], double(level_of(i)), p.pressure[i],
                                   p.velocity[i].norm(), double(p.passive[i])});
    }
    if (end_override > 0) return 0;
    // Heights at both gauges once the full waves have arrived.
    const std::vector<double> t(gauges.times().begin(), gauges.times().end());
    auto height = [&](const std::vector<double>& tt, const std::vector<double>& eta, std::size_t i) {
      const double from = maker.ramp_time() + gauge_x[i] / c_g + settle * period;
      return analysis::zero_crossing_analysis(tt, eta, from, end_time).mean_height;
    };
    std::vector<double> eta[2];
    for (std::size_t i = 0; i < 2; ++i) {
      eta[i].assign(gauges.series(i).begin(), gauges.series(i).end());
      fmt::print("gauge x = {:.3f} m: H = {:.5f} m ({:.3f} H_target)\n", gauge_x[i], height(t, eta[i], i),
                 height(t, eta[i], i) / g.wave.wave_height);
    }
    if (compare.empty()) return 0;

    const auto table = io::read_csv(std::filesystem::path(compare) / "gauges.csv");
    const std::vector<double> tu = table.column("t");
    std::vector<double> eu[2];
    for (std::size_t i = 0; i < 2; ++i) eu[i] = table.column(gauges.column_name(i));
    const double h_down_u = height(tu, eu[1], 1), h_down_r = height(t, eta[1], 1);
    const double transmission = h_down_r / h_down_u - 1;
    // Reflection: from the time a wave reflected at the box's upstream end reaches the upstream gauge (linear
    // group velocity, plus the settling periods) to the end; the refined record interpolated to the uniform's times.
    const double h_up_u = height(tu, eu[0], 0);
    const double reflected_from = maker.ramp_time() + (2 * x0 - gauge_x[0]) / c_g + settle * period;
    std::vector<double> diff, diff_t;
    io::CsvWriter cmp(
        out / "comparison.csv", {"t", "eta_up_uniform", "eta_up_refined", "difference"},
        fmt::format("upstream gauge x = {} m; reflected waves arrive from t = {} s", gauge_x[0], reflected_from));
    for (std::size_t k = 0; k < tu.size(); ++k) {
      if (tu[k] > sim.time()) break;
      const double er = interpolate(t, eta[0], tu[k]);
      cmp.write_row({tu[k], eu[0][k], er, er - eu[0][k]});
      if (tu[k] >= reflected_from) {
        diff.push_back(er - eu[0][k]);
        diff_t.push_back(tu[k]);
      }
    }
    double rms = 0;
    const double m = mean(diff);
    for (double d : diff) rms += (d - m) * (d - m);
    rms = diff.empty() ? 0 : std::sqrt(rms / double(diff.size()));
    const double incident = 0.5 * h_up_u;
    // The reflected wave: the difference's harmonic at the wave frequency over whole periods (a wave reflected at the
    // box has the incident wave's frequency); the second harmonic and the whole difference (the box's spurious waves
    // of every frequency) reported beside it.
    const double window_to =
        reflected_from + std::floor((diff_t.empty() ? 0 : diff_t.back() - reflected_from) / period) * period;
    auto harmonic = [&](int k) {
      return std::abs(analysis::harmonic_amplitude<double>(diff_t, diff, 2 * std::numbers::pi * k / period,
                                                           reflected_from, window_to));
    };
    const double reflected = harmonic(1), second = harmonic(2);
    const double reflection = reflected / incident;
    fmt::print("downstream H: refined {:.5f} m, uniform {:.5f} m: {:+.2f} % (criterion 3 %)\n", h_down_r, h_down_u,
               100 * transmission);
    fmt::print(
        "upstream difference eta_r - eta_u over [{:.2f}, {:.2f}] s: at the wave frequency {:.2e} m = {:.2f} % of the "
        "incident amplitude {:.5f} m (the reflection, criterion 2 %); second harmonic {:.2f} %; all frequencies "
        "(sqrt(2) RMS, the box's spurious waves included) {:.2f} %\n",
        reflected_from, window_to, reflected, 100 * reflection, incident, 100 * second / incident,
        100 * std::sqrt(2.0) * rms / incident);
    const bool pass = std::abs(transmission) <= 0.03 && reflection <= 0.02;
    fmt::print("{}\n", pass ? "PASS" : "FAIL");
    return pass ? 0 : 1;
  };
  if (apr && local_steps) return run(Adaptive(system.domain(), boxes, apr_params), LocalSymplecticVerlet{});
  if (local_steps) throw InputError("--local-steps on: only with --method apr (split and merge pair the two sizes)");
  if (fine_step_margin >= 0 && !local_steps)
    throw InputError(
        fmt::format("--fine-step-margin {}: only with --local-steps on (valid: < 0 without it)", fine_step_margin));
  if (apr) return run(Adaptive(system.domain(), boxes, apr_params), SymplecticVerlet{});
  return run(Refinement(system.domain(), boxes, params), SymplecticVerlet{});
} catch (const std::exception& e) {
  fmt::print(stderr, "refined_wave: {}\n", e.what());
  return 2;
}
