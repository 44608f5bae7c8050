// sphfsi: the SolidModel concept, what couplings and scenes may rely on in any elastic solid model.
//
// A solid model is a ParticleModel (integrators/concepts.hpp) that owns the particles of one body
// (kind == Kind::solid, body == body()) and advances them itself, sub-cycling inside the fluid step. Contract:
//   - before advance(system, t, dt), p.acceleration of its particles holds the external (fluid) force per unit
//     mass, written by couplings after WcsphFluid zeroed it; the model holds it constant over [t, t + dt] and adds
//     its internal forces and gravity itself;
//   - it publishes p.density, p.pressure (-tr(sigma)/Dim) and p.sound_speed of its particles;
//   - stable_time_step() is +inf when it sub-cycles;
// and it offers, for couplings and diagnostics:
//   body()                  body index of its particles
//   particle_ids()          ids of its particles (stable across re-sorting)
//   reference_spacing()     initial particle spacing, m
//   cauchy_stress(id)       Cauchy stress of a particle, Pa (tension positive)
//   solid_time_step()       its own stable step, s (CFL on the P-wave speed)
//   max_stretch()           largest stretch between initially neighbouring particles
//   material()              its ElasticMaterial
//   clamp_where(pred)       holds the particles whose reference position satisfies pred
#pragma once

#include <sphfsi/core/types.hpp>
#include <sphfsi/integrators/concepts.hpp>
#include <sphfsi/solid/elastic_material.hpp>

#include <concepts>
#include <cstdint>
#include <vector>

namespace sphfsi {

template <class M, class System>
concept SolidModel = ParticleModel<M, System> &&
    requires(M& m, const M& cm, std::uint32_t id,
             bool (*pred)(const Vec<System::dimension, typename System::scalar_type>&)) {
  { cm.body() } -> std::convertible_to<std::int32_t>;
  { cm.particle_ids() } -> std::convertible_to<const std::vector<std::uint32_t>&>;
  { cm.reference_spacing() } -> std::convertible_to<typename System::scalar_type>;
  { cm.cauchy_stress(id) } -> std::convertible_to<Mat<System::dimension, typename System::scalar_type>>;
  { cm.solid_time_step() } -> std::convertible_to<typename System::scalar_type>;
  { cm.max_stretch() } -> std::convertible_to<typename System::scalar_type>;
  { cm.material() } -> std::convertible_to<const ElasticMaterial<typename System::scalar_type>&>;
  { m.clamp_where(pred) } -> std::convertible_to<std::size_t>;
};

}  // namespace sphfsi
