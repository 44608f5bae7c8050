// sphfsi: a run that survives a blow-up with its last good checkpoint and a diagnosis.
//
// guarded_run(sim, end, options, snapshot) advances a Simulation to `end`, writing a checkpoint (io/checkpoint.hpp)
// and calling the snapshot writer at the start and then every checkpoint_interval / snapshot_interval seconds of
// simulated time. A state is "good" when ParticleSystem::check_state passes on it (every value finite, every
// particle inside the domain): nothing is saved before that check, and checkpoints are replaced atomically, so
// the file on disk is always the last good state. On a BlowUpError (NaN/Inf, a particle leaving the domain, a
// collapsing time step) the run stops, a diagnosis file is written next to the checkpoint (the error, time,
// step, the last good checkpoint and snapshot, and the particles with extreme velocity, acceleration, density
// and sound speed), and the result (or the rethrown error) says where to find them.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/io/checkpoint.hpp>

#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

namespace sphfsi::io {

struct GuardedRunOptions {
  std::filesystem::path checkpoint{};  ///< where the last good checkpoint is kept (required)
  std::filesystem::path diagnosis{};   ///< written on blow-up; empty: "<checkpoint>.diagnosis.txt"
  double checkpoint_interval{0};       ///< simulated seconds between checkpoints, (0, inf)
  double snapshot_interval{0};         ///< simulated seconds between snapshots, [0, inf) (0: start and end only)
  bool rethrow{false};                 ///< rethrow the BlowUpError (with the diagnosis) instead of returning

  void validate() const {
    if (checkpoint.empty()) throw InputError("GuardedRunOptions::checkpoint = \"\" is invalid: give a file path");
    require_positive("GuardedRunOptions::checkpoint_interval (s)", checkpoint_interval);
    require_non_negative("GuardedRunOptions::snapshot_interval (s)", snapshot_interval);
  }
  std::filesystem::path diagnosis_path() const {
    return diagnosis.empty() ? std::filesystem::path(checkpoint.string() + ".diagnosis.txt") : diagnosis;
  }
};

/// How a guarded run ended.
struct GuardedRunResult {
  bool completed{false};  ///< reached the end time
  double time{0};         ///< simulated time reached, s
  std::size_t steps{0};   ///< step count reached
  std::size_t checkpoints_written{0};
  std::size_t snapshots_written{0};
  double last_checkpoint_time{-1};  ///< s (negative: none written)
  std::size_t last_checkpoint_step{0};
  std::string error;                     ///< the BlowUpError message (empty if completed)
  std::string diagnosis;                 ///< the diagnosis text (empty if completed)
  std::filesystem::path diagnosis_file;  ///< where it was written (empty if completed)
};

/// A text summary of the extremes of a particle state: where a blow-up is to be looked for.
template <class System>
std::string diagnose_state(const System& system) {
  using T = typename System::scalar_type;
  const auto& p = system.particles();
  const auto vec = [](const auto& v) {
    std::string s;
    for (int d = 0; d < v.size(); ++d) s += fmt::format("{}{:.6g}", d ? ", " : "", v[d]);
    return "[" + s + "]";
  };
  const auto describe = [&](std::size_t i) {
    return fmt::format("{} particle id {} at x = {} (v = {}, a = {}, rho = {:.6g} kg/m^3, p = {:.6g} Pa)",
                       kind_name(p.kind[i]), p.id[i], vec(p.position[i]), vec(p.velocity[i]), vec(p.acceleration[i]),
                       p.density[i], p.pressure[i]);
  };
  std::size_t non_finite = 0, outside = 0;
  std::string first_non_finite, first_outside;
  std::size_t v_max = 0, a_max = 0, rho_min = 0, rho_max = 0, c_max = 0;
  T v_best = -1, a_best = -1, rho_lo = std::numeric_limits<T>::max(), rho_hi = -1, c_best = -1;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool finite = p.position[i].allFinite() && p.velocity[i].allFinite() && p.acceleration[i].allFinite() &&
                        std::isfinite(p.density[i]) && std::isfinite(p.pressure[i]);
    if (!finite) {
      if (non_finite++ == 0) first_non_finite = describe(i);
      continue;
    }
    if (!system.domain().contains(p.position[i]) && outside++ == 0) first_outside = describe(i);
    if (p.kind[i] == Kind::wall) continue;
    if (const T v = p.velocity[i].norm(); v > v_best) v_best = v, v_max = i;
    if (const T a = p.acceleration[i].norm(); a > a_best) a_best = a, a_max = i;
    if (p.density[i] < rho_lo) rho_lo = p.density[i], rho_min = i;
    if (p.density[i] > rho_hi) rho_hi = p.density[i], rho_max = i;
    if (p.sound_speed[i] > c_best) c_best = p.sound_speed[i], c_max = i;
  }
  std::string out = fmt::format("particles: {} ({} fluid, {} wall, {} solid)\n", p.size(), p.count(Kind::fluid),
                                p.count(Kind::wall), p.count(Kind::solid));
  out += fmt::format("non-finite state: {} particle(s){}{}\n", non_finite, non_finite ? ", first: " : "",
                     first_non_finite);
  out += fmt::format("outside the domain: {} particle(s){}{}\n", outside, outside ? ", first: " : "", first_outside);
  if (v_best >= 0) {
    out += fmt::format("largest speed        {:.6g} m/s: {}\n", v_best, describe(v_max));
    out += fmt::format("largest acceleration {:.6g} m/s^2: {}\n", a_best, describe(a_max));
    out += fmt::format("lowest density       {:.6g} kg/m^3: {}\n", rho_lo, describe(rho_min));
    out += fmt::format("highest density      {:.6g} kg/m^3: {}\n", rho_hi, describe(rho_max));
    out += fmt::format("largest sound speed  {:.6g} m/s: {}\n", c_best, describe(c_max));
  }
  return out;
}

/// Runs `sim` to end_time with periodic checkpoints and snapshots; on a BlowUpError keeps the last good
/// checkpoint, writes a diagnosis and returns (or rethrows, options.rethrow). snapshot(sim, index) is called
/// with the running snapshot index; observer(sim) after every step (a ProgressReporter, for instance).
template <class Sim, class Snapshot, class Observer>
GuardedRunResult guarded_run(Sim& sim, double end_time, const GuardedRunOptions& options, Snapshot&& snapshot,
                             Observer&& observer) {
  using T = typename Sim::scalar_type;
  options.validate();
  require_finite("guarded_run end_time (s)", end_time);
  GuardedRunResult result;
  const double start = static_cast<double>(sim.time());
  double next_checkpoint = start, next_snapshot = start;
  std::size_t last_snapshot_step = std::numeric_limits<std::size_t>::max();
  const auto save = [&](bool force) {
    const double t = static_cast<double>(sim.time());
    const bool saved_this_step = result.checkpoints_written > 0 && result.last_checkpoint_step == sim.step_count();
    const bool checkpoint_due = (force && !saved_this_step) || t >= next_checkpoint;
    const bool snapshot_due = (force && last_snapshot_step != sim.step_count()) ||
                              (options.snapshot_interval > 0 && t >= next_snapshot) || result.snapshots_written == 0;
    if (!checkpoint_due && !snapshot_due) return;
    sim.system().check_state(static_cast<T>(t));  // only a good state is saved
    if (checkpoint_due) {
      write_checkpoint(options.checkpoint, sim);
      ++result.checkpoints_written;
      result.last_checkpoint_time = t;
      result.last_checkpoint_step = sim.step_count();
      while (next_checkpoint <= t) next_checkpoint += options.checkpoint_interval;
    }
    if (snapshot_due) {
      snapshot(static_cast<const Sim&>(sim), result.snapshots_written);
      ++result.snapshots_written;
      last_snapshot_step = sim.step_count();
      if (options.snapshot_interval > 0)
        while (next_snapshot <= t) next_snapshot += options.snapshot_interval;
    }
  };
  try {
    save(false);
    sim.run(static_cast<T>(end_time), [&](Sim& s) {
      observer(s);
      save(false);
    });
    save(true);
    result.completed = true;
  } catch (const BlowUpError& e) {
    result.error = e.what();
    result.diagnosis = fmt::format(
        "sphfsi blow-up diagnosis\nerror: {}\nlast completed step: t = {:.9g} s, step {}, dt = {:.6g} s\n", e.what(),
        static_cast<double>(sim.time()), sim.step_count(), static_cast<double>(sim.last_time_step()));
    if (result.checkpoints_written > 0)
      result.diagnosis +=
          fmt::format("last good checkpoint: {} (t = {:.9g} s, step {}); resume with read_checkpoint\n",
                      options.checkpoint.string(), result.last_checkpoint_time, result.last_checkpoint_step);
    else result.diagnosis += "last good checkpoint: none (the initial state was already bad)\n";
    result.diagnosis += fmt::format("snapshots written: {}\nstate at failure:\n{}", result.snapshots_written,
                                    diagnose_state(sim.system()));
    result.diagnosis_file = options.diagnosis_path();
    std::ofstream(result.diagnosis_file) << result.diagnosis;
    if (options.rethrow)
      throw BlowUpError(fmt::format("{}\n(diagnosis in {}; last good checkpoint {})", result.error,
                                    result.diagnosis_file.string(),
                                    result.checkpoints_written ? options.checkpoint.string() : "none"));
  }
  result.time = static_cast<double>(sim.time());
  result.steps = sim.step_count();
  return result;
}

/// guarded_run without a per-step observer.
template <class Sim, class Snapshot>
GuardedRunResult guarded_run(Sim& sim, double end_time, const GuardedRunOptions& options, Snapshot&& snapshot) {
  return guarded_run(sim, end_time, options, std::forward<Snapshot>(snapshot), [](const Sim&) {});
}

}  // namespace sphfsi::io
