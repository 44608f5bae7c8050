// sphfsi: local time stepping for overlapping resolutions: the symplectic position-Verlet scheme of
// integrators/symplectic.hpp with two time levels. The finest particles (and the solids' models) advance in two
// sub-steps of dt / 2, the coarser fluid and wall particles in one step of dt, so that a particle is stepped at the
// rate its own resolution needs (the acoustic limit h / c scales with h). Multi-rate integration of this kind is
// the hierarchical power-of-two time bins of astrophysical SPH (Springel 2005, MNRAS 364:1105), the regional time
// stepping of weakly compressible SPH (Goswami & Batty 2014, Eurographics short papers) and the multiple time
// stepping of Zhang, Rezavand & Hu 2021 (J. Comput. Phys. 429:110028) for a fine solid in a coarse fluid. Here it is
// applied to the resolutions of adaptive particle refinement (fluid/adaptive_refinement.hpp), which interact only
// through passive particles (FluidParameters::same_resolution_pairs), so that no SPH pair joins the two time levels.
//
// One macro step [t, t + dt], f the finest level, c the coarse level (Simulation::time_levels()):
//   sub-step 1:  f drifts dt/4, c drifts dt/2 to its midpoint:  x^{n+1/2}_c = x^n_c + dt/2 v^n_c,  rho likewise
//                evaluation of f alone at t + dt/4 (c keeps its last rates F^{n-1/2}_c)
//                f: kick dt/2 and drift dt/4 to t + dt/2 (as SymplecticVerlet with dt/2)
//                c: v_c = v^n_c + dt/2 F^{n-1/2}_c, a predictor of its velocity at t + dt/2, so that the models and
//                   the refinement pass find both levels at t + dt/2
//                the models advance [t, t + dt/2] (the refinement pass fits the passive particles of both levels)
//   sub-step 2:  c: v_c -= dt/2 F^{n-1/2}_c (back to v^n_c, with what the models changed)
//                f as SymplecticVerlet with dt/2; one evaluation of both levels: f at t + 3dt/4, c at its midpoint
//                t + dt/2, where its passive neighbours were just fitted
//                c: v^{n+1}_c = v_c + dt F^{n+1/2}_c,  x^{n+1}_c = x^{n+1/2}_c + dt/2 v^{n+1}_c,
//                   rho^{n+1}_c = rho^n_c (2 - e) / (2 + e),  e = -dt D^{n+1/2}_c / rho^{n+1/2}_c
//                the models advance [t + dt/2, t + dt]
// The coarse level is the symplectic scheme with dt and the fine one with dt / 2, each exactly: with one smoothing
// length everywhere a macro step is two SymplecticVerlet steps of dt / 2, bit for bit. The coarse level is evaluated
// once per macro step, the fine one twice: the saving is the coarse particles' second evaluation. Evaluating the
// coarse level at the second evaluation rather than the first puts its passive neighbours (inside a finer box) at
// its own midpoint: fitted at t + dt/2 from the fine level, not carried from t.
// A passive coarse particle drifts with the velocity the pass fitted. A coarse particle the pass at t + dt/2 turned
// passive takes no further rate; one it turned active (Simulation::passive_at_step_start) completes the step from
// its fitted state at t + dt/2 with dt/2.
//
// Fine-step regions (Simulation::set_fine_step_regions): coarse particles that start a macro step inside one step
// with the finest level. Around a refinement box they keep the coarse fluid that feeds the passive particles on the
// fine step, so that the resolutions couple as with one global step; the time levels then meet inside the coarse
// fluid, where a pair joins a frozen particle to a stepping one. In the sub-step that evaluates the finest level
// alone such a pair gives its share to the stepping particle only, read from the frozen one at its midpoint
// (WcsphFluid::compute_rates with `mixed`); in the other both take their shares. Momentum across that edge is then
// exchanged at two times, as in the hierarchical time bins of Springel 2005, not conserved pair by pair.
//
// Limits: models' forces on coarse particles are taken from the second evaluation only; solids and couplings belong
// in the finest level (the porous blades in the refinement box). The coarse particles' signal speeds are those of
// their last evaluation, kept by Simulation as a level limit (a restart takes them from the saved rates).
#pragma once

#include <sphfsi/core/parallel.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/integrators/symplectic.hpp>

namespace sphfsi {

struct LocalSymplecticVerlet {
  static constexpr const char* name = "symplectic-local";
  static constexpr bool local_time_stepping = true;

  template <class Sim, class T>
  void step(Sim& sim, T dt) const {
    auto& p = sim.system().particles();
    const T t = sim.time();
    const T half = T(0.5) * dt, quarter = T(0.25) * dt;
    const T t_half = t + half;  // the end of sub-step 1, as a SymplecticVerlet step of dt / 2 would reach it
    auto active_fluid = [&](std::size_t i) { return p.kind[i] == Kind::fluid && !p.passive[i]; };

    // Sub-step 1.
    {
      const auto& coarse = sim.update_time_levels();
      parallel_for(p.size(),
                   [&](std::size_t i) { SymplecticVerlet::begin_particle(sim, p, i, coarse[i] ? dt : half); });
      sim.move_walls(t + quarter, t_half);
    }
    sim.evaluate_rates(t + quarter, true);
    {
      const auto& coarse = sim.time_levels();
      parallel_for(p.size(), [&](std::size_t i) {
        if (p.kind[i] == Kind::solid) return;
        if (coarse[i]) {  // at its midpoint: a predictor of the velocity there, from its last rates
          if (active_fluid(i)) p.velocity[i] = p.velocity_old[i] + half * p.acceleration[i];
          return;
        }
        SymplecticVerlet::finish_particle(sim, p, i, half);
      });
      sim.move_walls(t_half, t_half);
    }
    sim.advance_models(t, half);
    sim.fluid().keep_fluid_beside_structures(sim.system());

    // Sub-step 2 (a model may have re-sorted, added or removed particles: the levels are marked again).
    auto turned_active = [&](std::size_t i) { return active_fluid(i) && sim.passive_at_step_start(p.id[i]); };
    {
      const auto& coarse = sim.update_time_levels();
      parallel_for(p.size(), [&](std::size_t i) {
        if (coarse[i]) {  // keeps its state at t in the _old fields; its velocity back to v^n
          if (active_fluid(i) && !turned_active(i)) p.velocity[i] -= half * p.acceleration[i];
          return;
        }
        SymplecticVerlet::begin_particle(sim, p, i, half);
      });
      sim.move_walls(t_half + quarter, t_half);
    }
    sim.evaluate_rates(t_half + quarter);
    {
      const auto& coarse = sim.time_levels();
      parallel_for(p.size(), [&](std::size_t i) {
        const Kind kind = p.kind[i];
        if (kind == Kind::solid) return;
        if (coarse[i]) {
          if (kind == Kind::fluid && p.passive[i]) {  // drifts with its fitted velocity
            p.position[i] += half * p.velocity[i];
            return;
          }
          if (turned_active(i)) {  // from its fitted state at t + dt/2
            const T e = -half * p.density_rate[i] / p.density[i];
            p.density[i] = sim.limit_density(i, p.density[i] * (T(2) - e) / (T(2) + e));
            p.velocity[i] += half * p.acceleration[i];
            p.position[i] += half * (p.velocity[i] + p.xsph_velocity[i]);
            return;
          }
          const T e = -dt * p.density_rate[i] / p.density[i];
          p.density[i] = sim.limit_density(i, p.density_old[i] * (T(2) - e) / (T(2) + e));
          if (kind != Kind::fluid) return;
          p.velocity[i] += dt * p.acceleration[i];
          p.position[i] += half * (p.velocity[i] + p.xsph_velocity[i]);
          return;
        }
        SymplecticVerlet::finish_particle(sim, p, i, half);
      });
      sim.move_walls(t_half + half, t_half + half);
    }
    sim.advance_models(t_half, half);
  }
};

}  // namespace sphfsi
