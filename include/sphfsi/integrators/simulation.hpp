// sphfsi: the time loop. A Simulation advances a ParticleSystem with a fluid model, walls (fixed or moving
// with a prescribed motion), any number of extra ParticleModels (solids, couplings) and a TimeIntegrator.
// The time step varies with the acoustic CFL, force and viscous conditions (WcsphFluid::stable_time_step)
// unless a fixed step is given; a fixed step above the stability limit is rejected. With a LocalTimeStepping
// integrator (integrators/local_time_stepping.hpp) the step is a macro step: the finest particles take it in two
// halves, the coarser ones in one, and each time level's own stability limit sizes it.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/integrators/concepts.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace sphfsi {

template <Real T>
struct TimeStepParameters {
  T cfl{T(0.2)};       ///< CFL number applied to the stable step, (0, 1]
  T fixed_dt{T(0)};    ///< fixed step, s (0: variable step)
  T max_dt{T(1e-2)};   ///< upper bound of the variable step, s
  T min_dt{T(1e-10)};  ///< a step below this is a blow-up ("collapsing time step"), s

  void validate() const {
    require_in_range("TimeStepParameters::cfl", cfl, T(1e-6), T(1));
    require_non_negative("TimeStepParameters::fixed_dt (s)", fixed_dt);
    require_positive("TimeStepParameters::max_dt (s)", max_dt);
    require_positive("TimeStepParameters::min_dt (s)", min_dt);
  }
};

/// A prescribed rigid translation of a wall group: displacement(t) from the initial position and velocity(t).
template <int Dim, Real T>
struct PrescribedMotion {
  std::function<Vec<Dim, T>(T)> displacement;
  std::function<Vec<Dim, T>(T)> velocity;
};

/// A prescribed motion of each particle of a wall group from its initial (reference) position, for motions that are
/// not rigid translations (a flap wavemaker rotating about its hinge): state(reference, t) returns the particle's
/// {position, velocity} at time t.
template <int Dim, Real T>
struct PrescribedKinematics {
  std::function<std::pair<Vec<Dim, T>, Vec<Dim, T>>(const Vec<Dim, T>&, T)> state;
};

// clang-format 14 writes the fold expression below as `...>&&...)`: keep it as written.
// clang-format off
template <class System, class Integrator, class... Models>
  requires(ParticleModel<Models, System> && ...)
class Simulation {
  // clang-format on
 public:
  static constexpr int Dim = System::dimension;
  using T = typename System::scalar_type;
  using Vector = Vec<Dim, T>;
  using scalar_type = T;
  using system_type = System;
  using integrator_type = Integrator;

  Simulation(System& system, const FluidParameters<Dim, T>& fluid, const TimeStepParameters<T>& time_step = {},
             Models... models)
      : system_(system), fluid_(fluid), time_step_(time_step), models_(std::move(models)...) {
    time_step_.validate();
  }

  System& system() noexcept { return system_; }
  const System& system() const noexcept { return system_; }
  WcsphFluid<System>& fluid() noexcept { return fluid_; }
  const WcsphFluid<System>& fluid() const noexcept { return fluid_; }
  template <std::size_t I>
  auto& model() noexcept {
    return std::get<I>(models_);
  }
  template <std::size_t I>
  const auto& model() const noexcept {
    return std::get<I>(models_);
  }
  static constexpr std::size_t model_count = sizeof...(Models);
  /// Whether the integrator steps the time levels at their own rates (LocalTimeStepping).
  static constexpr bool local_time_stepping = LocalTimeStepping<Integrator>;
  T time() const noexcept { return time_; }
  /// Sum over the steps of the particles each step advanced: every particle once per step; with local time stepping
  /// the finest level's particles (and solids) twice per macro step, the coarser ones once. The cost measure of
  /// docs/variable-resolution.md.
  double particle_steps() const noexcept { return particle_steps_; }
  std::size_t step_count() const noexcept { return steps_; }
  T last_time_step() const noexcept { return dt_; }

  /// Receives the run's warnings (a reference sound speed too low for the flow, see check_sound_speed); the
  /// default prints them to stderr. A handler may log them, collect them or throw to make them fatal.
  void set_warning_handler(std::function<void(const std::string&)> handler) {
    if (!handler) throw InputError("set_warning_handler: the handler must be callable");
    warn_ = std::move(handler);
  }

  /// The flow's speed scale U for the sound-speed check, where the default estimate (the long-wave speed
  /// sqrt(g D) of the fluid's depth D) does not apply, e.g. small waves in a deep flume (their orbital velocity).
  void set_expected_flow_speed(T speed) {
    require_positive("Simulation::set_expected_flow_speed speed (m/s)", speed);
    expected_speed_ = speed;
  }

  /// Local time stepping: axis-aligned boxes [lower, upper] in which every particle steps with the finest level,
  /// whatever its smoothing length. Around a refinement box they keep the coarse fluid that meets the fine one
  /// through passive particles on the fine step, so that the two resolutions couple as with one global step and
  /// the time levels meet inside the coarse fluid instead (a coarse pair across the region's edge then joins the
  /// levels: the stepping particle reads its frozen neighbour at that neighbour's midpoint, the hierarchical time
  /// bins of Springel 2005). A particle's level is fixed for a whole macro step by its position at the step's start.
  /// An empty list (the default) puts the level boundary at the resolution boundary.
  void set_fine_step_regions(std::vector<std::pair<Vector, Vector>> boxes) {
    if constexpr (!local_time_stepping)
      if (!boxes.empty())
        throw InputError(
            "Simulation::set_fine_step_regions: only with a local-time-stepping integrator "
            "(LocalSymplecticVerlet); with one global step every particle steps at the finest rate");
    for (const auto& [lower, upper] : boxes)
      for (int d = 0; d < Dim; ++d)
        if (!(std::isfinite(lower[d]) && std::isfinite(upper[d]) && lower[d] < upper[d]))
          throw InputError(
              fmt::format("Simulation::set_fine_step_regions: box axis {} spans [{}, {}] m (valid: "
                          "finite bounds with lower < upper)",
                          d, lower[d], upper[d]));
    fine_step_regions_ = std::move(boxes);
    fine_step_by_id_.clear();
  }
  /// The boxes of set_fine_step_regions().
  const std::vector<std::pair<Vector, Vector>>& fine_step_regions() const noexcept { return fine_step_regions_; }

  /// Moves all wall particles of `body` rigidly with the given motion (a wavemaker paddle, a piston).
  void set_wall_motion(std::int32_t body, PrescribedMotion<Dim, T> motion) {
    if (!motion.displacement || !motion.velocity)
      throw InputError("set_wall_motion: both displacement(t) and velocity(t) must be given");
    motions_[body] = std::move(motion);
    record_reference_positions();
  }

  /// Moves each wall particle of `body` to kinematics.state(its initial position, t) (e.g. a flap rotating about a
  /// hinge). Like set_wall_motion, call it before the first step; a body has one motion or one kinematics.
  void set_wall_kinematics(std::int32_t body, PrescribedKinematics<Dim, T> kinematics) {
    if (!kinematics.state) throw InputError("set_wall_kinematics: state(reference_position, t) must be given");
    kinematics_[body] = std::move(kinematics);
    record_reference_positions();
  }

  /// Advances one time step; returns the step taken.
  T step() {
    if (!initialised_) initialise();
    const T dt = next_time_step();
    const auto n = double(system_.particles().size());
    if constexpr (local_time_stepping) {
      mark_fine_step_regions();
      update_time_levels();
      particle_steps_ += 2.0 * n - double(coarse_count_);
      const auto& p = system_.particles();
      passive_at_start_.assign(p.id_capacity(), 0);
      for (std::size_t i = 0; i < p.size(); ++i)
        if (p.kind[i] == Kind::fluid && p.passive[i]) passive_at_start_[p.id[i]] = 1;
    } else {
      particle_steps_ += n;
    }
    Integrator{}.step(*this, dt);
    fluid_.keep_fluid_beside_structures(system_);
    time_ += dt;
    dt_ = dt;
    ++steps_;
    if (!mach_warned_) check_mach_number();
    return dt;
  }

  /// Advances until end_time (the last step is shortened to land on it), calling observer(*this) after each step.
  template <class Observer>
  void run(T end_time, Observer&& observer) {
    require_finite("Simulation::run end_time (s)", end_time);
    if (!initialised_) initialise();
    while (time_ < end_time - T(1e-12) * std::max(T(1), end_time)) {
      end_limit_ = end_time;
      step();
      observer(*this);
    }
    end_limit_ = std::numeric_limits<T>::max();
  }
  void run(T end_time) {
    run(end_time, [](Simulation&) {});
  }

  /// Initial positions of moving wall particles, indexed by particle id, one entry per id given out when the
  /// motion was set (empty without set_wall_motion).
  const std::vector<Vector>& wall_reference_positions() const noexcept { return reference_position_; }

  /// Whether the initial rate evaluation has been done (the first step() or run() does it).
  bool rates_evaluated() const noexcept { return initialised_; }

  /// Resumes from a saved state (io/checkpoint.hpp): the particle arrays, rates included, must already hold the
  /// state after step `steps`; with rates_evaluated the first rate evaluation is skipped because the saved rates
  /// are those the next step would reuse. Wall motions must be registered (set_wall_motion) before this call.
  void restore_state(T time, std::size_t steps, T last_dt, std::vector<Vector> wall_reference_positions = {},
                     bool rates_evaluated = true) {
    require_finite("Simulation::restore_state time (s)", time);
    require_non_negative("Simulation::restore_state last_dt (s)", last_dt);
    if (!motions_.empty() || !kinematics_.empty()) {
      // Indexed by id: it must cover every wall particle's id (fluid ids may have grown since, by splitting).
      const auto& p = system_.particles();
      std::size_t needed = 0;
      for (std::size_t i = 0; i < p.size(); ++i)
        if (p.kind[i] == Kind::wall) needed = std::max<std::size_t>(needed, std::size_t(p.id[i]) + 1);
      if (wall_reference_positions.size() < std::max<std::size_t>(needed, 1))
        throw InputError(
            fmt::format("Simulation::restore_state wall_reference_positions has {} entries: with moving "
                        "walls it needs one per particle id up to every wall particle's id ({})",
                        wall_reference_positions.size(), std::max<std::size_t>(needed, 1)));
    }
    time_ = time;
    steps_ = steps;
    dt_ = last_dt;
    reference_position_ = std::move(wall_reference_positions);
    initialised_ = rates_evaluated;
    level_steps_known_ = false;  // local time stepping: the levels' limits are taken from the saved rates
  }

  // ---- hooks used by the integrators ----

  /// Neighbours, pressure, fluid and wall rates, then each model's rates, at time t.
  ///
  /// Local time stepping: with freeze_coarse, the coarse time level (time_levels(), recomputed here after the
  /// neighbour search re-sorted the particles) keeps the rates of its last evaluation, models' contributions included,
  /// and only the finest level is evaluated. Each evaluation records the stability limit of the levels it evaluated.
  void evaluate_rates(T t, bool freeze_coarse = false) {
    if (!edges_collected_) collect_structure_edges();
    system_.update_neighbors(t);
    system_.update_pressure();
    auto& p = system_.particles();
    if (const T p_min = fluid_.parameters().minimum_pressure; p_min > -std::numeric_limits<T>::infinity()) {
      parallel_for(p.size(), [&](std::size_t i) {
        if (p.kind[i] == Kind::fluid) p.pressure[i] = std::max(p.pressure[i], p_min);
      });
    }
    if constexpr (local_time_stepping) {
      update_time_levels();
      freeze_coarse = freeze_coarse && coarse_count_ > 0;
      fluid_.compute_rates(system_, freeze_coarse ? &coarse_ : nullptr, !fine_step_regions_.empty());
      if (freeze_coarse) {  // the models add to the fluid's rates: the frozen ones are kept as they were
        frozen_acceleration_.resize(p.size());
        frozen_xsph_.resize(p.size());
        frozen_density_rate_.resize(p.size());
        parallel_for(p.size(), [&](std::size_t i) {
          if (!coarse_[i]) return;
          frozen_acceleration_[i] = p.acceleration[i];
          frozen_xsph_[i] = p.xsph_velocity[i];
          frozen_density_rate_[i] = p.density_rate[i];
        });
      }
      std::apply([&](auto&... m) { (m.compute_rates(system_, t), ...); }, models_);
      if (freeze_coarse) {
        parallel_for(p.size(), [&](std::size_t i) {
          if (!coarse_[i]) return;
          p.acceleration[i] = frozen_acceleration_[i];
          p.xsph_velocity[i] = frozen_xsph_[i];
          p.density_rate[i] = frozen_density_rate_[i];
        });
      }
      record_level_steps(!freeze_coarse);
    } else {
      fluid_.compute_rates(system_);
      std::apply([&](auto&... m) { (m.compute_rates(system_, t), ...); }, models_);
    }
  }

  /// Local time stepping: marks the coarse time level, one flag per slot (1: a fluid or wall particle whose smoothing
  /// length exceeds 1.5 times the smallest one of the fluid and walls and that is outside the fine-step regions at
  /// the start of the step, set_fine_step_regions(); solids step with the finest level), and
  /// returns the flags. Call it again after anything that re-sorted, added or removed particles. The coarse level
  /// interacts with the finest one through the refinement's passive particles only, so it needs
  /// FluidParameters::same_resolution_pairs.
  const std::vector<std::uint8_t>& update_time_levels() {
    const auto& p = system_.particles();
    const std::size_t n = p.size();
    T h_min = std::numeric_limits<T>::max();
    for (std::size_t i = 0; i < n; ++i)
      if (p.kind[i] != Kind::solid) h_min = std::min(h_min, p.smoothing_length[i]);
    coarse_.assign(n, 0);
    coarse_count_ = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (p.kind[i] == Kind::solid || !(p.smoothing_length[i] > T(1.5) * h_min)) continue;
      if (in_fine_step_region(i)) continue;
      coarse_[i] = 1;
      ++coarse_count_;
    }
    if (coarse_count_ > 0 && !fluid_.parameters().same_resolution_pairs)
      throw InputError(
          fmt::format("local time stepping: {} particles have a smoothing length above 1.5 x the smallest ({:.4g} m) "
                      "and FluidParameters::same_resolution_pairs is false: valid only with same_resolution_pairs = "
                      "true (the resolutions meet through passive particles, fluid/adaptive_refinement.hpp), or one "
                      "smoothing length",
                      coarse_count_, h_min));
    return coarse_;
  }
  /// Local time stepping: whether the particle with this id was a passive fluid particle at the start of the step
  /// being taken (false for ids created since).
  bool passive_at_step_start(std::uint32_t id) const noexcept {
    return id < passive_at_start_.size() && passive_at_start_[id] != 0;
  }
  /// The flags of the last update_time_levels() (or evaluation).
  const std::vector<std::uint8_t>& time_levels() const noexcept { return coarse_; }
  /// Particles in the coarse time level at the last update_time_levels().
  std::size_t coarse_particle_count() const noexcept { return coarse_count_; }

  /// Places moving wall particles at their prescribed position and velocity at time t.
  void move_walls(T t) { move_walls(t, t); }
  /// The same, local time stepping: the finest level's walls at t_fine, the coarse level's (time_levels()) at
  /// t_coarse.
  void move_walls(T t_fine, T t_coarse) {
    if (motions_.empty() && kinematics_.empty()) return;
    auto& p = system_.particles();
    const bool two_times = t_fine != t_coarse;
    if (two_times && coarse_.size() != p.size())
      throw InputError("Simulation::move_walls(t_fine, t_coarse): call update_time_levels() first");
    auto time_of = [&](std::size_t i) { return two_times && coarse_[i] ? t_coarse : t_fine; };
    for (const auto& [body, kinematics] : kinematics_) {
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kind[i] != Kind::wall || p.body[i] != body) continue;
        const auto [x, v] = kinematics.state(reference_position_[p.id[i]], time_of(i));
        p.position[i] = x;
        p.velocity[i] = v;
      }
    }
    for (const auto& [body, motion] : motions_) {
      const Vector d_fine = motion.displacement(t_fine), v_fine = motion.velocity(t_fine);
      const Vector d_coarse = two_times ? motion.displacement(t_coarse) : d_fine;
      const Vector v_coarse = two_times ? motion.velocity(t_coarse) : v_fine;
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kind[i] != Kind::wall || p.body[i] != body) continue;
        const bool coarse = two_times && coarse_[i];
        p.position[i] = reference_position_[p.id[i]] + (coarse ? d_coarse : d_fine);
        p.velocity[i] = coarse ? v_coarse : v_fine;
      }
    }
  }

  /// Lets every model advance the particles it owns over [t, t + dt].
  void advance_models(T t, T dt) {
    std::apply([&](auto&... m) { (m.advance(system_, t, dt), ...); }, models_);
  }

  /// Density after an update: wall particles never drop below rho0 (no wall suction).
  T limit_density(std::size_t i, T rho) const {
    if (system_.particles().kind[i] == Kind::wall) return std::max(rho, system_.eos().reference_density());
    return rho;
  }

  /// The step the next call to step() will take. Local time stepping: the macro step, at most twice the finest
  /// level's limit (models' limits included: they step with it) and the coarse level's limit.
  T next_time_step() {
    if (!initialised_) initialise();
    T stable;
    T sub_steps = T(1);  // sub-steps of the finest level in one step
    if constexpr (local_time_stepping) {
      if (!level_steps_known_) {
        update_time_levels();
        record_level_steps(true);
      }
      sub_steps = T(2);
      stable = std::min(sub_steps * fine_stable_, coarse_stable_);
    } else {
      stable = fluid_.stable_time_step(system_);
    }
    std::apply([&](const auto&... m) { ((stable = std::min(stable, sub_steps * m.stable_time_step(system_))), ...); },
               models_);
    T dt;
    if (time_step_.fixed_dt > T(0)) {
      dt = time_step_.fixed_dt;
      if (dt > stable && steps_ == 0)
        throw InputError(
            fmt::format("TimeStepParameters::fixed_dt = {} s is above the stability limit of this "
                        "scene (acoustic, force and viscous conditions): valid range is (0, {}] s",
                        dt, stable));
    } else {
      dt = std::min(time_step_.cfl * stable, time_step_.max_dt);
    }
    if (!(dt >= time_step_.min_dt))
      throw BlowUpError(
          fmt::format("time step collapsed at t = {:.6g} s, step {}: dt = {:.3g} s is below "
                      "min_dt = {:.3g} s (largest acceleration or sound speed exploded)",
                      time_, steps_, dt, time_step_.min_dt));
    if (time_ + dt > end_limit_) dt = std::max(end_limit_ - time_, time_step_.min_dt);
    return dt;
  }

 private:
  /// Models with thin structures (`structure_edges(std::vector<StructureEdge>&) const` in 2D; in 3D
  /// `structure_edges(edges, bands)` with each edge's lateral band, a ribbon's) publish their edges once; the fluid
  /// hides pairs across them (fluid/thin_structure_visibility.hpp).
  void collect_structure_edges() {
    edges_collected_ = true;
    std::vector<StructureEdge> edges;
    std::vector<std::array<T, 2>> bands;
    std::apply([&](const auto&... m) { (append_structure_edges(m, edges, bands), ...); }, models_);
    if (!edges.empty()) fluid_.set_structure_edges(std::move(edges), std::move(bands));
  }
  template <class Model>
  static void append_structure_edges(const Model& model, std::vector<StructureEdge>& edges,
                                     std::vector<std::array<T, 2>>& bands) {
    if constexpr (Dim == 3 && requires { model.structure_edges(edges, bands); }) model.structure_edges(edges, bands);
    else if constexpr (Dim == 2 && requires { model.structure_edges(edges); }) model.structure_edges(edges);
  }

  /// Local time stepping: which particles (by id) start this step inside a fine-step region.
  void mark_fine_step_regions() {
    if (fine_step_regions_.empty()) return;
    const auto& p = system_.particles();
    fine_step_by_id_.assign(p.id_capacity(), 0);
    for (std::size_t i = 0; i < p.size(); ++i) fine_step_by_id_[p.id[i]] = inside_fine_step_region(p.position[i]);
  }
  bool inside_fine_step_region(const Vector& x) const {
    for (const auto& [lower, upper] : fine_step_regions_)
      if ((x.array() >= lower.array()).all() && (x.array() <= upper.array()).all()) return true;
    return false;
  }
  /// The level a particle took at the start of the step (its position now if it was created since).
  bool in_fine_step_region(std::size_t i) const {
    if (fine_step_regions_.empty()) return false;
    const auto id = system_.particles().id[i];
    if (id < fine_step_by_id_.size()) return fine_step_by_id_[id] != 0;
    return inside_fine_step_region(system_.particles().position[i]);
  }

  /// Local time stepping: the stability limits of the levels just evaluated (the coarse one only when it was).
  void record_level_steps(bool coarse_evaluated) {
    fine_stable_ = fluid_.stable_time_step(system_, [&](std::size_t a) { return !coarse_[a]; });
    if (coarse_evaluated)
      coarse_stable_ = fluid_.stable_time_step(system_, [&](std::size_t a) { return coarse_[a] != 0; });
    level_steps_known_ = true;
  }

  void record_reference_positions() {
    const auto& p = system_.particles();
    reference_position_.resize(p.id_capacity());  // indexed by id
    for (std::size_t i = 0; i < p.size(); ++i) reference_position_[p.id[i]] = p.position[i];
  }

  void initialise() {
    initialised_ = true;
    move_walls(time_);
    evaluate_rates(time_);
    if (time_ == T(0)) {
      system_.check_overlaps();
      check_sound_speed();
    }
  }

  /// Weak compressibility needs c0 >= 10 U for the flow's speed scale U (density errors Ma^2 / 2 <= 0.5 %).
  /// Before the first step U is estimated as the larger of the largest fluid speed and the long-wave speed
  /// sqrt(|g| D), D the fluid's extent along gravity (Monaghan 1994; DualSPHysics's coefsound rule).
  void check_sound_speed() {
    const auto& p = system_.particles();
    const Vector g = fluid_.parameters().gravity;
    const T g_norm = g.norm();
    T lowest = std::numeric_limits<T>::max(), highest = std::numeric_limits<T>::lowest(), v_max = T(0);
    bool any_fluid = false;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.kind[i] != Kind::fluid) continue;
      any_fluid = true;
      v_max = std::max(v_max, p.velocity[i].norm());
      if (g_norm > T(0)) {
        const T depth = -p.position[i].dot(g) / g_norm;
        lowest = std::min(lowest, depth);
        highest = std::max(highest, depth);
      }
    }
    if (!any_fluid) return;
    const T wave_speed = g_norm > T(0) ? std::sqrt(g_norm * (highest - lowest)) : T(0);
    const T speed = std::max(v_max, expected_speed_ > T(0) ? expected_speed_ : wave_speed);
    const T c0 = system_.eos().reference_sound_speed();
    if (c0 < T(10) * speed)
      warn_(
          fmt::format("reference sound speed c0 = {:.4g} m/s is below 10 x the expected flow speed ({:.3g} m/s: "
                      "largest fluid speed {:.3g} m/s, {} {:.3g} m/s): valid range c0 >= {:.4g} m/s for density "
                      "errors below 0.5 %",
                      c0, speed, v_max, expected_speed_ > T(0) ? "expected flow speed" : "long-wave speed sqrt(g D)",
                      expected_speed_ > T(0) ? expected_speed_ : wave_speed, T(10) * speed));
  }

  /// Once per run: the flow has reached Mach 0.2 (density errors Ma^2 / 2 of 2 %, four times the design value).
  void check_mach_number() {
    const auto& p = system_.particles();
    const T v_max = parallel_max(p.size(), T(0),
                                 [&](std::size_t i) { return p.kind[i] == Kind::fluid ? p.velocity[i].norm() : T(0); });
    const T c0 = system_.eos().reference_sound_speed();
    if (!(v_max > T(0.2) * c0)) return;
    mach_warned_ = true;
    warn_(
        fmt::format("at t = {:.6g} s the largest fluid speed {:.3g} m/s is Mach {:.3g} against the reference sound "
                    "speed c0 = {:.4g} m/s: density errors of order Ma^2 / 2 = {:.2g} %; raise c0 to at least "
                    "{:.4g} m/s (10 x the flow speed)",
                    time_, v_max, v_max / c0, c0, T(50) * (v_max / c0) * (v_max / c0), T(10) * v_max));
  }

  System& system_;
  WcsphFluid<System> fluid_;
  TimeStepParameters<T> time_step_;
  std::tuple<Models...> models_;
  std::map<std::int32_t, PrescribedMotion<Dim, T>> motions_;
  std::map<std::int32_t, PrescribedKinematics<Dim, T>> kinematics_;
  std::vector<Vector> reference_position_;
  T time_{0}, dt_{0};
  T end_limit_ = std::numeric_limits<T>::max();
  std::size_t steps_{0};
  bool initialised_{false};
  bool mach_warned_{false};
  bool edges_collected_{false};
  T expected_speed_{0};  // m/s, 0: estimate sqrt(g D)
  double particle_steps_{0};
  // Local time stepping: the coarse level's flags per slot, its size, the levels' last stability limits (without
  // the CFL factor) and the coarse rates kept across a frozen evaluation.
  std::vector<std::uint8_t> coarse_;
  std::vector<std::uint8_t> passive_at_start_;  // by id, at the start of the step being taken
  std::size_t coarse_count_{0};
  T fine_stable_{std::numeric_limits<T>::max()}, coarse_stable_{std::numeric_limits<T>::max()};
  bool level_steps_known_{false};
  std::vector<Vector> frozen_acceleration_, frozen_xsph_;
  std::vector<T> frozen_density_rate_;
  std::vector<std::pair<Vector, Vector>> fine_step_regions_;  // set_fine_step_regions()
  std::vector<std::uint8_t> fine_step_by_id_;                 // by id: inside a fine-step region at the step's start
  std::function<void(const std::string&)> warn_ = [](const std::string& message) {
    std::fprintf(stderr, "warning: %s\n", message.c_str());
  };
};

}  // namespace sphfsi
