// sphfsi: the FsiCoupling concept, the extension point for fluid-structure coupling.
//
// A coupling is a small trivially copyable struct of parameters with
//   template <class System, class Solid> void apply(System&, const Solid&, T time) const;
// called after the fluid rates are computed (WcsphFluid skips fluid-solid pairs and zeroes the acceleration of
// solid particles). It adds the fluid-on-solid force per unit mass to the acceleration of the solid's particles and
// the equal and opposite reaction to the fluid particles (and, if it treats solid particles as part of the fluid's
// continuity equation, their contribution to density_rate). Every coupling of sphfsi conserves the linear momentum
// of the fluid-solid pair to round-off: the reaction is computed from the same pair terms as the action.
// A coupling whose pair forces are stiffer than the fluid may also provide
//   template <class System, class Solid> T stable_time_step(const System&, const Solid&) const;
// (without the CFL factor); CoupledBody then limits the fluid step by it.
// A coupling that lets the fluid through the solid (a porous blade exchanging its drag) says so with
//   static constexpr bool permeable = true;
// its solid then publishes no thin-structure edges: the fluid neither hides pairs across it nor is kept on a face.
// CoupledBody<Coupling, Solid> (coupling/coupled_body.hpp) turns a coupling and a SolidModel into one ParticleModel.
#pragma once

#include <concepts>
#include <type_traits>

namespace sphfsi {

template <class C, class System, class Solid>
concept FsiCoupling = std::is_trivially_copyable_v<C> &&
    requires(const C& c, System& s, const Solid& solid, typename System::scalar_type t) {
  { C::name } -> std::convertible_to<const char*>;
  c.apply(s, solid, t);
};

/// Whether a coupling lets the fluid pass through its solid (C::permeable, false when absent).
template <class C>
inline constexpr bool permeable_coupling = [] {
  if constexpr (requires { C::permeable; }) return bool(C::permeable);
  else return false;
}();

}  // namespace sphfsi
