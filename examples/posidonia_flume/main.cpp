// sphfsi example: Posidonia plants in the reference paper's wave flume (issue 5 part 4; paper, Results, Fig. 8).
//
// Still-water depth h = 0.2 m, piston paddle at x = 0, one plant (or a meadow of N plants) clamped in the bed from
// x = 1.2 m, gauges at x = 0.6, 1.0, 1.3 and 1.7 m, a damping zone beyond x = 2 m (scenes/posidonia_flume.hpp).
// The plants are the real blades as elastic rods (t = 0.1 mm): porous rows of leaves that exchange their Morison
// drag with the water (--blade drag, the default: coupling/blade_drag.hpp), or full-width blades pushed on both
// faces (--blade rod; scenes/meadow.hpp); or total-Lagrangian continuum blades 3 particles thick (--blade
// scaled|equivalent),
// coupled to the fluid by the paper's retained repulsive-force coupling (eqs 17-23; for the continuum blades with
// the depth factor eps(z) referred to the still-water level). The same flume is run
// with and without plants at equal resolution (the empty flume loses 11-15 % of the height per wavelength at
// these resolutions, docs/flume.md, so the plants' effect is the difference of the two runs).
// Output (--output DIR): DIR/plants and DIR/empty with gauges.csv, wave_heights.csv, (plants) tips.csv and VTK
// snapshots; DIR/comparison.csv (H at each gauge, both runs) and DIR/posidonia_flume.png. See docs/posidonia.md.
// --refine on (drag blades, --runs plants): fine fluid (dp / 2) around the plants only, by adaptive particle
// refinement (scenes::PlantRefinement); --reference DIR compares it with a uniformly fine run in DIR
// (docs/variable-resolution.md section 4); --local-steps on steps the coarse fluid at twice the fine step.
#include <sphfsi/analysis/harmonic_fit.hpp>
#include <sphfsi/analysis/wave_reflection.hpp>
#include <sphfsi/analysis/zero_crossing.hpp>
#include <sphfsi/coupling/coupled_body.hpp>
#include <sphfsi/coupling/repulsive_force.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/adaptive_refinement.hpp>
#include <sphfsi/integrators/local_time_stepping.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/io/progress.hpp>
#include <sphfsi/io/vtk_writer.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/gate_tip_comparison.hpp>
#include <sphfsi/scenes/meadow.hpp>
#include <sphfsi/scenes/posidonia_flume.hpp>
#include <sphfsi/solid/total_lagrangian.hpp>
#include <sphfsi/waves/gauges.hpp>
#include <sphfsi/waves/wavemaker.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

using namespace sphfsi;

struct Options {
  scenes::PosidoniaFlume<double> scene;
  double alpha{0.01}, delta{0.1};
  double cfl{0.2};  // CFL number of the fluid step
  double waves_analysed{4};
  double end_time{0};
  double snapshots{0};
  double flow_map_from{-1};   // --flow-map-from: time the period-mean flow map starts averaging, s (< 0: no map)
  double flow_map_window{0};  // --flow-map-window: also a map per window of this length from flow_map_from, s (0: none)
  bool run_plants{true}, run_empty{true};
  bool check{false};  // exit 4 unless every plant sways with the water beside it and stands (see --check)
  // Rod blades: fluid pairs across a blade do not interact (fluid/thin_structure_visibility.hpp).
  bool visibility{false};
  // Rod blades: a fluid particle that steps through a blade is put back on its face (fluid/thin_structure_guard.hpp).
  bool guard{true};
  // --refine on: the coarse fluid steps at twice the fine step (integrators/local_time_stepping.hpp).
  bool local_steps{false};
  // --local-steps on: the coarse fluid within this distance (m) of the box's transition zone steps with the fine
  // level too, so that the time levels meet inside the coarse fluid (Simulation::set_fine_step_regions); < 0: none.
  double fine_step_margin{-1};
  // --uniform-viscosity on: alpha applies at the plants' smoothing length and scales as h_ref / h elsewhere, so the
  // coarse fluid has the fine fluid's viscosity (FluidParameters::viscosity_reference_smoothing_length).
  bool uniform_viscosity{false};
  // --receding-viscosity on: the artificial viscosity on receding pairs too (FluidParameters::receding_pair_viscosity).
  bool receding_viscosity{false};
  // --fluid-shift on: particle shifting of every active fluid particle (fluid/particle_shifting.hpp); refined runs:
  // of every level (AdaptiveRefinementParameters::shift_refined_only off).
  bool fluid_shift{false};
  std::filesystem::path out;
  std::filesystem::path empty_from;  // reuse DIR/empty/wave_heights.csv of an earlier run instead of the empty run
  std::filesystem::path reference;   // the uniformly fine run to compare a refined run with (DIR/plants)
};

/// What one run measured.
struct CaseResult {
  std::vector<double> height, height_std, period;  // per gauge (NaN where no complete wave)
  std::vector<double> tip_dx_amplitude, tip_dz_amplitude, tip_dx_mean, tip_dz_mean;  // per plant, m
  std::vector<double> water_dx_amplitude, water_dx_mean;  // the water beside each tip, per plant, m
  std::vector<double> tip_dz_lowest;                      // per plant, over the whole run, m
  // the periodic part of the tip's motion (4 harmonics of the wave under a quadratic drift, analysis::fit_harmonics):
  // its half peak-to-peak in x and z, and the range of the fitted drift of x over the window, per plant, m
  std::vector<double> tip_dx_periodic, tip_dz_periodic, tip_dx_drift_range;
  std::vector<double> current_mean;  // the Eulerian mean horizontal velocity at each plant's mid-height, m/s
  // incident and reflected amplitudes at the paddle's frequency from the gauges upstream of the plants, m (NaN: fewer
  // than two such gauges, or no complete record)
  double incident_amplitude{std::numeric_limits<double>::quiet_NaN()};
  double reflected_amplitude{std::numeric_limits<double>::quiet_NaN()};
  std::size_t fluid{0}, wall{0}, solid{0}, steps{0}, solid_sub_steps{0}, fluid_inside_max{0}, crossings{0}, put_back{0};
  double particle_steps{0};  // Simulation::particle_steps(): particles advanced, summed over the (sub-)steps
  double lowest_node{std::numeric_limits<double>::quiet_NaN()};  // rods: lowest free node above the bed, m
  double wall_seconds{0}, end_time{0}, reached{0}, max_stretch{1};
  std::string failure;
};

/// Horizontal fluid velocity at x, Shepard-interpolated over the fluid particles whose kernel reaches it, m/s (0 if
/// none does).
template <class System>
double eulerian_velocity(const System& system, const Vec<2, typename System::scalar_type>& x) {
  using T = typename System::scalar_type;
  const auto& p = system.particles();
  const auto& kernel = system.kernel();
  T sum_w = 0, sum_u = 0;
  for (std::size_t f = 0; f < p.size(); ++f) {
    if (p.kind[f] != Kind::fluid || p.passive[f]) continue;
    const T r = (p.position[f] - x).norm(), h = p.smoothing_length[f];
    if (r >= support_radius<typename System::kernel_type>(h)) continue;
    const T w = p.mass[f] / p.density[f] * kernel.value(r, h);
    sum_w += w, sum_u += w * p.velocity[f][0];
  }
  return sum_w > T(0) ? double(sum_u / sum_w) : 0.0;
}

/// Time-mean map of the active fluid on a grid of square bins (flow_map.csv): per bin the mean number of active and
/// passive particles of the coarse (level 0) and fine (level >= 1) resolution, the mean mass per area, the mean
/// volume fraction sum m / rho / A, the mean mass flux sum m u / (rho0 A) (a transport velocity, m/s: divergence-free
/// in a steady mean flow unless the bin holds a source of active mass), the mean kinetic energy per area, and the
/// active mass the refinement's passes created there per unit time and area, split into status changes (a particle that
/// became active with its mass, or passive) and the accounts (an active particle's mass rescaled), kg / (m^3 s).
/// Diagnoses where a refined run makes or loses water (docs/variable-resolution.md, session 34).
template <class System>
class FlowMap {
 public:
  using T = typename System::scalar_type;
  FlowMap(double x0, double x1, double z1, double bin, double rho0, double base_smoothing, double base_spacing)
      : x0_(x0),
        bin_(bin),
        rho0_(rho0),
        base_smoothing_(base_smoothing),
        base_spacing_(base_spacing),
        nx_(static_cast<std::size_t>(std::ceil((x1 - x0) / bin))),
        nz_(static_cast<std::size_t>(std::ceil(z1 / bin))),
        sums_(nx_ * nz_ * fields, 0.0) {}

  /// Every step: the active mass each particle gained since the last step (status changes and accounts), binned,
  /// from `from` on.
  void track(const System& s, double t, double from) {
    const auto& p = s.particles();
    const bool counting = t >= from && tracked_;
    for (std::size_t a = 0; a < p.size(); ++a) {
      if (p.kind[a] != Kind::fluid) continue;
      const std::size_t id = p.id[a];
      if (id >= previous_.size()) previous_.resize(id + 1, std::numeric_limits<double>::quiet_NaN());
      const double m = p.passive[a] ? 0.0 : double(p.mass[a]);
      const double before = previous_[id];
      previous_[id] = m;
      if (!counting || std::isnan(before) || m == before) continue;
      const std::size_t b = bin_of(p.position[a]);
      if (b == npos) continue;
      const bool status_change = (before == 0.0) != (m == 0.0);
      sums_[b * fields + (status_change ? status_source : account_source)] += m - before;
    }
    if (counting && last_track_ >= from) tracked_time_ += t - last_track_;
    last_track_ = t;
    tracked_ = true;
  }

  /// At each sample time from `from` on: the particles' counts, mass, volume and mass flux, binned.
  void sample(const System& s) {
    const auto& p = s.particles();
    for (std::size_t a = 0; a < p.size(); ++a) {
      if (p.kind[a] != Kind::fluid) continue;
      const std::size_t b = bin_of(p.position[a]);
      if (b == npos) continue;
      const int level = level_of(double(p.smoothing_length[a]));
      const bool fine = level > 0;
      double* c = &sums_[b * fields];
      if (p.passive[a]) {
        c[fine ? passive_fine : passive_coarse] += 1;
        continue;
      }
      c[fine ? active_fine : active_coarse] += 1;
      const double m = double(p.mass[a]);
      c[mass] += m;
      c[volume] += m / double(p.density[a]);
      c[flux_x] += m * double(p.velocity[a][0]);
      c[flux_z] += m * double(p.velocity[a][1]);
      c[kinetic_energy] += 0.5 * m * double(p.velocity[a].squaredNorm());
      if (fine) c[fine_mass_ratio] += m / nominal_mass(level);
    }
    ++samples_;
  }

  std::size_t samples() const { return samples_; }

  /// Starts a new mean: the sums and the tracked time are cleared; each particle's last active mass is kept, so the
  /// sources of the next window count from here.
  void restart() {
    std::fill(sums_.begin(), sums_.end(), 0.0);
    samples_ = 0;
    tracked_time_ = 0;
  }

  void write(const std::filesystem::path& file, double from) const {
    io::CsvWriter csv(
        file,
        {"x", "z", "active_coarse", "active_fine", "passive_coarse", "passive_fine", "mass_per_area", "volume_fraction",
         "flux_x", "flux_z", "kinetic_energy", "fine_mass_ratio", "status_source", "account_source"},
        fmt::format("time-mean map of the active fluid from t = {:.6g} s ({} samples, {:.9g} s tracked); "
                    "bins of {} m, centres x, z (m); mean particle counts per bin; mass per area "
                    "kg/m^3; flux = sum m u / (rho0 A), m/s; kinetic_energy = sum m u^2 / (2 A), J/m^3; "
                    "fine_mass_ratio: mean mass / nominal of the "
                    "active fine particles; sources: active mass created per time and area, kg/(m^3 s)",
                    from, samples_, tracked_time_, bin_));
    const double area = bin_ * bin_, n = std::max<double>(double(samples_), 1.0);
    const double duration = tracked_time_ > 0 ? tracked_time_ : 1.0;
    for (std::size_t i = 0; i < nx_; ++i)
      for (std::size_t k = 0; k < nz_; ++k) {
        const double* c = &sums_[(i * nz_ + k) * fields];
        const double fine_count = c[active_fine];
        csv.write_row({x0_ + (double(i) + 0.5) * bin_, (double(k) + 0.5) * bin_, c[active_coarse] / n,
                       c[active_fine] / n, c[passive_coarse] / n, c[passive_fine] / n, c[mass] / n / area,
                       c[volume] / n / area, c[flux_x] / n / area / rho0_, c[flux_z] / n / area / rho0_,
                       c[kinetic_energy] / n / area, fine_count > 0 ? c[fine_mass_ratio] / fine_count : 0.0,
                       c[status_source] / duration / area, c[account_source] / duration / area});
      }
  }

 private:
  enum Field : std::size_t {
    active_coarse,
    active_fine,
    passive_coarse,
    passive_fine,
    mass,
    volume,
    flux_x,
    flux_z,
    kinetic_energy,
    fine_mass_ratio,
    status_source,
    account_source,
    fields
  };
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  std::size_t bin_of(const Vec<2, T>& x) const {
    const double i = std::floor((double(x[0]) - x0_) / bin_), k = std::floor(double(x[1]) / bin_);
    if (!(i >= 0 && k >= 0 && i < double(nx_) && k < double(nz_))) return npos;
    return static_cast<std::size_t>(i) * nz_ + static_cast<std::size_t>(k);
  }
  int level_of(double h) const { return static_cast<int>(std::lround(std::log2(base_smoothing_ / h))); }
  double nominal_mass(int level) const {
    const double s = std::ldexp(base_spacing_, -level);
    return rho0_ * s * s;
  }

  double x0_, bin_, rho0_, base_smoothing_, base_spacing_;
  std::size_t nx_, nz_;
  std::vector<double> sums_;
  std::vector<double> previous_;  // active mass of each particle id at the last step (0: passive; NaN: unseen)
  std::size_t samples_{0};
  double tracked_time_{0}, last_track_{0};
  bool tracked_{false};
};

template <class T>
scenes::PosidoniaFlume<T> converted(const scenes::PosidoniaFlume<double>& s) {
  scenes::PosidoniaFlume<T> c;
  c.depth = T(s.depth), c.wave_height = T(s.wave_height), c.period = T(s.period), c.ramp_periods = T(s.ramp_periods);
  c.particles_per_depth = T(s.particles_per_depth), c.sound_speed_factor = T(s.sound_speed_factor);
  c.absorber_start = T(s.absorber_start), c.damping_wavelengths = T(s.damping_wavelengths);
  c.damping_rate = T(s.damping_rate);
  c.gauges.assign(s.gauges.begin(), s.gauges.end());
  c.plants = s.plants, c.first_plant_x = T(s.first_plant_x), c.spacing = T(s.spacing);
  c.height_ratio = T(s.height_ratio), c.blade = s.blade, c.blade_rows = s.blade_rows, c.clamp_rows = s.clamp_rows;
  c.real_density = T(s.real_density), c.real_youngs_modulus = T(s.real_youngs_modulus);
  c.real_thickness = T(s.real_thickness), c.poisson_ratio = T(s.poisson_ratio);
  c.equivalent_bulk_modulus = T(s.equivalent_bulk_modulus);
  c.rod_node_spacing = T(s.rod_node_spacing), c.rod_added_mass = T(s.rod_added_mass);
  c.rod_load_smoothing = s.rod_load_smoothing, c.rod_velocity_factor = s.rod_velocity_factor;
  c.rod_normal_damping = T(s.rod_normal_damping);
  c.rod_repulsion = T(s.rod_repulsion);
  c.leaf_width = T(s.leaf_width), c.drag_coefficient = T(s.drag_coefficient);
  c.friction_coefficient = T(s.friction_coefficient), c.added_mass_coefficient = T(s.added_mass_coefficient);
  c.frontal_fraction = T(s.frontal_fraction);
  c.refinement = {s.refinement.enabled,
                  T(s.refinement.margin),
                  T(s.refinement.top),
                  T(s.refinement.transition_spacings),
                  T(s.refinement.bunched_fraction),
                  s.refinement.shifting,
                  T(s.refinement.shift_coefficient),
                  s.refinement.shift_passive,
                  s.refinement.limit_fit,
                  T(s.refinement.status_hysteresis),
                  T(s.refinement.account_relaxation),
                  s.refinement.momentum_account,
                  s.refinement.mass_account,
                  s.refinement.lagrangian,
                  s.refinement.follow_flow,
                  T(s.refinement.distant_fit_interval),
                  T(s.refinement.edge_dither),
                  s.refinement.wall_faces,
                  s.refinement.paired_statuses,
                  s.refinement.paired_exchange,
                  T(s.refinement.activated_mass_bound),
                  s.refinement.account_over_all_fluid,
                  s.refinement.passive_mass_from_volume,
                  T(s.refinement.passive_mass_bound)};
  return c;
}

/// What stands in the flume: nothing, continuum blades (scaled, equivalent), rods (the real blade) pushed on both
/// faces, or porous drag rods.
enum class Plants { none, continuum, rods, drag_rods };

/// Refined: fine fluid around the plants (scene.refinement; the drag blades only), one more model; Local: with local
/// time stepping (the coarse fluid at twice the fine step).
template <class T, Plants Kind, bool Refined = false, bool Local = false>
CaseResult run_case(const Options& o, const std::filesystem::path& dir) {
  constexpr bool WithPlants = Kind != Plants::none, Drag = Kind == Plants::drag_rods;
  static_assert(!Refined || Drag, "refinement: the porous drag blades only");
  static_assert(!Local || Refined, "local time stepping: the refined flume only");
  constexpr bool Rods = Kind == Plants::rods || Drag;  // a rod per plant (RodBlades)
  using System = ParticleSystem<2, T, WendlandC2<2>, Tait<T>>;
  using Solid = TotalLagrangianSolid<System>;
  using Plant =
      std::conditional_t<Drag, scenes::RodBlades<System, BladeDrag<T>>,
                         std::conditional_t<Rods, scenes::RodBlades<System>, CoupledBody<RepulsiveForce<T>, Solid>>>;
  using Adaptive = AdaptiveRefinement<System>;
  using Shifting = ParticleShifting<System>;  // --fluid-shift (the refined flume shifts in its refinement model)
  using Solver = std::conditional_t<
      Refined,
      Simulation<System, std::conditional_t<Local, LocalSymplecticVerlet, SymplecticVerlet>, waves::DampingZone<T>,
                 Plant, Adaptive>,
      std::conditional_t<WithPlants, Simulation<System, SymplecticVerlet, waves::DampingZone<T>, Plant, Shifting>,
                         Simulation<System, SymplecticVerlet, waves::DampingZone<T>, Shifting>>>;
  scenes::PosidoniaFlume<T> scene = converted<T>(o.scene);
  if (!WithPlants) scene.plants = 0;
  if (!Refined) scene.refinement.enabled = false;
  const auto g = scene.flume();
  System system(scenes::wave_flume_domain(g), Tait<T>(1000, g.sound_speed()));
  const auto layout = scenes::build_posidonia_flume(system, scene);
  FluidParameters<2, T> fluid = scenes::wave_flume_fluid(g);
  fluid.artificial_viscosity = T(o.alpha);
  fluid.density_diffusion = T(o.delta);
  fluid.thin_structure_visibility = o.visibility;
  fluid.thin_structure_guard = o.guard;
  fluid.same_resolution_pairs = Refined;  // adaptive refinement: each resolution sees only its own particles
  if (o.uniform_viscosity) fluid.viscosity_reference_smoothing_length = g.smoothing_ratio * scene.plant_dp();
  fluid.receding_pair_viscosity = o.receding_viscosity;
  ParticleShiftingParameters<T> shifting;  // --fluid-shift: every active fluid particle, after each step
  shifting.enabled = o.fluid_shift;
  shifting.coefficient = T(o.scene.refinement.shift_coefficient);

  auto adaptive_parameters = scene.adaptive_refinement_parameters();
  if (o.fluid_shift) {
    adaptive_parameters.shifting.enabled = true;
    adaptive_parameters.shift_refined_only = false;
  }
  TimeStepParameters<T> stepping;
  stepping.cfl = T(o.cfl);
  auto make_solver = [&]() {
    if constexpr (Refined) {
      return Solver(system, fluid, stepping, g.damping_zone(), scenes::add_posidonia_drag_blades(system, scene, layout),
                    Adaptive(system.domain(), scene.refinement_boxes(), adaptive_parameters));
    } else if constexpr (Drag) {
      return Solver(system, fluid, stepping, g.damping_zone(), scenes::add_posidonia_drag_blades(system, scene, layout),
                    Shifting(shifting));
    } else if constexpr (Rods) {
      return Solver(system, fluid, stepping, g.damping_zone(), scenes::add_posidonia_rods(system, scene, layout),
                    Shifting(shifting));
    } else if constexpr (WithPlants) {
      typename Solid::Parameters params;
      params.gravity = Vec<2, T>(0, -g.wave.gravity);
      params.stretch_limit = T(3);
      Solid blades(system, layout.plant_body, scene.blade_material(), params);
      blades.clamp_by_reflection(Vec<2, T>(0, 0), Vec<2, T>(0, 1));  // embedded rows: odd images about the bed
      // eps(z) of eq. 22 referred to the still-water level, as for the hydrostatic pressure it balances
      RepulsiveForce<T> coupling;
      coupling.water_level = scene.depth;
      coupling.local_depth = scene.depth;
      return Solver(system, fluid, stepping, g.damping_zone(), Plant(coupling, std::move(blades)), Shifting(shifting));
    } else {
      return Solver(system, fluid, stepping, g.damping_zone(), Shifting(shifting));
    }
  };
  Solver sim = make_solver();
  if constexpr (Refined) {
    sim.template model<2>().populate(system);  // the fine particles of the box and its transition zone
    const auto box = scene.refinement_boxes().front();
    fmt::print("refinement box x [{:.3f}, {:.3f}] m, z [{:.3f}, {:.3f}] m at dp / 2 = {:.4f} m, transition {:.3f} m\n",
               double(box.lower[0]), double(box.upper[0]), double(box.lower[1]), double(box.upper[1]),
               double(scene.plant_dp()), double(scene.refinement.transition_spacings * scene.dp()));
  }
  if constexpr (Local) {
    if (o.fine_step_margin >= 0) {  // the box and its transition zone, grown by the margin, bed to wall top
      const auto box = scene.refinement_boxes().front();
      const T grow = scene.refinement.transition_spacings * scene.dp() + T(o.fine_step_margin);
      const Vec<2, T> lower(box.lower[0] - grow, -g.wave.depth), upper(box.upper[0] + grow, T(2) * g.wave.depth);
      sim.set_fine_step_regions({{lower, upper}});
      fmt::print("local steps: the fine step over x [{:.3f}, {:.3f}] m (the box, its transition and {:.3f} m)\n",
                 double(lower[0]), double(upper[0]), o.fine_step_margin);
    }
  }
  const waves::Wavemaker<T> maker(g.wave);
  sim.set_wall_motion(layout.flume.paddle_body, maker.template piston_motion<2>());
  const auto wave = maker.wave();
  sim.set_expected_flow_speed(wave.surface_orbital_velocity(g.wave.wave_height));  // for the c0 check

  CaseResult r;
  r.fluid = system.particles().count(Kind::fluid);
  r.wall = system.particles().count(Kind::wall);
  r.solid = system.particles().count(Kind::solid);
  const double x_last = double(*std::max_element(scene.gauges.begin(), scene.gauges.end()));
  r.end_time = o.end_time > 0 ? o.end_time
                              : double(maker.ramp_time()) + x_last / double(wave.group_velocity) +
                                    (o.waves_analysed + 1.5) * double(wave.period);
  fmt::print("--- {} ({} fluid, {} wall, {} solid particles; end time {:.2f} s)\n",
             WithPlants ? fmt::format("{} plant(s)", scene.plants) : std::string("empty flume"), r.fluid, r.wall,
             r.solid, r.end_time);

  std::filesystem::create_directories(dir);
  waves::WaveGauges<T> gauges(scene.gauges, layout.flume.still_level, g.dp());
  gauges.open(dir / "gauges.csv",
              fmt::format("posidonia_flume ({}): eta (m) at x (m) = column suffix; h = {} m, T = {} s, H = {} m, "
                          "h/dp = {}",
                          WithPlants ? fmt::format("{} plants", scene.plants) : "empty", double(scene.depth),
                          double(scene.period), double(scene.wave_height), double(scene.particles_per_depth)));
  // tips: mean displacement of each plant's top row from its rest position
  const std::size_t plant_count = WithPlants ? layout.plant_x.size() : 0;
  std::vector<std::string> tip_columns{"t"};
  for (std::size_t k = 0; k < plant_count; ++k) {
    tip_columns.push_back(fmt::format("dx_{}", k));
    tip_columns.push_back(fmt::format("dz_{}", k));
  }
  // the water beside each tip: mean displacement of the fluid particles that start within 1.5 dp of it (a passive
  // blade cannot move further than this water)
  for (std::size_t k = 0; k < plant_count; ++k) {
    tip_columns.push_back(fmt::format("water_dx_{}", k));
    tip_columns.push_back(fmt::format("water_dz_{}", k));
  }
  // the Eulerian current at each plant: the fluid's horizontal velocity, Shepard-interpolated at half the blade length
  // above the base (the drag acts on it, where the tracers above follow the water's Lagrangian drift)
  for (std::size_t k = 0; k < plant_count; ++k) tip_columns.push_back(fmt::format("u_mid_{}", k));
  // the same at l/8, 3l/8, 5l/8 and 7l/8 above the base: the profile of the current the blade stands in
  const std::array<double, 4> profile_heights{0.125, 0.375, 0.625, 0.875};
  for (std::size_t k = 0; k < plant_count; ++k)
    for (double f : profile_heights)
      tip_columns.push_back(fmt::format("u_{}_z{:.4f}", k, f * double(scene.blade_length())));
  std::optional<io::CsvWriter> tips_csv;
  if (WithPlants)
    tips_csv.emplace(dir / "tips.csv", tip_columns,
                     fmt::format("plant tip (top row mean) displacement (m); plant centre lines x = {} m",
                                 fmt::join(layout.plant_x, ", ")));
  // the current profile along the flume: the Eulerian horizontal velocity at the blade's four profile heights
  // (l/8 ... 7l/8 above the bed) every 0.1 m from 0.5 to 1.9 m, so that the mean current near the bed can be followed
  // into and through a refinement box
  std::vector<double> current_x;
  for (int i = 5; i <= 19; ++i) current_x.push_back(0.1 * i);
  std::vector<std::string> current_columns{"t"};
  for (double x : current_x)
    for (double f : profile_heights)
      current_columns.push_back(fmt::format("u_x{:.2f}_z{:.4f}", x, f * double(scene.blade_length())));
  io::CsvWriter currents_csv(dir / "currents.csv", current_columns,
                             "Eulerian horizontal velocity (m/s) of the active fluid at x (m, first number) and height "
                             "above the bed (m, second number)");
  // the period-mean map of the active fluid (--flow-map-from): over the current probes' span along x, up to above the
  // crests, in bins of half the fine spacing of the refined runs (2.5 mm)
  std::optional<FlowMap<System>> flow_map, window_map;
  if (o.flow_map_from >= 0)
    flow_map.emplace(current_x.front(), current_x.back(), 1.3 * double(scene.depth), 0.0025,
                     double(system.eos().reference_density()), double(g.smoothing_ratio * scene.dp()),
                     double(scene.dp()));
  // --flow-map-window: the same map over consecutive windows, to see whether the mean flow changes along the record
  if (flow_map && o.flow_map_window > 0) window_map.emplace(*flow_map);
  std::size_t window_index = 0;
  const auto window_start = [&](std::size_t k) { return o.flow_map_from + double(k) * o.flow_map_window; };
  const auto write_window = [&]() {
    window_map->write(dir / fmt::format("flow_map_window{}.csv", window_index), window_start(window_index));
    window_map->restart();
    ++window_index;
  };
  // the active fluid's volume sum m / rho and mass, per unit width: a refinement box's status changes move water
  // between the active and the passive fluid, and its mass account hands the difference back at fixed density
  io::CsvWriter volume_csv(
      dir / "fluid_volume.csv",
      {"t", "active_volume", "active_mass", "status_mass_coarse", "status_nominal_coarse", "status_mass_fine",
       "status_nominal_fine"},
      "active fluid particles: sum of m / rho (m^2 per m width) and of m (kg per m width); with refinement, the active "
      "mass the status changes of the coarse and the fine level brought in since the start, with the particles' "
      "masses and at their nominal masses (kg per m width, before the accounts)");
  auto record_volume = [&](const System& s, double t) {
    const auto& p = s.particles();
    double volume = 0, mass = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::fluid || p.passive[i]) continue;
      volume += double(p.mass[i] / p.density[i]), mass += double(p.mass[i]);
    }
    std::array<double, 4> status{};
    if constexpr (Refined) {
      const auto& c = sim.template model<2>().total_counts();
      status = {c.status_mass[0], c.status_nominal_mass[0], c.status_mass[1], c.status_nominal_mass[1]};
    }
    volume_csv.write_row({t, volume, mass, status[0], status[1], status[2], status[3]});
  };
  auto tip_position = [&](const System& s, std::size_t k) {
    if constexpr (Rods) return Vec<2, T>(sim.template model<1>().rod(k).tip_position());
    Vec<2, T> c = Vec<2, T>::Zero();
    for (auto id : layout.tips[k]) c += s.particles().position[s.particles().slot_of_id(id)];
    return Vec<2, T>(c / T(layout.tips[k].size()));
  };
  std::vector<Vec<2, T>> tip0;
  for (std::size_t k = 0; k < plant_count; ++k) tip0.push_back(tip_position(system, k));
  std::vector<scenes::FluidTracers<System>> water;
  for (std::size_t k = 0; k < plant_count; ++k) water.emplace_back(system, tip0[k], T(1.5) * scene.dp());
  std::vector<double> times;
  std::vector<std::vector<double>> tip_dx(plant_count), tip_dz(plant_count), water_dx(plant_count), u_mid(plant_count);
  scenes::BladeCrossingCounter<System> crossings(T(1.5) * scene.dp());

  io::VtkSeriesWriter vtk(dir, "posidonia_flume");
  const double sample_every = double(scene.period) / 40;
  double next_sample = 0, next_snapshot = 0;
  io::ProgressReporter progress(r.end_time);
  const auto start = std::chrono::steady_clock::now();
  try {
    sim.run(T(r.end_time), [&](Solver& sm) {
      progress(sm);
      r.particle_steps = sm.particle_steps();
      if (flow_map) flow_map->track(sm.system(), double(sm.time()), o.flow_map_from);
      if (window_map) {
        if (double(sm.time()) >= window_start(window_index + 1)) write_window();
        window_map->track(sm.system(), double(sm.time()), o.flow_map_from);
      }
      if constexpr (Rods && !Drag) {
        // Every step (porous blades: the water passes): between samples a particle beside the tip could go round it.
        crossings.update(sm.system(), sm.template model<1>());
      }
      if (double(sm.time()) + 1e-9 >= next_sample) {
        gauges.sample(sm.system(), sm.time());
        record_volume(sm.system(), double(sm.time()));
        if (flow_map && double(sm.time()) >= o.flow_map_from) flow_map->sample(sm.system());
        if (window_map && double(sm.time()) >= o.flow_map_from) window_map->sample(sm.system());
        {
          std::vector<double> row{double(sm.time())};
          for (double x : current_x)
            for (double f : profile_heights)
              row.push_back(eulerian_velocity(sm.system(), Vec<2, T>(T(x), T(f) * scene.blade_length())));
          currents_csv.write_row(row);
        }
        if constexpr (WithPlants) {
          std::vector<double> row{double(sm.time())};
          times.push_back(double(sm.time()));
          for (std::size_t k = 0; k < plant_count; ++k) {
            const Vec<2, T> d = tip_position(sm.system(), k) - tip0[k];
            row.push_back(double(d[0]));
            row.push_back(double(d[1]));
            tip_dx[k].push_back(double(d[0]));
            tip_dz[k].push_back(double(d[1]));
          }
          for (std::size_t k = 0; k < plant_count; ++k) {
            const Vec<2, T> w = water[k].mean_displacement(sm.system());
            row.push_back(double(w[0]));
            row.push_back(double(w[1]));
            water_dx[k].push_back(double(w[0]));
          }
          for (std::size_t k = 0; k < plant_count; ++k) {
            const double u =
                eulerian_velocity(sm.system(), Vec<2, T>(layout.plant_x[k], T(0.5) * scene.blade_length()));
            row.push_back(u);
            u_mid[k].push_back(u);
          }
          for (std::size_t k = 0; k < plant_count; ++k)
            for (double f : profile_heights)
              row.push_back(eulerian_velocity(sm.system(), Vec<2, T>(layout.plant_x[k], T(f) * scene.blade_length())));
          tips_csv->write_row(row);
          if constexpr (Rods) {
            const auto& rods = sm.template model<1>();
            r.max_stretch = std::max(r.max_stretch, double(rods.max_stretch()));
            const double low = double(rods.lowest_free_node(T(0), T(0)));
            r.lowest_node = std::isnan(r.lowest_node) ? low : std::min(r.lowest_node, low);
          } else {
            r.max_stretch = std::max(r.max_stretch, double(sm.template model<1>().solid().max_stretch()));
            r.fluid_inside_max =
                std::max(r.fluid_inside_max, scenes::fluid_particles_inside_solid(sm.system(), layout.plant_body));
          }
        }
        next_sample += sample_every;
      }
      if (o.snapshots > 0 && double(sm.time()) + 1e-9 >= next_snapshot) {
        vtk.write(sm.system().particles(), sm.time());
        next_snapshot += r.end_time / o.snapshots;
      }
    });
  } catch (const BlowUpError& e) {
    r.failure = e.what();
    fmt::print(stderr, "run stopped: {}\n", r.failure);
    vtk.write(system.particles(), sim.time());
  }
  progress.finish(sim);
  if (flow_map) flow_map->write(dir / "flow_map.csv", o.flow_map_from);
  if (window_map && window_map->samples() > 0) write_window();  // the last, possibly shorter, window
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.steps = sim.step_count();
  r.reached = double(sim.time());
  if constexpr (Rods) r.solid_sub_steps = sim.template model<1>().sub_step_total(), r.crossings = crossings.total();
  else if constexpr (WithPlants) r.solid_sub_steps = sim.template model<1>().solid().sub_step_total();
  r.put_back = sim.fluid().structure_crossings_prevented();
  fmt::print("{} steps to t = {:.2f} s, {:.1f} s wall ({:.4g} particle-steps, {:.2f} million particle-steps/s)\n",
             r.steps, r.reached, r.wall_seconds, r.particle_steps, r.particle_steps / r.wall_seconds * 1e-6);
  if constexpr (Refined) {
    const auto c = sim.template model<2>().total_counts();
    std::size_t active = 0, passive = 0, fine = 0;
    const auto& p = system.particles();
    // where the active fine fluid is at the end (with --lagrangian on the patch moves with the water)
    double fine_x0 = std::numeric_limits<double>::infinity(), fine_x1 = -fine_x0, fine_z1 = -fine_x0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid) {
        (p.passive[i] ? passive : active) += 1;
        const bool is_fine = sim.template model<2>().level_of(p.smoothing_length[i]) > 0;
        fine += is_fine ? 1 : 0;
        if (is_fine && !p.passive[i]) {
          fine_x0 = std::min(fine_x0, double(p.position[i][0]));
          fine_x1 = std::max(fine_x1, double(p.position[i][0]));
          fine_z1 = std::max(fine_z1, double(p.position[i][1]));
        }
      }
    fmt::print(
        "refinement: {} fluid particles at the end ({} active, {} passive, {} fine); {} children created, {} removed; "
        "largest mass-account correction {:.2e}, momentum-account velocity shift {:.2e} m/s; largest passive mass "
        "{:.4f} nominal masses\n",
        active + passive, active, passive, fine, c.created, c.removed, c.mass_correction, c.momentum_correction,
        c.passive_mass_highest);
    if (scene.refinement.paired_exchange)
      fmt::print("refinement: paired exchange in {} groups, {} groups left to the accounts\n", c.exchanged,
                 c.exchange_skipped);
    const auto box = scene.refinement_boxes().front();
    if (scene.refinement.follow_flow)
      fmt::print("refinement: the box moved {:.4f} m along x with the water\n",
                 double(sim.template model<2>().box_displacement()));
    fmt::print(
        "refinement: active fine fluid at the end over x {:.4f} to {:.4f} m, up to z = {:.4f} m (the box: x "
        "{:.4f} to {:.4f} m, up to z = {:.4f} m)\n",
        fine_x0, fine_x1, fine_z1, double(box.lower[0]), double(box.upper[0]), double(box.upper[1]));
  }

  // zero up-crossing heights once the full-amplitude waves have reached each gauge
  const std::vector<double> t(gauges.times().begin(), gauges.times().end());
  io::CsvWriter heights(dir / "wave_heights.csv", {"x", "H", "H_std", "T", "waves"});
  for (std::size_t i = 0; i < scene.gauges.size(); ++i) {
    const std::vector<double> eta(gauges.series(i).begin(), gauges.series(i).end());
    const double x = double(scene.gauges[i]);
    const double from = double(maker.ramp_time()) + x / double(wave.group_velocity) + double(wave.period);
    double H = std::numeric_limits<double>::quiet_NaN(), s = H, T_ = H, n = 0;
    try {
      const auto w = analysis::zero_crossing_analysis(t, eta, from, r.reached);
      H = w.mean_height, s = w.height_std, T_ = w.mean_period, n = double(w.count());
    } catch (const InputError& e) {
      fmt::print("gauge x = {:.2f} m: no complete wave after t = {:.2f} s\n", x, from);
    }
    r.height.push_back(H), r.height_std.push_back(s), r.period.push_back(T_);
    heights.write_row({x, H, s, T_, n});
  }
  // Incident and reflected waves at the paddle's frequency from the gauges upstream of the (first) plant position
  // (Mansard & Funke 1980; Goda & Suzuki 1976 with two gauges): what the plants, and a refinement box, send back. The
  // window opens when the wave reflected at the plant position has reached the farthest of these gauges.
  {
    const double x_plant = double(scene.first_plant_x);
    std::vector<double> xs;
    std::vector<std::vector<double>> records;
    for (std::size_t i = 0; i < scene.gauges.size(); ++i)
      if (double(scene.gauges[i]) < x_plant) {
        xs.push_back(double(scene.gauges[i]));
        records.emplace_back(gauges.series(i).begin(), gauges.series(i).end());
      }
    if (xs.size() >= 2) {
      const double x_min = *std::min_element(xs.begin(), xs.end());
      const double from = double(maker.ramp_time()) + (2 * x_plant - x_min) / double(wave.group_velocity);
      io::CsvWriter csv(dir / "reflection.csv",
                        {"from", "to", "incident_amplitude", "reflected_amplitude", "K_r", "residual", "gauges"},
                        fmt::format("incident and reflected amplitudes (m) at omega = {:.4f} rad/s, k = {:.4f} rad/m "
                                    "from the gauges upstream of x = {:.3f} m (Mansard & Funke 1980)",
                                    double(wave.angular_frequency), double(wave.wave_number), x_plant));
      try {
        const auto sep = analysis::separate_incident_reflected<double>(t, records, xs, double(wave.angular_frequency),
                                                                       double(wave.wave_number), from, r.reached);
        r.incident_amplitude = sep.incident_amplitude, r.reflected_amplitude = sep.reflected_amplitude;
        fmt::print(
            "reflection ({} gauges upstream of x = {:.2f} m, {:.2f}-{:.2f} s): incident amplitude {:.5f} m, "
            "reflected {:.5f} m, K_r = {:.4f}\n",
            xs.size(), x_plant, from, r.reached, sep.incident_amplitude, sep.reflected_amplitude,
            sep.reflection_coefficient);
        csv.write_row({from, r.reached, sep.incident_amplitude, sep.reflected_amplitude, sep.reflection_coefficient,
                       sep.residual, double(xs.size())});
      } catch (const InputError& e) {
        fmt::print("reflection: not separated ({})\n", e.what());
      }
    }
  }
  // tip excursion: half the peak-to-peak displacement once the full waves have reached the plant
  for (std::size_t k = 0; k < plant_count; ++k) {
    const double from =
        double(maker.ramp_time()) + double(layout.plant_x[k]) / double(wave.group_velocity) + double(wave.period);
    double lo_x = 1e9, hi_x = -1e9, lo_z = 1e9, hi_z = -1e9, sum_x = 0, sum_z = 0;
    double lo_w = 1e9, hi_w = -1e9, sum_w = 0, sum_u = 0;
    std::size_t n = 0;
    for (std::size_t j = 0; j < times.size(); ++j) {
      if (times[j] < from) continue;
      lo_x = std::min(lo_x, tip_dx[k][j]), hi_x = std::max(hi_x, tip_dx[k][j]);
      lo_z = std::min(lo_z, tip_dz[k][j]), hi_z = std::max(hi_z, tip_dz[k][j]);
      lo_w = std::min(lo_w, water_dx[k][j]), hi_w = std::max(hi_w, water_dx[k][j]);
      sum_x += tip_dx[k][j], sum_z += tip_dz[k][j], sum_w += water_dx[k][j], sum_u += u_mid[k][j], ++n;
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    r.tip_dx_amplitude.push_back(n ? 0.5 * (hi_x - lo_x) : nan);
    r.tip_dz_amplitude.push_back(n ? 0.5 * (hi_z - lo_z) : nan);
    r.tip_dx_mean.push_back(n ? sum_x / double(n) : nan);
    r.tip_dz_mean.push_back(n ? sum_z / double(n) : nan);
    r.water_dx_amplitude.push_back(n ? 0.5 * (hi_w - lo_w) : nan);
    r.water_dx_mean.push_back(n ? sum_w / double(n) : nan);
    r.current_mean.push_back(n ? sum_u / double(n) : nan);
    r.tip_dz_lowest.push_back(tip_dz[k].empty() ? nan : *std::min_element(tip_dz[k].begin(), tip_dz[k].end()));
    double periodic_x = nan, periodic_z = nan, drift_x = nan;
    if (!times.empty()) {
      try {
        const double omega = 2 * std::numbers::pi / double(wave.period);
        const auto fx = analysis::fit_harmonics(times, tip_dx[k], omega, from, times.back(), 4, 2);
        const auto fz = analysis::fit_harmonics(times, tip_dz[k], omega, from, times.back(), 4, 2);
        periodic_x = fx.periodic_half_range(), periodic_z = fz.periodic_half_range(), drift_x = fx.drift_range;
      } catch (const InputError&) {
        // a record shorter than one period after the full waves arrive: no periodic part (NaN)
      }
    }
    r.tip_dx_periodic.push_back(periodic_x);
    r.tip_dz_periodic.push_back(periodic_z);
    r.tip_dx_drift_range.push_back(drift_x);
  }
  if constexpr (WithPlants) {
    io::CsvWriter motion(
        dir / "plant_motion.csv",
        {"x", "tip_dx_amplitude", "tip_dz_amplitude", "tip_dx_mean", "tip_dz_mean", "water_dx_amplitude",
         "current_mean", "tip_dx_periodic", "tip_dz_periodic", "tip_dx_drift_range"},
        "per plant, once the full waves have arrived: tip excursion (half peak-to-peak) and mean "
        "displacement (m), the water beside the tip (m), the mean current at mid-height (m/s); the "
        "half peak-to-peak of the tip's periodic part (4 wave harmonics fitted under a quadratic "
        "drift) and the drift's range in x (m)");
    for (std::size_t k = 0; k < plant_count; ++k)
      motion.write_row({double(layout.plant_x[k]), r.tip_dx_amplitude[k], r.tip_dz_amplitude[k], r.tip_dx_mean[k],
                        r.tip_dz_mean[k], r.water_dx_amplitude[k], r.current_mean[k], r.tip_dx_periodic[k],
                        r.tip_dz_periodic[k], r.tip_dx_drift_range[k]});
  }
  return r;
}

const char* blade_name(scenes::BladeModel b) {
  switch (b) {
    case scenes::BladeModel::rod: return "rod";
    case scenes::BladeModel::drag: return "drag";
    case scenes::BladeModel::scaled: return "scaled";
    case scenes::BladeModel::equivalent: return "equivalent";
  }
  return "?";
}

/// A refined run against the uniformly fine one (issue 9 part 4): H at every gauge within 2 %, the tip excursion dx
/// within 5 % and dz within 5 % of the dx excursion (the motion's scale: dz is a tenth of it), with at least 2.5 times
/// fewer particle-steps. Writes DIR/refinement_comparison.csv; returns whether all criteria hold.
bool compare_with_reference(const Options& o, const CaseResult& with) {
  const auto dir = o.reference / "plants";
  const auto heights = io::read_csv(dir / "wave_heights.csv");
  const auto motion = io::read_csv(dir / "plant_motion.csv");
  const auto summary = io::read_csv(o.reference / "summary.csv");
  const auto H = heights.column("H"), x = heights.column("x");
  if (H.size() != with.height.size())
    throw InputError(
        fmt::format("--reference {}: {} gauges there, {} here", o.reference.string(), H.size(), with.height.size()));
  const auto dx = motion.column("tip_dx_amplitude"), dz = motion.column("tip_dz_amplitude");
  if (dx.size() != with.tip_dx_amplitude.size())
    throw InputError(fmt::format("--reference {}: {} plants there, {} here", o.reference.string(), dx.size(),
                                 with.tip_dx_amplitude.size()));
  const auto run_column = summary.column("run"), steps_column = summary.column("particle_steps");
  double reference_steps = 0;
  for (std::size_t i = 0; i < run_column.size(); ++i)
    if (run_column[i] == 1) reference_steps = steps_column[i];
  io::CsvWriter out(
      o.out / "refinement_comparison.csv", {"quantity", "index", "refined", "reference", "error"},
      fmt::format(
          "refined run against the uniformly fine run in {}; errors relative (H: to the "
          "reference H; tip dx, dz: to the reference tip dx excursion); quantity 0 H, 1 tip dx, 2 tip dz, 3 "
          "particle-steps (error: the saving), 4 incident amplitude, 5 K_r (error: the difference), 6 periodic tip dx, "
          "7 periodic tip dz (to the reference periodic dx)",
          o.reference.string()));
  bool pass = true;
  fmt::print("\nagainst the uniformly fine run ({}):\n", o.reference.string());
  for (std::size_t i = 0; i < H.size(); ++i) {
    const double e = with.height[i] / H[i] - 1;
    pass = pass && std::abs(e) <= 0.02;
    fmt::print("  H at x = {:.2f} m: {:.5f} m, fine {:.5f} m: {:+.2f} % (criterion 2 %)\n", x[i], with.height[i], H[i],
               100 * e);
    out.write_row({0, double(i), with.height[i], H[i], e});
  }
  for (std::size_t k = 0; k < dx.size(); ++k) {
    const double ex = with.tip_dx_amplitude[k] / dx[k] - 1, ez = (with.tip_dz_amplitude[k] - dz[k]) / dx[k];
    pass = pass && std::abs(ex) <= 0.05 && std::abs(ez) <= 0.05;
    fmt::print(
        "  plant {} tip excursion dx {:.2f} mm, fine {:.2f} mm: {:+.2f} %; dz {:.2f} mm, fine {:.2f} mm: {:+.2f} % of "
        "the dx excursion (criteria 5 %)\n",
        k, 1e3 * with.tip_dx_amplitude[k], 1e3 * dx[k], 100 * ex, 1e3 * with.tip_dz_amplitude[k], 1e3 * dz[k],
        100 * ez);
    out.write_row({1, double(k), with.tip_dx_amplitude[k], dx[k], ex});
    out.write_row({2, double(k), with.tip_dz_amplitude[k], dz[k], ez});
  }
  // diagnostic, no criterion: the tip's periodic part, apart from the drift of its mean position (references written
  // before session 28 lack these columns)
  if (motion.has_column("tip_dx_periodic")) {
    const auto px = motion.column("tip_dx_periodic"), pz = motion.column("tip_dz_periodic"),
               mean = motion.column("tip_dx_mean");
    for (std::size_t k = 0; k < px.size(); ++k) {
      const double ex = with.tip_dx_periodic[k] / px[k] - 1, ez = (with.tip_dz_periodic[k] - pz[k]) / px[k];
      fmt::print(
          "  plant {} periodic part: dx {:.2f} mm, fine {:.2f} mm: {:+.2f} %; dz {:.2f} mm, fine {:.2f} mm: {:+.2f} % "
          "of dx; mean dx {:+.2f} mm, fine {:+.2f} mm (no criterion)\n",
          k, 1e3 * with.tip_dx_periodic[k], 1e3 * px[k], 100 * ex, 1e3 * with.tip_dz_periodic[k], 1e3 * pz[k], 100 * ez,
          1e3 * with.tip_dx_mean[k], 1e3 * mean[k]);
      out.write_row({6, double(k), with.tip_dx_periodic[k], px[k], ex});
      out.write_row({7, double(k), with.tip_dz_periodic[k], pz[k], ez});
    }
  }
  // diagnostic, no criterion: the incident wave and its reflection upstream of the plants (reflection.csv)
  if (std::filesystem::exists(dir / "reflection.csv") && !std::isnan(with.incident_amplitude)) {
    const auto reflection = io::read_csv(dir / "reflection.csv");
    const double a = reflection.column("incident_amplitude").at(0), b = reflection.column("reflected_amplitude").at(0);
    const double e = with.incident_amplitude / a - 1;
    fmt::print(
        "  upstream of the plants: incident amplitude {:.5f} m, fine {:.5f} m: {:+.2f} %; reflected {:.5f} m "
        "(K_r {:.4f}), fine {:.5f} m (K_r {:.4f}) (no criterion)\n",
        with.incident_amplitude, a, 100 * e, with.reflected_amplitude,
        with.reflected_amplitude / with.incident_amplitude, b, b / a);
    out.write_row({4, 0, with.incident_amplitude, a, e});
    out.write_row({5, 0, with.reflected_amplitude / with.incident_amplitude, b / a,
                   with.reflected_amplitude / with.incident_amplitude - b / a});
  }
  const double saving = reference_steps / with.particle_steps;
  pass = pass && saving >= 2.5;
  fmt::print("  particle-steps {:.4g}, fine {:.4g}: {:.3f} times fewer (criterion 2.5)\n{}\n", with.particle_steps,
             reference_steps, saving, pass ? "PASS" : "FAIL");
  out.write_row({3, 0, with.particle_steps, reference_steps, saving});
  return pass;
}

template <class T>
int run(const Options& o) {
  const auto scene = converted<T>(o.scene);
  const auto g = scene.flume();
  const waves::Wavemaker<T> maker(g.wave);
  const auto w = maker.wave();
  const auto m = scene.blade_material();
  fmt::print(
      "Posidonia flume ({}): h = {} m, T = {} s, target H = {} m; kh = {:.3f}, L = {:.3f} m, c_g = {:.3f} m/s, "
      "piston stroke S = {:.4f} m\n",
      sizeof(T) == 4 ? "float" : "double", double(scene.depth), double(scene.period), double(scene.wave_height),
      double(w.kh()), double(w.wavelength), double(w.group_velocity), double(maker.stroke()));
  fmt::print(
      "resolution: dp = {:.4f} m (h/dp = {}, H/dp = {:.2f}, L/dp = {:.0f}); flume {:.2f} m, damping zone "
      "{:.2f} ... {:.2f} m; c0 = {:.2f} m/s\n",
      double(scene.dp()), double(scene.particles_per_depth), double(scene.wave_height / scene.dp()),
      double(w.wavelength / scene.dp()), double(g.length()), double(g.damping_zone().x_start),
      double(g.damping_zone().x_end), double(g.sound_speed()));
  fmt::print(
      "plants: {} at x = {} m, blade {} model: length l = {:.3f} m ({} rows, l/h = {:.3f}), thickness t_m = "
      "{:.4f} m ({} rows);\n  rho_m = {:.4g} kg/m^3, E_m = {:.4g} Pa, nu_m = {:.5g} (K_m = {:.4g} Pa), "
      "P-wave speed {:.3g} m/s; bending stiffness per width {:.3g} N m (real E t^3/12 = {:.3g} N m, "
      "ratio {:.4g}); mass per length {:.4g} kg/m^2 (real {:.4g})\n",
      scene.plants, fmt::join(scene.plant_x(), ", "), blade_name(scene.blade), double(scene.blade_length()),
      scene.blade_length_rows(), double(scene.blade_length() / scene.depth), double(scene.blade_thickness()),
      scene.blade_rows, double(m.density), double(m.youngs_modulus), double(m.poisson_ratio), double(m.bulk_modulus()),
      double(m.p_wave_speed()), double(scene.model_bending_stiffness()), double(scene.real_bending_stiffness()),
      double(scene.model_bending_stiffness() / scene.real_bending_stiffness()),
      double(m.density * scene.blade_thickness()), double(scene.real_density * scene.real_thickness));
  if (scene.thin_blade()) {
    const auto b = scene.rod_blade();
    fmt::print(
        "rod blades: {} nodes (ds = {:.4f} m), t = {} m, E = {:.3g} Pa, rho = {} kg/m^3, E t^3/12 = {:.3g} N m, "
        "rho t = {:.4g} kg/m^2 per unit width (the real blade's), clamped at the bed, buoyant in 1000 kg/m^3\n",
        b.node_count(scene.plant_dp()), double(b.length) / (b.node_count(scene.plant_dp()) - 1), double(b.thickness),
        double(b.youngs_modulus), double(b.density), double(b.bending_stiffness_per_width()),
        double(b.mass_per_area()));
  }
  if (scene.blade == scenes::BladeModel::drag) {
    const T a = T(1) / scene.spacing;
    fmt::print(
        "porous blades: each plant a row of leaves b = {} m wide covering {} of the flume's width; C_D = {:.3f} ({}), "
        "C_f = {}, "
        "added inertia C_M rho_w pi b / 4 = {:.3g} kg/m^2 (C_M = {}); KC of the incident wave over the blade height "
        "{:.1f}{}\n",
        double(scene.leaf_width), double(scene.frontal_fraction), double(scene.blade_drag_coefficient()),
        scene.drag_coefficient > T(0) ? "given" : "plate law at the incident KC", double(scene.friction_coefficient),
        double(plate_added_mass_per_area(T(1000), scene.leaf_width, scene.added_mass_coefficient)),
        double(scene.added_mass_coefficient), double(scene.keulegan_carpenter_number()),
        scene.plants > 1 ? fmt::format("; meadow frontal area a = 1 / spacing = {:.1f} 1/m ({:.0f} leaves per m^2)",
                                       double(a), double(a / scene.leaf_width))
                         : std::string());
  }

  CaseResult with, without;
  if (o.run_plants)
    with = scene.refinement.enabled && o.local_steps ? run_case<T, Plants::drag_rods, true, true>(o, o.out / "plants")
           : scene.refinement.enabled                ? run_case<T, Plants::drag_rods, true>(o, o.out / "plants")
           : scene.blade == scenes::BladeModel::drag ? run_case<T, Plants::drag_rods>(o, o.out / "plants")
           : scene.blade == scenes::BladeModel::rod  ? run_case<T, Plants::rods>(o, o.out / "plants")
                                                     : run_case<T, Plants::continuum>(o, o.out / "plants");
  if (o.run_empty) without = run_case<T, Plants::none>(o, o.out / "empty");
  const bool have_empty = o.run_empty || !o.empty_from.empty();
  if (!o.run_empty && have_empty) {  // the empty flume of an earlier run at the same waves and resolution
    const auto table = io::read_csv(o.empty_from / "empty" / "wave_heights.csv");
    const auto x = table.column("x");
    without.height = table.column("H");
    if (x.size() != scene.gauges.size())
      throw InputError(fmt::format("--empty-from {}: {} gauges there, {} here", o.empty_from.string(), x.size(),
                                   scene.gauges.size()));
    for (std::size_t i = 0; i < x.size(); ++i)
      if (std::abs(x[i] - double(scene.gauges[i])) > 1e-6)
        throw InputError(fmt::format("--empty-from {}: gauge {} at x = {} m, here at {} m", o.empty_from.string(), i,
                                     x[i], double(scene.gauges[i])));
    fmt::print("empty flume heights from {} (same waves and resolution assumed)\n", o.empty_from.string());
  }

  const std::size_t n = scene.gauges.size();
  io::CsvWriter comparison(o.out / "comparison.csv", {"x", "H_plants", "H_empty", "relative_change"});
  fmt::print("\ngauge x (m)   H with plants (m)   H empty (m)   change\n");
  for (std::size_t i = 0; i < n; ++i) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double a = o.run_plants ? with.height[i] : nan, b = have_empty ? without.height[i] : nan;
    fmt::print("  {:8.2f}   {:17.5f}   {:11.5f}   {:+6.1f} %\n", double(scene.gauges[i]), a, b, 100 * (a / b - 1));
    comparison.write_row({double(scene.gauges[i]), a, b, a / b - 1});
  }
  if (o.run_plants) {
    fmt::print("tip excursion (half peak-to-peak after the full waves arrive) and mean displacement:\n");
    for (std::size_t k = 0; k < with.tip_dx_amplitude.size(); ++k)
      fmt::print("  plant {} at x = {:.3f} m: |dx| {:.2f} mm, |dz| {:.2f} mm; mean dx {:+.2f} mm, dz {:+.2f} mm\n", k,
                 double(scene.plant_x()[k]), 1e3 * with.tip_dx_amplitude[k], 1e3 * with.tip_dz_amplitude[k],
                 1e3 * with.tip_dx_mean[k], 1e3 * with.tip_dz_mean[k]);
    fmt::print(
        "periodic part of the tip's motion (4 wave harmonics under a quadratic drift; half peak-to-peak) and the "
        "drift's range:\n");
    for (std::size_t k = 0; k < with.tip_dx_periodic.size(); ++k)
      fmt::print("  plant {}: periodic |dx| {:.2f} mm, |dz| {:.2f} mm; the mean position drifts over {:.2f} mm in x\n",
                 k, 1e3 * with.tip_dx_periodic[k], 1e3 * with.tip_dz_periodic[k], 1e3 * with.tip_dx_drift_range[k]);
    fmt::print(
        "the water beside each tip (fluid particles that started within 1.5 dp of it) and the Eulerian mean current "
        "at the plant's mid-height:\n");
    for (std::size_t k = 0; k < with.water_dx_amplitude.size(); ++k)
      fmt::print("  plant {}: |dx| {:.2f} mm, mean dx {:+.2f} mm; mean current {:+.2f} mm/s\n", k,
                 1e3 * with.water_dx_amplitude[k], 1e3 * with.water_dx_mean[k], 1e3 * with.current_mean[k]);
    fmt::print(
        "plants run: {} + {} + {} particles, {} steps, {} solid sub-steps, {:.1f} s wall; max stretch {:.3f}, "
        "fluid particles inside the blades (max) {}; fluid particles that crossed a rod blade {} (put back by the "
        "guard: {}); lowest rod node {:.4f} m above the bed{}\n",
        with.fluid, with.wall, with.solid, with.steps, with.solid_sub_steps, with.wall_seconds, with.max_stretch,
        with.fluid_inside_max, with.crossings, with.put_back, with.lowest_node,
        with.failure.empty() ? "" : "; FAILED: " + with.failure);
  }
  if (o.run_empty)
    fmt::print("empty run: {} + {} particles, {} steps, {:.1f} s wall{}\n", without.fluid, without.wall, without.steps,
               without.wall_seconds, without.failure.empty() ? "" : "; FAILED: " + without.failure);
  io::CsvWriter summary(o.out / "summary.csv", {"run", "fluid", "wall", "solid", "steps", "solid_sub_steps", "wall_s",
                                                "reached_s", "max_stretch", "fluid_inside_max", "failed",
                                                "rod_crossings", "rod_lowest_node", "rod_put_back", "particle_steps"});
  if (o.run_plants)
    summary.write_row({1, double(with.fluid), double(with.wall), double(with.solid), double(with.steps),
                       double(with.solid_sub_steps), with.wall_seconds, with.reached, with.max_stretch,
                       double(with.fluid_inside_max), with.failure.empty() ? 0.0 : 1.0, double(with.crossings),
                       with.lowest_node, double(with.put_back), with.particle_steps});
  if (o.run_empty)
    summary.write_row({0, double(without.fluid), double(without.wall), 0, double(without.steps), 0,
                       without.wall_seconds, without.reached, 1, 0, without.failure.empty() ? 0.0 : 1.0, 0,
                       std::numeric_limits<double>::quiet_NaN(), 0, without.particle_steps});
  const std::string plot =
      fmt::format("/usr/bin/python3 {}/examples/posidonia_flume/plot.py {}", SPHFSI_SOURCE_DIR, o.out.string());
  std::fflush(stdout);
  if (std::system(plot.c_str()) != 0) fmt::print("(plot skipped: /usr/bin/python3 with matplotlib not available)\n");
  const bool failed = (o.run_plants && !with.failure.empty()) || (o.run_empty && !without.failure.empty());
  if (failed) return 3;
  if (!o.reference.empty() && o.run_plants && !compare_with_reference(o, with)) return 5;
  if (o.check && o.run_plants) {
    // A passive plant moves with the water: its tip excursion within a factor 2 of the water's beside it (a broken
    // coupling leaves it still, a blade pushed by more than the flow outruns it), its mean lean within 0.3 l and its
    // tip never below l / 4 under its upright height (the full-width rod blade leans 0.31 l and dips 0.58 l by 10 s,
    // docs/posidonia.md).
    const double l = double(scene.blade_length());
    bool ok = true;
    for (std::size_t k = 0; k < with.tip_dx_amplitude.size(); ++k) {
      const double ratio = with.tip_dx_amplitude[k] / with.water_dx_amplitude[k];
      const bool sways = ratio >= 0.5 && ratio <= 2,
                 stands = std::abs(with.tip_dx_mean[k]) <= 0.3 * l && with.tip_dz_lowest[k] >= -0.25 * l;
      fmt::print(
          "check plant {}: tip / water excursion {:.2f} (valid [0.5, 2]), mean lean {:.3f} l (valid 0.3 l), "
          "lowest tip dz {:.3f} l (valid -0.25 l): {}\n",
          k, ratio, with.tip_dx_mean[k] / l, with.tip_dz_lowest[k] / l, sways && stands ? "ok" : "FAILED");
      ok = ok && sways && stands;
    }
    if (!ok) return 4;
  }
  return 0;
}

int main(int argc, char** argv) try {
  // `--no-plants` (no value) runs the empty flume only; the parser below takes `--name value` pairs
  std::vector<char*> args{argv[0]};
  bool no_plants = false;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--no-plants") no_plants = true;
    else args.push_back(argv[i]);
  }
  io::CommandLine cli(int(args.size()), args.data(),
                      "posidonia_flume: Posidonia plants in the reference paper's wave flume (h = 0.2 m); wave "
                      "height at the gauges with and without plants, tip trajectories. Flag --no-plants: run the "
                      "empty flume only.");
  Options o;
  auto& s = o.scene;
  s.wave_height = cli.get_number("height", 0.03, "target wave height H, m");
  const auto gauges = cli.get_numbers("gauges", "0.6,1,1.3,1.7",
                                      "wave gauge positions, m, comma-separated, before the damping zone (H per gauge; "
                                      "the incident and reflected waves from those upstream of the first plant)");
  if (gauges.empty()) throw InputError("--gauges: at least one gauge position is needed (m, in (0, 2) by default)");
  s.gauges.assign(gauges.begin(), gauges.end());
  s.period = cli.get_number("period", 1.2, "wave period T, s");
  s.ramp_periods = cli.get_number("ramp", 2, "paddle start-up ramp, periods");
  s.particles_per_depth = cli.get_number("resolution", 20, "particles over the depth h/dp (40: dp = 5 mm)");
  s.sound_speed_factor = cli.get_number("sound-speed", 7, "c0 / sqrt(g h)");
  s.plants = int(cli.get_number("plants", 1, "number of plants"));
  s.spacing = cli.get_number("spacing", 0.1, "distance between plants, m");
  s.first_plant_x = cli.get_number("plant-x", 1.2, "centre line of the first plant, m");
  s.height_ratio = cli.get_number("height-ratio", 0.4, "blade length / depth (paper: 0.32 to 0.5)");
  const std::string blade =
      cli.get("blade", "drag",
              "blade model: drag (the real blade, t = 0.1 mm, as porous rows of leaves) | rod (the real blade, "
              "full width, pushed on both faces) | scaled (paper Table 3) | equivalent (blows up: docs/posidonia.md)");
  s.blade_rows = int(cli.get_number("blade-rows", 3, "particle rows across the blade"));
  s.equivalent_bulk_modulus =
      cli.get_number("bulk-modulus", 1e5, "bulk modulus of the equivalent blade, Pa (bending unaffected)");
  s.rod_node_spacing = cli.get_number("rod-spacing", 0.5, "rod blade: node spacing / dp");
  s.rod_added_mass = cli.get_number("added-mass", 1, "rod blade: added inertia per length and width / (rho_w dp)");
  s.rod_load_smoothing = int(cli.get_number("load-smoothing", 2, "rod blade: passes of the load filter"));
  s.rod_velocity_factor = cli.get_switch("velocity-factor", false, "rod blade: eq. 23 velocity factor on | off");
  s.rod_normal_damping =
      cli.get_number("normal-damping", 0.5, "rod blade: beta of the coupling's normal dashpot (rate beta c0 / h)");
  s.rod_repulsion =
      cli.get_number("repulsion", 0, "rod blade: k of eq. 19, A = k c0^2 / h (0: stops 3 x the orbital velocity)");
  s.leaf_width = cli.get_number("leaf-width", 0.01, "drag blade: width b of one leaf, m");
  s.drag_coefficient = cli.get_number("blade-cd", 0, "drag blade: C_D (0: the plate law at the incident wave's KC)");
  s.friction_coefficient = cli.get_number("blade-cf", 0, "drag blade: C_f of the tangential skin friction");
  s.added_mass_coefficient =
      cli.get_number("added-mass-coefficient", 1, "drag blade: C_M of the leaf's added inertia C_M rho_w pi b / 4");
  s.frontal_fraction = cli.get_number(
      "frontal-fraction", 1, "drag blade: share of the flume's width one plant's leaves cover (1: a full row), (0, 1]");
  s.poisson_ratio = cli.get_number("poisson", 0.3, "Poisson ratio of the real and scaled blade");
  s.real_density = cli.get_number("real-density", 910, "density of the real blade, kg/m^3");
  s.real_youngs_modulus = cli.get_number("real-modulus", 4.7e8, "Young's modulus of the real blade, Pa");
  s.real_thickness = cli.get_number("real-thickness", 1e-4, "thickness of the real blade, m");
  const std::string runs = cli.get("runs", "both", "runs: both | plants | empty");
  o.visibility = cli.get_switch("visibility", false,
                                "rod blade: on: fluid pairs across the blade do not interact (the blade then holds "
                                "each face's whole pressure: raise --repulsion) | off");
  o.guard = cli.get_switch("guard", true,
                           "rod blade: on: a fluid particle that steps through the blade is put back on its face "
                           "(counted) | off");
  o.check = cli.get_switch("check", false,
                           "on: exit 4 unless every plant sways with the water beside it (tip / water excursion in "
                           "[0.5, 2]) and stands (mean lean within 0.3 l, tip never l / 4 below upright) | off");
  o.alpha = cli.get_number("alpha", 0.01, "artificial viscosity alpha");
  o.delta = cli.get_number("delta", 0.1, "delta-SPH coefficient");
  o.cfl = cli.get_number("cfl", 0.2, "CFL number of the fluid step (0, 1]");
  o.waves_analysed = cli.get_number("waves", 4, "full-amplitude waves recorded at the last gauge");
  o.end_time = cli.get_number("end-time", 0, "end time, s (0: from the waves to analyse at the last gauge)");
  o.snapshots = cli.get_number("snapshots", 20, "VTK snapshots per run (0: none)");
  o.flow_map_from = cli.get_number(
      "flow-map-from", -1,
      "write flow_map.csv: the time-mean active fluid (counts per resolution, mass, volume, mass flux, the "
      "refinement's sources of active mass) in 2.5 mm bins over x 0.5 to 1.9 m, averaged from this time, s (< 0: "
      "no map)");
  o.flow_map_window = cli.get_number("flow-map-window", 0,
                                     "with --flow-map-from: also flow_map_window<k>.csv, the same map over consecutive "
                                     "windows of this length, s (0: none)");
  std::string precision =
      cli.get("precision", "auto", "scalar type: float | double | auto (double for the rod, float otherwise)");
  o.out = cli.get("output", "out/posidonia_flume", "output folder");
  o.empty_from = cli.get("empty-from", "", "with --runs plants: take the empty flume's heights from DIR/empty");
  s.refinement.enabled = cli.get_switch(
      "refine", false, "fine fluid (dp / 2) around the plants only, adaptive refinement (--blade drag): on | off");
  s.refinement.margin = cli.get_number("refine-margin", 0.1, "refinement box beyond the first and last plant, m");
  s.refinement.top = cli.get_number("refine-top", 0.13, "refinement box top above the bed, m (0: above the crests)");
  s.refinement.transition_spacings = cli.get_number("transition", 4, "refinement: transition zone width / dp");
  s.refinement.bunched_fraction =
      cli.get_number("bunched", 0.3, "refinement: bunched_fraction of the passive fine particles");
  s.refinement.shifting =
      cli.get_switch("shift", false, "refinement: particle shifting of the fine particles: on | off");
  s.refinement.shift_coefficient = cli.get_number("shift-coefficient", 2, "refinement: A of the particle shift");
  s.refinement.shift_passive =
      cli.get_switch("shift-passive", true, "refinement: shift the passive fine particles too: on | off");
  s.refinement.limit_fit = cli.get_switch(
      "limit-fit", false, "refinement: the passive particles' linear fit limited to its neighbours' range: on | off");
  s.refinement.status_hysteresis = cli.get_number("hysteresis", 0,
                                                  "refinement: a particle keeps its status within this distance of a "
                                                  "box edge, base spacings, [0, transition - h/dp] (h/dp = 2 here)");
  s.refinement.account_relaxation =
      cli.get_number("account-relaxation", 0, "refinement: relaxation time of the mass account, s (0: at once), >= 0");
  s.refinement.momentum_account =
      cli.get_switch("momentum-account", true, "refinement: the momentum account: on | off");
  s.refinement.mass_account = cli.get_switch("mass-account", true, "refinement: the mass account: on | off");
  s.refinement.lagrangian = cli.get_switch(
      "lagrangian", false,
      "refinement: statuses fixed at the start and carried by the particles (the fine patch moves with the water; no "
      "status changes, children or removals): on | off");
  s.refinement.follow_flow = cli.get_switch(
      "follow-flow", false,
      "refinement: the box moves along x with the mean velocity of the fine water in it (at most transition - h/dp "
      "base spacings): on | off");
  s.refinement.distant_fit_interval = cli.get_number(
      "distant-fit", 0,
      "refinement: the passive particles farther than two kernel supports from where their resolution is active are "
      "fitted at this interval only, s (0: at every pass), [0, 1]");
  s.refinement.edge_dither = cli.get_number(
      "edge-dither", 0,
      "refinement: each particle sees the box edges moved by its own fixed offset, uniform over this width, base "
      "spacings, [0, 2] (a water column then changes status particle by particle)");
  s.refinement.wall_faces = cli.get_switch(
      "wall-faces", false,
      "refinement: the box's bed face (and its top above the crests) counts as a wall, not an edge: no dither, "
      "hysteresis or account band there (off: the accounts' band takes in the box's bottom transition width, as in "
      "sessions 14-29): on | off");
  s.refinement.paired_statuses = cli.get_switch(
      "paired-statuses", false,
      "refinement: a fine particle near a box edge is active exactly when the nearest coarse one is passive, so the "
      "water changes hands cell by cell (off: each particle's status follows its own position): on | off");
  s.refinement.paired_exchange = cli.get_switch(
      "paired-exchange", false,
      "refinement, with --paired-statuses on: a coarse particle and its paired fine ones exchange mass and momentum as "
      "they change status (off: the activated particles keep their passive masses and the accounts balance): on | off");
  s.refinement.activated_mass_bound = cli.get_number(
      "activated-account", 0,
      "refinement: the mass account hands a pass's change first to the particles that became active in it, each "
      "within this fraction of its nominal mass, [0, 1) (0: off, all to the particles near the box edges)");
  const std::string account_region = cli.get(
      "account-region", "edges",
      "refinement: the accounts hand their changes to the active particles near the box edges (edges) or to all "
      "active fluid (all)");
  if (account_region != "edges" && account_region != "all")
    throw InputError(fmt::format("--account-region '{}': valid are edges, all", account_region));
  s.refinement.account_over_all_fluid = account_region == "all";
  s.refinement.passive_mass_from_volume =
      cli.get_switch("volume-mass", true,
                     "refinement: passive masses from their SPH volume, capped at --passive-mass-bound (off: "
                     "nominal): on | off");
  s.refinement.passive_mass_bound = cli.get_number(
      "passive-mass-bound", 1,
      "refinement: the largest volume-based passive mass, in nominal masses, [1, 2] (above 1 the number density "
      "counts the walls of the particle's resolution too)");
  o.local_steps = cli.get_switch("local-steps", false,
                                 "refinement: local time stepping, the coarse fluid at twice the fine step: on | off");
  o.fine_step_margin = cli.get_number(
      "fine-step-margin", -1,
      "with --local-steps on: the coarse fluid within this distance (m) of the box's transition zone steps at the "
      "fine step too, so that the time levels meet inside the coarse fluid (< 0: at the resolution boundary)");
  o.uniform_viscosity = cli.get_switch(
      "uniform-viscosity", false,
      "alpha at the plants' smoothing length, scaled as h_ref / h elsewhere (the same nu, proportional to alpha h c0, "
      "at both resolutions): on | off");
  o.receding_viscosity = cli.get_switch(
      "receding-viscosity", false,
      "the artificial viscosity on receding pairs too (the delta-SPH viscous term; off: Monaghan's switch): on | off");
  o.fluid_shift = cli.get_switch("fluid-shift", false,
                                 "particle shifting of every active fluid particle, A = --shift-coefficient (refined "
                                 "runs: of every level; --shift: the fine levels only): on | off");
  o.reference = cli.get("reference", "",
                        "with --refine on: compare with the uniformly fine run in DIR (H within 2 %, tip motion within "
                        "5 %, 2.5 times fewer particle-steps; exit 5 if not)");
  if (!cli.finish()) return 0;
  if (blade == "equivalent") s.blade = scenes::BladeModel::equivalent;
  else if (blade == "scaled") s.blade = scenes::BladeModel::scaled;
  else if (blade == "rod") s.blade = scenes::BladeModel::rod;
  else if (blade == "drag") s.blade = scenes::BladeModel::drag;
  else throw InputError(fmt::format("--blade '{}': valid are drag, rod, equivalent, scaled", blade));
  // the rod's axial strains (1e-6) are below float's position resolution over a metre (6e-8 m on 5 mm edges)
  if (precision == "auto") precision = s.thin_blade() ? "double" : "float";
  if (o.visibility && s.blade == scenes::BladeModel::drag)
    throw InputError("--visibility on: only for --blade rod (the porous drag blades let the water through)");
  // the shift's concentration leaves solid particles out, so it would push the water into a continuum blade
  if (o.fluid_shift && (s.blade == scenes::BladeModel::scaled || s.blade == scenes::BladeModel::equivalent))
    throw InputError(
        "--fluid-shift on: only for --blade rod or drag (a continuum blade's particles are not in the "
        "shift's particle concentration)");
  if (runs != "both" && runs != "plants" && runs != "empty")
    throw InputError(fmt::format("--runs '{}': valid are both, plants, empty", runs));
  o.run_plants = runs != "empty" && !no_plants && s.plants > 0;
  o.run_empty = runs != "plants" || no_plants;
  if (s.refinement.enabled && o.run_empty)
    throw InputError(
        "--refine on: use --runs plants (the empty flume has no plants to refine around; compare with a "
        "uniformly fine run through --reference)");
  if (o.local_steps && !s.refinement.enabled)
    throw InputError("--local-steps on: only with --refine on (one resolution has one time level)");
  if (o.fine_step_margin >= 0 && !o.local_steps)
    throw InputError(
        fmt::format("--fine-step-margin {}: only with --local-steps on (valid: < 0 without it)", o.fine_step_margin));
  if (!(o.flow_map_window >= 0) || (o.flow_map_window > 0 && o.flow_map_from < 0))
    throw InputError(fmt::format("--flow-map-window {}: valid is 0 (none) or a length > 0 s with --flow-map-from >= 0",
                                 o.flow_map_window));
  s.validate();
  if (precision == "float") return run<float>(o);
  if (precision == "double") return run<double>(o);
  throw InputError(fmt::format("--precision '{}': valid are float, double", precision));
} catch (const std::exception& e) {
  fmt::print(stderr, "posidonia_flume: error: {}\n", e.what());
  return 1;
}
