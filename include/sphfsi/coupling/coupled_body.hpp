// sphfsi: a solid body coupled to the fluid: one ParticleModel made of an FsiCoupling policy and a SolidModel.
//
//   using Gate = CoupledBody<RepulsiveForce<double>, TotalLagrangianSolid<System>>;
//   Simulation<System, SymplecticVerlet, Gate> sim(system, fluid, time_step, Gate{coupling, solid});
//
// Each evaluation: the solid publishes its pressure/stress, then the coupling adds the fluid-on-solid force to
// the solid's particles and the reaction to the fluid. advance() lets the solid sub-cycle over the fluid step.
#pragma once

#include <sphfsi/coupling/concepts.hpp>
#include <sphfsi/solid/concepts.hpp>

#include <algorithm>
#include <utility>

namespace sphfsi {

template <class Coupling, class Solid>
class CoupledBody {
 public:
  CoupledBody(const Coupling& coupling, Solid solid) : coupling_(coupling), solid_(std::move(solid)) {
    coupling_.validate();
  }

  template <class System>
  void compute_rates(System& system, typename System::scalar_type time) {
    static_assert(FsiCoupling<Coupling, System, Solid>, "Coupling does not model FsiCoupling (coupling/concepts.hpp)");
    static_assert(SolidModel<Solid, System>, "Solid does not model SolidModel (solid/concepts.hpp)");
    solid_.compute_rates(system, time);
    coupling_.apply(system, solid_, time);
  }

  /// The solid's limit (infinite when it sub-cycles) and, if the coupling has one, the coupling's.
  template <class System>
  typename System::scalar_type stable_time_step(const System& system) const {
    auto dt = solid_.stable_time_step(system);
    if constexpr (requires { coupling_.stable_time_step(system, solid_); })
      dt = std::min(dt, coupling_.stable_time_step(system, solid_));
    return dt;
  }

  template <class System>
  void advance(System& system, typename System::scalar_type time, typename System::scalar_type dt) {
    solid_.advance(system, time, dt);
  }

  // ---- checkpoint (io/checkpoint.hpp): the couplings keep no state between steps, the solid does ----
  template <class Writer>
    requires requires(const Solid& s, Writer& w) { s.save_checkpoint(w); }
  void save_checkpoint(Writer& w) const { solid_.save_checkpoint(w); }
  template <class Reader>
    requires requires(Solid& s, Reader& r) { s.load_checkpoint(r); }
  void load_checkpoint(Reader& r) { solid_.load_checkpoint(r); }

  /// The solid's thin-structure edges, if it has any and the coupling is not permeable (the fluid may hide pairs
  /// across them and is kept on its face of them: fluid/thin_structure_visibility.hpp, thin_structure_guard.hpp).
  template <class Edges>
    requires requires(const Solid& s, Edges& e) { s.structure_edges(e); }
  void structure_edges(Edges& edges) const {
    if constexpr (!permeable_coupling<Coupling>) solid_.structure_edges(edges);
  }
  /// The same for a 3D ribbon: its edges and their lateral bands.
  template <class Edges, class Bands>
    requires requires(const Solid& s, Edges& e, Bands& b) { s.structure_edges(e, b); }
  void structure_edges(Edges& edges, Bands& bands) const {
    if constexpr (!permeable_coupling<Coupling>) solid_.structure_edges(edges, bands);
  }

  Solid& solid() noexcept { return solid_; }
  const Solid& solid() const noexcept { return solid_; }
  const Coupling& coupling() const noexcept { return coupling_; }

 private:
  Coupling coupling_;
  Solid solid_;
};

}  // namespace sphfsi
