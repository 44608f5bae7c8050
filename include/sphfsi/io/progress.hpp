// sphfsi: progress reporting for long runs.
//
// A ProgressReporter is an observer for Simulation::run(end, observer). It prints simulated time / end time,
// step, particle count, steps per second, particle-steps per second and the estimated time to completion:
//   t = 0.412 / 2 s (20.6%) | step 10234 | 48120 particles | 812 steps/s | 3.91e+07 particle-steps/s | ETA 6m 12s
// On a terminal (isatty) one line is rewritten in place (carriage return) a few times a second; in a log or CI
// a plain line is written every interval_s seconds of wall time. Throughput is measured over the last
// reporting window; the ETA divides the remaining simulated time by the simulated-time rate since the start.
#pragma once

#include <sphfsi/core/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>

#if defined(__unix__) || defined(__APPLE__)
#include <unistd.h>
#endif

namespace sphfsi::io {

/// One progress measurement (all rates per second of wall time).
struct ProgressSample {
  double time{0};                       ///< simulated time, s
  double end_time{0};                   ///< simulated end time, s
  std::size_t step{0};                  ///< steps taken
  std::size_t particles{0};             ///< particle count
  double steps_per_second{0};           ///< over the last reporting window
  double particle_steps_per_second{0};  ///< particles advanced per second (Simulation::particle_steps())
  double eta_seconds{-1};               ///< wall time to end_time, s (negative: not known yet)
};

/// "1h 02m 03s", "6m 12s", "41s", or "?" for a negative duration.
inline std::string format_duration(double seconds) {
  if (!(seconds >= 0) || !std::isfinite(seconds)) return "?";
  const auto s = static_cast<long long>(std::llround(seconds));
  if (s >= 3600) return fmt::format("{}h {:02}m {:02}s", s / 3600, (s / 60) % 60, s % 60);
  if (s >= 60) return fmt::format("{}m {:02}s", s / 60, s % 60);
  return fmt::format("{}s", s);
}

/// The progress line for one sample (no line ending).
inline std::string format_progress_line(const ProgressSample& s) {
  const double fraction = s.end_time > 0 ? 100.0 * s.time / s.end_time : 0.0;
  return fmt::format(
      "t = {:.4g} / {:.4g} s ({:.1f}%) | step {} | {} particles | {:.3g} steps/s | "
      "{:.3g} particle-steps/s | ETA {}",
      s.time, s.end_time, fraction, s.step, s.particles, s.steps_per_second, s.particle_steps_per_second,
      format_duration(s.eta_seconds));
}

/// How progress is written.
enum class ProgressMode {
  automatic,  ///< in-place line if the stream is a terminal, periodic lines otherwise
  in_place,   ///< one line rewritten with '\r'
  lines,      ///< one line per reporting interval
};

struct ProgressOptions {
  double interval_s{10.0};          ///< wall seconds between lines in a log, [0, inf)
  double terminal_interval_s{0.2};  ///< wall seconds between in-place updates on a terminal, [0, inf)
  ProgressMode mode{ProgressMode::automatic};
  std::FILE* stream{stderr};  ///< where progress goes
};

/// Observer for Simulation::run printing progress; call finish(sim) after the run for the final line.
class ProgressReporter {
 public:
  using Clock = std::chrono::steady_clock;

  explicit ProgressReporter(double end_time, const ProgressOptions& options = {})
      : end_time_(end_time), options_(options) {
    require_positive("ProgressReporter end_time (s)", end_time);
    require_non_negative("ProgressOptions::interval_s (s)", options.interval_s);
    require_non_negative("ProgressOptions::terminal_interval_s (s)", options.terminal_interval_s);
    if (!options.stream) throw InputError("ProgressOptions::stream = null is invalid: give an open FILE*");
    in_place_ = options.mode == ProgressMode::in_place ||
                (options.mode == ProgressMode::automatic && is_terminal(options.stream));
  }

  /// Observer call: reports when the reporting interval has passed since the last line.
  template <class Sim>
  void operator()(const Sim& sim) {
    const auto now = Clock::now();
    if (!started_) start(sim, now);
    const double since_last = seconds(now - last_wall_);
    if (since_last < (in_place_ ? options_.terminal_interval_s : options_.interval_s)) return;
    report(sample(sim, now), false);
  }

  /// Writes the final line (and ends the in-place line).
  template <class Sim>
  void finish(const Sim& sim) {
    const auto now = Clock::now();
    if (!started_) start(sim, now);
    report(sample(sim, now), true);
  }

  bool in_place() const noexcept { return in_place_; }
  std::size_t lines_written() const noexcept { return lines_; }

 private:
  static bool is_terminal([[maybe_unused]] std::FILE* f) {
#if defined(__unix__) || defined(__APPLE__)
    return ::isatty(::fileno(f)) != 0;
#else
    return false;
#endif
  }
  static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

  template <class Sim>
  void start(const Sim& sim, Clock::time_point now) {
    started_ = true;
    start_wall_ = last_wall_ = now;
    start_time_ = static_cast<double>(sim.time());
    last_step_ = sim.step_count();
    if constexpr (requires { sim.particle_steps(); }) last_particle_steps_ = sim.particle_steps();
  }

  template <class Sim>
  ProgressSample sample(const Sim& sim, Clock::time_point now) {
    ProgressSample s;
    s.time = static_cast<double>(sim.time());
    s.end_time = end_time_;
    s.step = sim.step_count();
    s.particles = sim.system().size();
    const double window = seconds(now - last_wall_);
    if (window > 0) {
      s.steps_per_second = static_cast<double>(s.step - last_step_) / window;
      s.particle_steps_per_second = s.steps_per_second * static_cast<double>(s.particles);
      // A Simulation counts what its steps advanced (local time stepping: not every particle in every sub-step).
      if constexpr (requires { sim.particle_steps(); })
        s.particle_steps_per_second = (sim.particle_steps() - last_particle_steps_) / window;
    }
    if constexpr (requires { sim.particle_steps(); }) last_particle_steps_ = sim.particle_steps();
    const double elapsed = seconds(now - start_wall_);
    const double simulated = s.time - start_time_;
    if (elapsed > 0 && simulated > 0) s.eta_seconds = std::max(0.0, end_time_ - s.time) * elapsed / simulated;
    last_wall_ = now;
    last_step_ = s.step;
    return s;
  }

  void report(const ProgressSample& s, bool final_line) {
    const std::string line = format_progress_line(s);
    if (in_place_) {
      const std::size_t pad = last_length_ > line.size() ? last_length_ - line.size() : 0;
      std::fprintf(options_.stream, "\r%s%*s", line.c_str(), static_cast<int>(pad), "");
      if (final_line) std::fputc('\n', options_.stream);
      last_length_ = line.size();
    } else {
      std::fprintf(options_.stream, "%s\n", line.c_str());
    }
    std::fflush(options_.stream);
    ++lines_;
  }

  double end_time_;
  ProgressOptions options_;
  bool in_place_{false};
  bool started_{false};
  Clock::time_point start_wall_{}, last_wall_{};
  double start_time_{0}, last_particle_steps_{0};
  std::size_t last_step_{0}, lines_{0}, last_length_{0};
};

}  // namespace sphfsi::io
