// sphfsi: concepts for time integration.
//
// TimeIntegrator: a small trivially copyable struct with
//   template <class Sim> void step(Sim& sim, T dt) const;
// that advances the fluid and wall particles of a Simulation by dt using the Simulation's public hooks
// (evaluate_rates, move_walls, advance_models). It never touches solid particles: solid models advance
// themselves (with their own, possibly smaller, time step) in advance_models.
//
// With local time stepping the step is made of sub-steps: a model's advance is called once per sub-step of the
// finest level, and its compute_rates at each evaluation.
//
// ParticleModel: physics that plugs into a Simulation beside the fluid (solid models, couplings, forcing):
//   void compute_rates(System&, T time);      // adds its forces after the fluid rates are computed
//   T stable_time_step(const System&) const;  // limit on the fluid step (infinity if it sub-cycles)
//   void advance(System&, T time, T dt);      // integrates the particles it owns over [time, time + dt]
#pragma once

#include <concepts>
#include <type_traits>

namespace sphfsi {

/// LocalTimeStepping: an integrator that advances the finest particles in two half steps and the coarser ones in one
/// (integrators/local_time_stepping.hpp) declares `static constexpr bool local_time_stepping = true;`; Simulation then
/// sizes its step from each time level's own stability limit and counts particle-steps per level.
template <class I>
concept LocalTimeStepping = requires {
  requires I::local_time_stepping;
};

template <class M, class System>
concept ParticleModel = requires(M& m, const M& cm, System& s, const System& cs, typename System::scalar_type t) {
  m.compute_rates(s, t);
  { cm.stable_time_step(cs) } -> std::convertible_to<typename System::scalar_type>;
  m.advance(s, t, t);
};

}  // namespace sphfsi
