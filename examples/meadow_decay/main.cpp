// sphfsi example: wave decay over a model seagrass meadow (issue 5 part 6, issue 6 part 4): Luhar, Infantes & Nepf
// (2017, J. Geophys. Res. Oceans 122:3736), case H1, against the measured H/H0 along the 5 m meadow
// (shared/data/luhar2017_meadow_H1_wave_decay.csv).
//
// Flume (scenes/wave_flume.hpp): still-water depth h = 0.16 m, regular waves T = 1.4286 s, H = 0.028 m from a piston
// with Madsen's second-order signal, a damping zone behind the meadow. The meadow starts about one wavelength
// (1.7 m) from the paddle and is 5 m long. Its 2D equivalent (scenes/meadow.hpp): one full-width LDPE blade
// (t = 0.1 mm, rho = 920 kg/m^3, E = 12 EI / (b t^3) with EI = 7.5e-8 N m^2, b = 3 mm; l = 0.13 m on a 0.01 m
// sheath modelled as the rigid, clamped lowest part) every dx_b = 1 / (N b) = 0.0463 m (N = 7200 blades/m^2: the
// frontal area per bed area N b l of the real meadow), each one elastic rod with the real bending stiffness and mass
// per unit width. By default (--coupling drag) each blade exchanges its Morison drag with the fluid, which passes
// through it as the water passes between the blades of the 3D meadow (coupling/blade_drag.hpp), with the plate's
// C_D = max(10 KC^(-1/3), 1.95) of Luhar & Nepf (2016) at the incident wave's KC (--blade-cd-from-kc);
// --coupling repulsive pushes the fluid on both faces with the repulsive force instead (a 2D wall, up to the leak
// of the SPH sums through it; docs/meadow.md). The fluid spacing is dx_b / m (m particles between blades; m = 3:
// h/dp = 10.4), so every blade stands on a lattice line between two fluid columns.
//
// The same flume is run without the meadow (equal resolution): the empty flume's own decay and generation deficit
// (docs/flume.md) are divided out in the "empty-normalised" H/H0. H0 is the height at the meadow's leading edge of
// the same run. The bulk drag coefficient C_D is fitted (analysis/vegetation_drag.hpp, Dalrymple et al. 1984) to the
// simulated H(x) and, the same way, to the measurement.
//
// Output (--output DIR): DIR/{meadow,empty}/gauges.csv, wave_heights.csv; DIR/meadow/tips.csv; DIR/decay.csv
// (x, H with and without the meadow, H/H0 raw and empty-normalised, measured); DIR/summary.csv; DIR/meadow_decay.png.
#include <sphfsi/analysis/vegetation_drag.hpp>
#include <sphfsi/analysis/zero_crossing.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/io/progress.hpp>
#include <sphfsi/io/vtk_writer.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/meadow.hpp>
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
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

using namespace sphfsi;
using T = double;
using V = Vec<2, T>;
using System = ParticleSystem<2, T, WendlandC2<2>, Tait<T>>;
using RepulsiveBlades = scenes::RodBlades<System>;
using DragBlades = scenes::RodBlades<System, BladeDrag<T>>;

/// Which flume a run simulates: no meadow, or the meadow with the repulsive (impermeable) or the drag (porous)
/// blade coupling.
enum class Run { empty, repulsive, drag };

/// The experiment (Luhar et al. 2017, H1) and the model's choices.
struct Options {
  T depth = 0.16, wave_height = 0.028, period = 1.4286;  // h, H (target at the paddle), T
  T meadow_start = 1.7, meadow_length = 5.0;             // m from the paddle, m
  T blades_per_square_metre = 7200, blade_width = 3e-3;  // N, b
  T flexural_rigidity = 7.5e-8;                          // EI of one blade, N m^2
  T blade_length = 0.13, sheath = 0.01;                  // l above the sheath, sheath height, m
  T thickness = 1e-4, density = 920;                     // t, rho_s
  T particles_per_gap = 3;                               // dx_b / dp
  T gauge_spacing = 0.2, gauge_before = 0.5;             // along the meadow; one gauge this far upstream of it
  T waves_analysed = 4, end_time = 0, snapshots = 0;
  T added_mass = 1, node_spacing = 1;       // rods: m_a / (rho_w dp), ds / dp
  int load_smoothing = 2, blade_count = 0;  // 0: the meadow's length / dx_b
  // beta of the blade coupling's normal dashpot (off: it makes the 2D blades a dam, docs/meadow.md)
  T normal_damping = 0;
  bool run_meadow = true, run_empty = true, check = false;
  // Fluid pairs across a blade interact (false: the 2D full-width blades every 3 dp would otherwise be a dam that
  // holds the whole wave pressure difference; see docs/meadow.md), and the weak repulsion that stops the fluid.
  bool visibility = false;
  bool guard = true;  // impermeable blades: put back fluid that steps through one (fluid/thin_structure_guard.hpp)
  std::string repulsion = "stop";  // blade repulsion strength: stop | hydrostatic
  // blade coupling: drag (porous blades exchange their Morison drag with the fluid, coupling/blade_drag.hpp) |
  // repulsive (the repulsive force of eqs 17-23; the fluid leaks through it in the SPH sums, docs/meadow.md)
  std::string coupling = "drag";
  T blade_cd = 1.95, blade_cf = 0, added_mass_coefficient = 1;  // drag coupling: C_D, C_f, C_M
  bool rigid_blades = false;                                    // drag coupling: every node clamped
  int kc_iterations = 0;  // drag coupling: reruns with C_D from the relative motion's KC
  T expect_cd = 0;        // > 0: exit 5 unless the fitted bulk C_D is within this relative deviation of blade_cd
  std::filesystem::path out = "out/meadow_decay", empty_from, meadow_from;
};

T blade_spacing(const Options& o) { return scenes::equivalent_blade_spacing(o.blades_per_square_metre, o.blade_width); }
T particle_spacing(const Options& o) { return blade_spacing(o) / o.particles_per_gap; }

/// KC = U_m T / b of a blade-normal velocity amplitude U_m and the plate's C_D there (Luhar & Nepf 2016).
struct PlateDrag {
  T kc, drag_coefficient;
};
PlateDrag plate_drag(const Options& o, T velocity_amplitude) {
  const T kc = analysis::keulegan_carpenter_number(velocity_amplitude, o.period, o.blade_width);
  return {kc, analysis::oscillatory_plate_drag_coefficient(kc)};
}

scenes::WaveFlumeGeometry<T> flume(const Options& o) {
  scenes::WaveFlumeGeometry<T> g;
  g.wave.paddle = waves::PaddleType::piston;
  g.wave.order = 2;
  g.wave.wave_height = o.wave_height;
  g.wave.period = o.period;
  g.wave.depth = o.depth;
  g.particles_per_depth = o.depth / particle_spacing(o);
  const T L = g.wavelength();
  g.damping_wavelengths = 1;
  // damping zone from half a metre behind the meadow, one wavelength long
  g.length_wavelengths = (o.meadow_start + o.meadow_length + T(0.5)) / L + g.damping_wavelengths;
  g.absorber = scenes::FlumeAbsorber::damping_zone;
  return g;
}

/// Blade base positions: lattice lines (multiples of dp) every particles_per_gap dp from the meadow's start.
std::vector<T> blade_positions(const Options& o) {
  const T dp = particle_spacing(o), dx = blade_spacing(o);
  const auto first = std::lround(o.meadow_start / dp);
  const int n = o.blade_count > 0 ? o.blade_count : int(std::floor(o.meadow_length / dx)) + 1;
  std::vector<T> x;
  for (int i = 0; i < n; ++i) x.push_back(T(first) * dp + T(i) * dx);
  return x;
}

scenes::ThinBlade<T> blade(const Options& o) {
  scenes::ThinBlade<T> b;
  b.length = o.blade_length + o.sheath;
  b.clamped_height = o.sheath;
  b.thickness = o.thickness;
  b.density = o.density;
  b.youngs_modulus = scenes::youngs_modulus_from_rigidity(o.flexural_rigidity, o.blade_width, o.thickness);
  b.node_spacing_ratio = o.node_spacing;
  return b;
}

/// Gauges: one gauge_before upstream of the leading edge, then from the leading edge every gauge_spacing to the end
/// of the meadow (x from the paddle, m).
std::vector<T> gauge_positions(const Options& o) {
  const T x0 = blade_positions(o).front();
  std::vector<T> x{x0 - o.gauge_before};
  const T length = blade_positions(o).back() - x0;
  for (int i = 0; T(i) * o.gauge_spacing <= length + 1e-9; ++i) x.push_back(x0 + T(i) * o.gauge_spacing);
  return x;
}

struct RunResult {
  std::vector<T> height, height_std;  // per gauge
  std::size_t fluid{0}, wall{0}, solid{0}, steps{0}, sub_steps{0}, crossings{0}, put_back{0}, moved_with_blade{0};
  T wall_seconds{0}, reached{0}, max_stretch{1}, lowest_node{std::numeric_limits<T>::quiet_NaN()};
  T lowest_tip{std::numeric_limits<T>::quiet_NaN()};  // over all blades and samples, m above the bed
  std::vector<T> tip_dx_amplitude;                    // first, middle, last blade, m
  // drag coupling: amplitude sqrt(2) x RMS of the blade-normal velocity of the fluid relative to the free nodes,
  // and of the fluid's own, over every blade once its waves have arrived, m/s
  T relative_velocity_amplitude{std::numeric_limits<T>::quiet_NaN()};
  T fluid_velocity_amplitude{std::numeric_limits<T>::quiet_NaN()};
  std::string failure;
};

template <Run Kind>
RunResult run_case(const Options& o, const std::filesystem::path& dir) {
  constexpr bool WithMeadow = Kind != Run::empty;
  using Blades = std::conditional_t<Kind == Run::drag, DragBlades, RepulsiveBlades>;
  using Solver = std::conditional_t<WithMeadow, Simulation<System, SymplecticVerlet, waves::DampingZone<T>, Blades>,
                                    Simulation<System, SymplecticVerlet, waves::DampingZone<T>>>;
  const auto g = flume(o);
  const T dp = g.dp();
  System system(scenes::wave_flume_domain(g), Tait<T>(1000, g.sound_speed()));
  const auto layout = scenes::build_wave_flume(system, g);
  auto fluid = scenes::wave_flume_fluid(g);
  fluid.thin_structure_visibility = o.visibility;
  fluid.thin_structure_guard = o.guard;
  const auto bases = blade_positions(o);
  const waves::Wavemaker<T> maker(g.wave);
  const auto wave = maker.wave();
  const auto make_solver = [&]() {
    if constexpr (Kind == Run::drag) {
      scenes::DragBladeCoupling<T> how;
      how.coupling.drag_coefficient = o.blade_cd;
      how.coupling.friction_coefficient = o.blade_cf;
      how.blade_width = o.blade_width;
      how.added_mass_coefficient = o.added_mass_coefficient;
      how.rigid = o.rigid_blades;
      return Solver(system, fluid, {}, g.damping_zone(),
                    scenes::add_drag_blades(system, bases, T(0), blade(o), dp, g.smoothing_ratio * dp,
                                            layout.first_free_body, how));
    } else if constexpr (WithMeadow) {
      scenes::RodBladeCoupling<T> how;
      how.added_mass_ratio = o.added_mass;
      how.load_smoothing_passes = o.load_smoothing;
      how.coupling.normal_damping = o.normal_damping;
      if (o.repulsion == "stop") {
        how.stopping_speed = T(3) * wave.surface_orbital_velocity(g.wave.wave_height);
      } else {  // each face holds its own side's hydrostatic load, like a repulsive wall (depth factor of eq. 22)
        how.coupling.strength = repulsive_strength_for_rest_gap(o.depth, T(9.81), g.sound_speed(), g.smoothing_ratio);
        how.coupling.water_level = layout.still_level;
        how.coupling.local_depth = o.depth;
      }
      return Solver(system, fluid, {}, g.damping_zone(),
                    scenes::add_rod_blades(system, bases, T(0), blade(o), dp, g.smoothing_ratio * dp,
                                           layout.first_free_body, how));
    } else {
      return Solver(system, fluid, {}, g.damping_zone());
    }
  };
  Solver sim = make_solver();
  sim.set_wall_motion(layout.paddle_body, maker.template piston_motion<2>());
  sim.set_expected_flow_speed(wave.surface_orbital_velocity(g.wave.wave_height));

  RunResult r;
  r.fluid = system.particles().count(Kind::fluid);
  r.wall = system.particles().count(Kind::wall);
  r.solid = system.particles().count(Kind::solid);
  const auto gx = gauge_positions(o);
  const T end_time =
      o.end_time > 0 ? o.end_time
                     : maker.ramp_time() + gx.back() / wave.group_velocity + (o.waves_analysed + T(1.5)) * wave.period;
  fmt::print("--- {} ({} fluid, {} wall, {} rod nodes; end time {:.2f} s)\n",
             WithMeadow ? fmt::format("meadow of {} blades", bases.size()) : std::string("empty flume"), r.fluid,
             r.wall, r.solid, end_time);
  std::filesystem::create_directories(dir);
  waves::WaveGauges<T> gauges(gx, layout.still_level, dp);
  gauges.open(dir / "gauges.csv", fmt::format("meadow_decay ({}): eta (m) at x (m) from the paddle = column suffix",
                                              WithMeadow ? "meadow" : "empty"));
  io::CsvWriter tips(dir / "tips.csv", {"t", "dx_first", "dz_first", "dx_middle", "dz_middle", "dx_last", "dz_last"},
                     "tip displacement (m) of the first, middle and last blade");
  scenes::BladeCrossingCounter<System> crossings(T(1.5) * dp);
  std::array<std::size_t, 3> watched{0, bases.size() / 2, bases.size() - 1};
  std::array<T, 3> lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
  io::VtkSeriesWriter vtk(dir, "meadow_decay");
  const T sample_every = wave.period / 40;
  T next_sample = 0, next_snapshot = 0;
  io::ProgressReporter progress(end_time);
  const auto start = std::chrono::steady_clock::now();
  T relative_square = 0, fluid_square = 0;
  std::size_t velocity_samples = 0;
  try {
    sim.run(end_time, [&](Solver& sm) {
      progress(sm);
      // Impermeable blades every step: between samples a particle beside a tip could go round it.
      if constexpr (Kind == Run::repulsive) crossings.update(sm.system(), sm.template model<1>());
      if (sm.time() + 1e-9 >= next_sample) {
        gauges.sample(sm.system(), sm.time());
        if constexpr (WithMeadow) {
          const auto& blades = sm.template model<1>();
          std::vector<T> row{sm.time()};
          for (std::size_t k = 0; k < 3; ++k) {
            const auto& rod = blades.rod(watched[k]);
            const V d = rod.tip_position() - rod.reference_positions().back();
            row.push_back(d[0]);
            row.push_back(d[1]);
            if (sm.time() > maker.ramp_time() + bases[watched[k]] / wave.group_velocity + wave.period)
              lo[k] = std::min(lo[k], d[0]), hi[k] = std::max(hi[k], d[0]);
          }
          tips.write_row(row);
          if constexpr (Kind == Run::drag) {
            const auto& p = sm.system().particles();
            for (std::size_t b = 0; b < blades.size(); ++b) {
              if (!(sm.time() > maker.ramp_time() + bases[b] / wave.group_velocity + wave.period)) continue;
              const auto& body = blades.blade(b);
              const auto& ids = body.solid().particle_ids();
              const auto& X = body.solid().reference_positions();
              for (std::size_t k = 0; k < ids.size(); ++k) {
                if (X[k][1] <= o.sheath + T(1e-9)) continue;  // the clamped sheath
                const std::size_t s = p.slot_of_id(ids[k]);
                const V u = body.coupling().relative_velocity(sm.system(), body.solid(), k);
                const T un = u.dot(p.normal[s]), fn = (u + p.velocity[s]).dot(p.normal[s]);
                relative_square += un * un, fluid_square += fn * fn, ++velocity_samples;
              }
            }
          }
          if constexpr (Kind == Run::drag) crossings.update(sm.system(), blades);  // porous: the water passes
          r.max_stretch = std::max(r.max_stretch, blades.max_stretch());
          const T low = blades.lowest_free_node(T(0), o.sheath);
          r.lowest_node = std::isnan(r.lowest_node) ? low : std::min(r.lowest_node, low);
          const T tip = blades.lowest_tip(T(0));
          r.lowest_tip = std::isnan(r.lowest_tip) ? tip : std::min(r.lowest_tip, tip);
        }
        next_sample += sample_every;
      }
      if (o.snapshots > 0 && sm.time() + 1e-9 >= next_snapshot) {
        vtk.write(sm.system().particles(), sm.time());
        next_snapshot += end_time / o.snapshots;
      }
    });
  } catch (const BlowUpError& e) {
    r.failure = e.what();
    fmt::print(stderr, "run stopped: {}\n", r.failure);
  }
  progress.finish(sim);
  r.wall_seconds = std::chrono::duration<T>(std::chrono::steady_clock::now() - start).count();
  r.steps = sim.step_count();
  r.reached = sim.time();
  if constexpr (WithMeadow) r.sub_steps = sim.template model<1>().sub_step_total();
  r.crossings = crossings.total();
  r.put_back = sim.fluid().structure_crossings_prevented();
  r.moved_with_blade = sim.fluid().structure_guard().moved_with_edge();
  if (velocity_samples > 0) {
    r.relative_velocity_amplitude = std::sqrt(T(2) * relative_square / T(velocity_samples));
    r.fluid_velocity_amplitude = std::sqrt(T(2) * fluid_square / T(velocity_samples));
  }
  for (std::size_t k = 0; k < 3; ++k) r.tip_dx_amplitude.push_back(hi[k] > lo[k] ? T(0.5) * (hi[k] - lo[k]) : T(0));
  fmt::print("{} steps to t = {:.2f} s, {:.1f} s wall\n", r.steps, r.reached, r.wall_seconds);

  const std::vector<double> t(gauges.times().begin(), gauges.times().end());
  io::CsvWriter heights(dir / "wave_heights.csv", {"x", "H", "H_std", "T", "waves"});
  for (std::size_t i = 0; i < gx.size(); ++i) {
    const std::vector<double> eta(gauges.series(i).begin(), gauges.series(i).end());
    const T from = maker.ramp_time() + gx[i] / wave.group_velocity + wave.period;
    T H = std::numeric_limits<T>::quiet_NaN(), s = H, period = H, n = 0;
    try {
      const auto w = analysis::zero_crossing_analysis(t, eta, from, r.reached);
      H = w.mean_height, s = w.height_std, period = w.mean_period, n = T(w.count());
    } catch (const InputError&) {
      fmt::print("gauge x = {:.3f} m: no complete wave after t = {:.2f} s\n", gx[i], from);
    }
    r.height.push_back(H), r.height_std.push_back(s);
    heights.write_row({gx[i], H, s, period, n});
  }
  return r;
}

/// Linear interpolation of (x, y) at xi (x increasing); NaN outside.
T interpolate(const std::vector<T>& x, const std::vector<T>& y, T xi) {
  for (std::size_t i = 0; i + 1 < x.size(); ++i)
    if (xi >= x[i] - 1e-12 && xi <= x[i + 1] + 1e-12) return y[i] + (y[i + 1] - y[i]) * (xi - x[i]) / (x[i + 1] - x[i]);
  return std::numeric_limits<T>::quiet_NaN();
}

/// C_D of Dalrymple et al. fitted to heights H(x) (x from the leading edge), with its standard error; H0 fitted,
/// or fixed when given.
analysis::DragCoefficient fitted_drag(const Options& o, const std::vector<T>& x, const std::vector<T>& H,
                                      std::optional<T> fixed_h0 = std::nullopt) {
  const auto fit = analysis::fit_decay(x, H, fixed_h0);
  const analysis::StemField stems{o.blade_length + o.sheath, o.blade_width, o.blades_per_square_metre};
  const auto wave = waves::linear_wave(o.period, o.depth);
  return analysis::drag_coefficient(fit, stems, wave.wave_number, o.depth);
}

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "meadow_decay: waves over the 5 m model meadow of Luhar et al. (2017, case H1) with real thin "
                      "blades; H/H0 along the meadow against the measurement and the bulk drag coefficient.");
  Options o;
  o.particles_per_gap = cli.get_number("resolution", 3, "fluid particles between neighbouring blades (3: h/dp = 10.4)");
  o.meadow_length = cli.get_number("meadow-length", 5, "meadow length, m");
  o.blade_count = int(cli.get_number("blades", 0, "number of blades (0: from the meadow length)"));
  o.meadow_start = cli.get_number("meadow-start", 1.7, "leading edge of the meadow from the paddle, m");
  o.gauge_spacing = cli.get_number("gauge-spacing", 0.2, "gauge spacing along the meadow, m");
  o.waves_analysed = cli.get_number("waves", 4, "full-amplitude waves recorded at the last gauge");
  o.end_time = cli.get_number("end-time", 0, "end time, s (0: from the waves to analyse at the last gauge)");
  o.snapshots = cli.get_number("snapshots", 0, "VTK snapshots per run (0: none)");
  o.added_mass = cli.get_number("added-mass", 1, "rod added inertia per length and width / (rho_w dp)");
  o.node_spacing = cli.get_number("rod-spacing", 1, "rod node spacing / dp");
  o.load_smoothing = int(cli.get_number("load-smoothing", 2, "passes of the load filter along each blade"));
  o.normal_damping = cli.get_number(
      "normal-damping", 0,
      "beta of the blade coupling's normal dashpot (rate beta c0 / h), 0-1 (0.5: the blades are impermeable)");
  o.flexural_rigidity = cli.get_number("rigidity", 7.5e-8, "flexural rigidity EI of one blade, N m^2");
  const std::string runs = cli.get("runs", "both", "runs: both | meadow | empty");
  o.visibility =
      cli.get_switch("visibility", false,
                     "on: fluid pairs across a blade do not interact (visibility criterion; a 2D blade is "
                     "then a full-width wall) | off: they do, the blade acts on the fluid by its repulsion only");
  o.guard = cli.get_switch("guard", true,
                           "impermeable blades: on: a fluid particle that steps through a blade is put back on its "
                           "face (counted) | off");
  o.repulsion = cli.get("repulsion", "stop",
                        "blade repulsion strength: stop (weakest that stops the fluid at 3 x the orbital velocity) | "
                        "hydrostatic (each face holds its side's hydrostatic load: for --visibility on)");
  o.coupling = cli.get("coupling", "drag",
                       "blade coupling: drag (porous blades exchange their Morison drag with the fluid: the 2D "
                       "stand-in for a 3D canopy) | repulsive (eqs 17-23: impermeable up to the SPH sums' leak)");
  o.blade_cd = cli.get_number("blade-cd", o.blade_cd, "drag coupling: C_D on the blade-normal relative velocity");
  const bool cd_from_kc = cli.get_switch(
      "blade-cd-from-kc", true,
      "on: C_D = max(10 KC^(-1/3), 1.95) (Luhar & Nepf 2016) with KC = U_m T / b of the incident linear wave's "
      "orbital velocity averaged over the blade height (replaces --blade-cd) | off: --blade-cd");
  o.blade_cf = cli.get_number("blade-cf", o.blade_cf, "drag coupling: C_f on the tangential relative velocity");
  o.added_mass_coefficient = cli.get_number(
      "added-mass-coefficient", o.added_mass_coefficient,
      "drag coupling: C_M of the rods' added inertia C_M rho_w pi b / 4 (--added-mass is for the repulsive one)");
  o.rigid_blades = cli.get_switch("rigid-blades", false,
                                  "drag coupling: on clamps every node (a rigid canopy: Dalrymple's formula with "
                                  "--blade-cd is the reference) | off");
  o.expect_cd = cli.get_number("expect-cd", 0,
                               "with --rigid-blades on: exit status 5 unless the fitted bulk C_D (empty-normalised, "
                               "H0 fixed) is within this relative deviation of --blade-cd (0: no check)");
  o.kc_iterations = int(cli.get_number("kc-iterations", 0,
                                       "drag coupling: rerun the meadow this many times, each with the plate-law "
                                       "C_D at the KC of the last run's velocity relative to the blades (0-10)"));
  o.check = cli.get_switch("check", false,
                           "on: exit status 4 if a blade tip fell below half its length or, with --coupling "
                           "repulsive, a fluid particle crossed a blade (regression guard)");
  o.out = cli.get("output", "out/meadow_decay", "output folder");
  o.empty_from = cli.get("empty-from", "", "with --runs meadow: take the empty flume's heights from DIR/empty");
  o.meadow_from = cli.get("meadow-from", "", "analyse DIR/meadow/wave_heights.csv of an earlier run (no meadow run)");
  if (!cli.finish()) return 0;
  require_in_range("--resolution (particles between blades)", o.particles_per_gap, T(2), T(20));
  require_in_range("--meadow-length (m)", o.meadow_length, T(0.1), T(20));
  require_in_range("--blades", o.blade_count, 0, 10000);
  require_in_range("--gauge-spacing (m)", o.gauge_spacing, T(0.02), T(2));
  if (runs != "both" && runs != "meadow" && runs != "empty")
    throw InputError(fmt::format("--runs '{}': valid are both, meadow, empty", runs));
  require_in_range("--expect-cd (relative deviation)", o.expect_cd, T(0), T(1));
  require_in_range("--kc-iterations", o.kc_iterations, 0, 10);
  if (o.kc_iterations > 0 && o.coupling != "drag")
    throw InputError("--kc-iterations needs --coupling drag (the relative velocity is the drag coupling's)");
  if (o.expect_cd > 0 && !(o.rigid_blades && o.coupling == "drag" && runs == "both"))
    throw InputError(
        "--expect-cd needs --rigid-blades on, --coupling drag and --runs both (the check compares a rigid "
        "canopy's decay, divided by the empty flume's, with its given C_D)");
  if (o.coupling != "drag" && o.coupling != "repulsive")
    throw InputError(fmt::format("--coupling '{}': valid are drag, repulsive", o.coupling));
  if (o.repulsion != "hydrostatic" && o.repulsion != "stop")
    throw InputError(fmt::format("--repulsion '{}': valid are hydrostatic, stop", o.repulsion));
  o.run_meadow = runs != "empty" && o.meadow_from.empty();
  o.run_empty = runs != "meadow" && o.empty_from.empty();

  const auto g = flume(o);
  const auto wave = waves::linear_wave(o.period, o.depth);
  if (cd_from_kc) {  // U_m: the incident wave's orbital velocity amplitude averaged over the blade height
    const T um = wave.canopy_orbital_velocity(o.wave_height, o.blade_length + o.sheath);
    const PlateDrag plate = plate_drag(o, um);
    o.blade_cd = plate.drag_coefficient;
    fmt::print("blade C_D from KC: U_m = {:.4f} m/s over the blade height, KC = {:.1f}, C_D = {:.3f}\n", um, plate.kc,
               o.blade_cd);
  }
  const auto b = blade(o);
  const auto bases = blade_positions(o);
  fmt::print(
      "meadow_decay: h = {} m, T = {} s, H = {} m (piston, second order); kh = {:.3f}, L = {:.3f} m, c_g = {:.3f} m/s\n"
      "resolution: dp = {:.5f} m (h/dp = {:.2f}, {} particles between blades); flume {:.2f} m, damping zone "
      "{:.2f} ... {:.2f} m\n"
      "meadow: {} blades every dx_b = 1 / (N b) = {:.5f} m from x = {:.4f} to {:.4f} m; blade: l = {} m on a {} m "
      "rigid sheath, t = {} m, rho = {} kg/m^3, E = 12 EI / (b t^3) = {:.4g} Pa, E t^3 / 12 = {:.4g} N m per "
      "width, {} rod nodes\n",
      o.depth, o.period, o.wave_height, wave.kh(), wave.wavelength, wave.group_velocity, g.dp(), g.particles_per_depth,
      o.particles_per_gap, g.length(), g.damping_zone().x_start, g.damping_zone().x_end, bases.size(), blade_spacing(o),
      bases.front(), bases.back(), o.blade_length, o.sheath, o.thickness, o.density, b.youngs_modulus,
      b.bending_stiffness_per_width(), b.node_count(g.dp()));

  RunResult with, without;
  if (o.run_meadow && o.coupling == "drag") {
    // --kc-iterations: rerun with the plate-law C_D of the last run's relative motion (Luhar & Nepf's KC)
    for (int it = 0;; ++it) {
      with = run_case<Run::drag>(o, o.out / "meadow");
      if (it == o.kc_iterations || !with.failure.empty() || std::isnan(with.relative_velocity_amplitude)) break;
      const PlateDrag next = plate_drag(o, with.relative_velocity_amplitude);
      fmt::print("KC iteration {}: relative velocity amplitude {:.4f} m/s, KC {:.1f}: C_D {:.3f} -> {:.3f}\n", it + 1,
                 with.relative_velocity_amplitude, next.kc, o.blade_cd, next.drag_coefficient);
      o.blade_cd = next.drag_coefficient;
    }
  } else if (o.run_meadow) {
    with = run_case<Run::repulsive>(o, o.out / "meadow");
  }
  if (o.run_empty) without = run_case<Run::empty>(o, o.out / "empty");
  const auto gx = gauge_positions(o);
  auto heights_from = [&](const std::filesystem::path& file, const char* flag) {
    const auto table = io::read_csv(file);
    const auto x = table.column("x");
    if (x.size() != gx.size() || std::abs(x.front() - gx.front()) > 1e-6 || std::abs(x.back() - gx.back()) > 1e-6)
      throw InputError(fmt::format("{} {}: its gauges ({} from {} to {} m) differ from these ({} from {} to {} m)",
                                   flag, file.string(), x.size(), x.front(), x.back(), gx.size(), gx.front(),
                                   gx.back()));
    fmt::print("heights from {}\n", file.string());
    return table.column("H");
  };
  if (!o.empty_from.empty()) without.height = heights_from(o.empty_from / "empty" / "wave_heights.csv", "--empty-from");
  if (!o.meadow_from.empty()) {
    with.height = heights_from(o.meadow_from / "meadow" / "wave_heights.csv", "--meadow-from");
    with.tip_dx_amplitude.assign(3, std::numeric_limits<T>::quiet_NaN());
  }
  const bool have_meadow = !with.height.empty(), have_empty = !without.height.empty();

  // H/H0 along the meadow: x from the leading edge, H0 = H at the leading edge gauge (index 1) of the same run
  const T x0 = bases.front();
  const T nan = std::numeric_limits<T>::quiet_NaN();
  std::vector<T> xs, ratio, ratio_empty_normalised;
  io::CsvWriter decay(o.out / "decay.csv", {"x_from_paddle", "x", "H_meadow", "H_empty", "H_over_H0",
                                            "H_over_H0_empty_normalised", "H_empty_over_H0_empty"});
  for (std::size_t i = 0; i < gx.size(); ++i) {
    const T hm = have_meadow ? with.height[i] : nan, he = have_empty ? without.height[i] : nan;
    const T r = hm / (have_meadow ? with.height[1] : nan);
    const T rn = (hm / he) / (have_meadow && have_empty ? with.height[1] / without.height[1] : nan);
    decay.write_row({gx[i], gx[i] - x0, hm, he, r, rn, he / (have_empty ? without.height[1] : nan)});
    if (i >= 1) xs.push_back(gx[i] - x0), ratio.push_back(r), ratio_empty_normalised.push_back(rn);
  }
  // against the measurement: RMS of the deviation at the measured x (simulated H/H0 interpolated between gauges)
  const auto measured =
      io::read_csv(std::filesystem::path(SPHFSI_SHARED_DATA_DIR) / "luhar2017_meadow_H1_wave_decay.csv");
  const auto mx = measured.column("x"), mh = measured.column("H_over_H0");
  T sum = 0, sum_n = 0;
  std::size_t count = 0;
  for (std::size_t k = 0; k < mx.size(); ++k) {
    const T a = interpolate(xs, ratio, mx[k]), c = interpolate(xs, ratio_empty_normalised, mx[k]);
    if (std::isnan(a)) continue;
    sum += (a - mh[k]) * (a - mh[k]), sum_n += (c - mh[k]) * (c - mh[k]), ++count;
  }
  const T rms = count ? std::sqrt(sum / T(count)) : nan, rms_n = count ? std::sqrt(sum_n / T(count)) : nan;
  fmt::print("\n x (m)   H meadow (mm)   H empty (mm)   H/H0   H/H0 empty-normalised\n");
  for (std::size_t i = 0; i < gx.size(); ++i) {
    const T hm = have_meadow ? with.height[i] : nan, he = have_empty ? without.height[i] : nan;
    fmt::print("{:6.3f}   {:13.2f}   {:12.2f}   {:5.3f}   {:5.3f}\n", gx[i] - x0, 1e3 * hm, 1e3 * he,
               hm / (have_meadow ? with.height[1] : nan),
               (hm / he) / (have_meadow && have_empty ? with.height[1] / without.height[1] : nan));
  }
  fmt::print(
      "RMS deviation of H/H0 from the measurement over x = {:.2f} ... {:.2f} m ({} points): raw {:.4f}, "
      "empty-normalised {:.4f}\n",
      mx.front(), mx.back(), count, rms, rms_n);

  // bulk drag coefficient over the measured range, simulated (raw and empty-normalised) and measured
  // H0 fitted; where that fit does not converge (a decay far from H0 / (1 + alpha x)), H0 fixed at H(0)
  analysis::DragCoefficient cd_n_fixed{nan, nan};  // empty-normalised, H0 fixed (the --expect-cd check)
  auto drag_over_measured_range = [&](const std::vector<T>& r, T h0, const char* label,
                                      analysis::DragCoefficient* fixed_out = nullptr) {
    std::vector<T> x, H;
    for (std::size_t i = 0; i < xs.size(); ++i)
      if (xs[i] <= mx.back() + 1e-9 && !std::isnan(r[i])) x.push_back(xs[i]), H.push_back(h0 * r[i]);
    analysis::DragCoefficient c{nan, nan};
    try {
      c = fitted_drag(o, x, H);
      fmt::print("  simulated, {}: C_D = {:.3f} +- {:.3f} (H0 fitted)\n", label, c.value, c.standard_error);
    } catch (const InputError& e) {
      fmt::print("  simulated, {}: no fit with H0 free ({})\n", label, e.what());
    }
    const auto fixed = fitted_drag(o, x, H, h0);
    if (fixed_out) *fixed_out = fixed;
    fmt::print("  simulated, {}: C_D = {:.3f} +- {:.3f} (H0 fixed at H(0) = {:.2f} mm)\n", label, fixed.value,
               fixed.standard_error, 1e3 * h0);
    return std::isnan(c.value) ? fixed : c;
  };
  std::vector<T> measured_H;
  for (T v : mh) measured_H.push_back(o.wave_height * v);
  const auto cd_measured = fitted_drag(o, mx, measured_H);
  const auto cd_measured_fixed = fitted_drag(o, mx, measured_H, o.wave_height * mh.front());
  fmt::print(
      "bulk drag coefficient (Dalrymple et al. 1984 fit, l_s = {} m, b_v = {} m, N = {} /m^2, standard error):\n"
      "  measured: C_D = {:.3f} +- {:.3f} (H0 fitted), {:.3f} +- {:.3f} (H0 fixed at {} m)\n",
      o.blade_length + o.sheath, o.blade_width, o.blades_per_square_metre, cd_measured.value,
      cd_measured.standard_error, cd_measured_fixed.value, cd_measured_fixed.standard_error, o.wave_height);
  analysis::DragCoefficient cd{nan, nan}, cd_n{nan, nan};
  if (have_meadow) {
    try {
      cd = drag_over_measured_range(ratio, with.height[1], "raw");
      if (have_empty)
        cd_n = drag_over_measured_range(ratio_empty_normalised, with.height[1], "empty-normalised", &cd_n_fixed);
    } catch (const InputError& e) {
      fmt::print("  simulated: no fit ({})\n", e.what());
    }
    fmt::print(
        "meadow run: {} + {} + {} particles, {} steps, {} rod sub-steps, {:.1f} s wall; max stretch {:.4f}; lowest "
        "free node {:.4f} m, lowest tip {:.4f} m above the bed; fluid particles that crossed a blade {} (put back by "
        "the guard: {}, of which {} moved with the blade); "
        "tip |dx| of the first, middle, last blade {:.1f}, {:.1f}, {:.1f} mm{}\n",
        with.fluid, with.wall, with.solid, with.steps, with.sub_steps, with.wall_seconds, with.max_stretch,
        with.lowest_node, with.lowest_tip, with.crossings, with.put_back, with.moved_with_blade,
        1e3 * with.tip_dx_amplitude[0], 1e3 * with.tip_dx_amplitude[1], 1e3 * with.tip_dx_amplitude[2],
        with.failure.empty() ? "" : "; FAILED: " + with.failure);
  }
  if (o.run_meadow && o.coupling == "drag" && !std::isnan(with.relative_velocity_amplitude)) {
    const PlateDrag relative = plate_drag(o, with.relative_velocity_amplitude);
    fmt::print(
        "blade-normal velocity amplitude at the free nodes: fluid {:.4f} m/s, fluid relative to the blade {:.4f} m/s; "
        "KC of the relative motion {:.1f}, plate-law C_D there {:.3f} (this run used {:.3f})\n",
        with.fluid_velocity_amplitude, with.relative_velocity_amplitude, relative.kc, relative.drag_coefficient,
        o.blade_cd);
  }
  if (o.run_empty)
    fmt::print("empty run: {} + {} particles, {} steps, {:.1f} s wall{}\n", without.fluid, without.wall, without.steps,
               without.wall_seconds, without.failure.empty() ? "" : "; FAILED: " + without.failure);
  io::CsvWriter summary(o.out / "summary.csv", {"dp",
                                                "blades",
                                                "rms_raw",
                                                "rms_empty_normalised",
                                                "cd_raw",
                                                "cd_raw_se",
                                                "cd_empty_normalised",
                                                "cd_empty_normalised_se",
                                                "cd_measured",
                                                "cd_measured_se",
                                                "fluid",
                                                "rod_nodes",
                                                "steps",
                                                "rod_sub_steps",
                                                "wall_s_meadow",
                                                "wall_s_empty",
                                                "crossings",
                                                "lowest_node",
                                                "max_stretch",
                                                "lowest_tip",
                                                "put_back"});
  summary.write_row({g.dp(),
                     T(bases.size()),
                     rms,
                     rms_n,
                     cd.value,
                     cd.standard_error,
                     cd_n.value,
                     cd_n.standard_error,
                     cd_measured.value,
                     cd_measured.standard_error,
                     T(with.fluid),
                     T(with.solid),
                     T(with.steps),
                     T(with.sub_steps),
                     with.wall_seconds,
                     without.wall_seconds,
                     T(with.crossings),
                     with.lowest_node,
                     with.max_stretch,
                     with.lowest_tip,
                     T(with.put_back)});
  const std::string plot =
      fmt::format("/usr/bin/python3 {}/examples/meadow_decay/plot.py {} {}/luhar2017_meadow_H1_wave_decay.csv",
                  SPHFSI_SOURCE_DIR, o.out.string(), SPHFSI_SHARED_DATA_DIR);
  std::fflush(stdout);
  if (std::system(plot.c_str()) != 0) fmt::print("(plot skipped: /usr/bin/python3 with matplotlib not available)\n");
  const bool failed = !with.failure.empty() || !without.failure.empty();
  if (failed) return 3;
  if (o.expect_cd > 0) {  // a rigid canopy must give back the C_D its drag was given
    const T deviation = std::abs(cd_n_fixed.value - o.blade_cd) / o.blade_cd;
    if (!(deviation <= o.expect_cd)) {
      fmt::print(stderr,
                 "check failed: bulk C_D {:.3f} (empty-normalised, H0 fixed) deviates {:.1f} % from the blades' "
                 "C_D = {:.3f} (valid: within {:.1f} %)\n",
                 cd_n_fixed.value, 100 * deviation, o.blade_cd, 100 * o.expect_cd);
      return 5;
    }
    fmt::print("check passed: bulk C_D {:.3f} within {:.1f} % of the blades' C_D = {:.3f} ({:.1f} %)\n",
               cd_n_fixed.value, 100 * o.expect_cd, o.blade_cd, 100 * deviation);
  }
  if (o.check && o.run_meadow) {
    const T half = T(0.5) * (o.blade_length + o.sheath);
    // porous (drag) blades let the fluid through by design: only the repulsive coupling must have no crossing
    const bool impermeable = o.coupling == "repulsive";
    if ((impermeable && with.crossings > 0) || !(with.lowest_tip >= half)) {
      fmt::print(stderr, "check failed: {} crossings (valid: {}), lowest tip {:.4f} m (valid: >= {:.4f} m)\n",
                 with.crossings, impermeable ? "0" : "any, porous blades", with.lowest_tip, half);
      return 4;
    }
    fmt::print("check passed: {}every tip above {:.4f} m\n", impermeable ? "no crossing, " : "", half);
  }
  return 0;
} catch (const std::exception& e) {
  fmt::print(stderr, "meadow_decay: error: {}\n", e.what());
  return 1;
}
