// Checkpoint and restart of fluid-structure scenes (issue 7): a coupled run resumed from a checkpoint is
// bit-identical to the uninterrupted run, for both solid models, and a checkpoint written by another scene is
// rejected with a clear message.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/coupling/coupled_body.hpp>
#include <sphfsi/coupling/repulsive_force.hpp>
#include <sphfsi/coupling/stress_continuity.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/checkpoint.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/scenes/antoci_gate.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/scenes/solid_builders.hpp>
#include <sphfsi/solid/total_lagrangian.hpp>
#include <sphfsi/solid/updated_lagrangian.hpp>

#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <random>

using namespace sphfsi;

namespace {

namespace fs = std::filesystem;
using System = ParticleSystem<2, double, CubicSpline<2>, Tait<double>>;
using V = Vec<2, double>;

fs::path checkpoint_dir() {
  const fs::path dir = fs::path(SPHFSI_TEST_OUTPUT_DIR) / "solid_checkpoint";
  fs::create_directories(dir);
  return dir;
}

// The Antoci et al. (2007) rubber of Table 2 (scenes/antoci_gate.hpp).
ElasticMaterial<double> rubber() { return scenes::AntociGate<double>{}.solid_material(); }

// A water column leaning on an elastic plate clamped at its foot, with random velocities so that every state
// array (stress, viscous terms, neighbour lists) matters for the next step.
System make_scene() {
  System system(Domain<2, double>(V(-0.1, -0.1), V(0.3, 0.3)), Tait<double>(1000, 20));
  const Resolution<double> res{0.005, 1.3};
  add_fluid_block(system, V(0, 0), V(0.05, 0.06), res, 0.06, 9.81);
  add_solid_block(system, V(0.05, 0), V(0.065, 0.08), res, rubber(), 1);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (auto& v : system.particles().velocity) v = V(u(rng), u(rng));
  return system;
}

TotalLagrangianSolid<System> make_solid(System& system, const TotalLagrangianParameters<2, double>& params) {
  TotalLagrangianSolid<System> solid(system, 1, rubber(), params);
  solid.clamp_where([](const V& x) { return x[1] < 0.006; });
  return solid;
}
UpdatedLagrangianSolid<System> make_solid(System& system, const UpdatedLagrangianParameters<2, double>& params) {
  UpdatedLagrangianSolid<System> solid(system, 1, rubber(), params);
  solid.clamp_where([](const V& x) { return x[1] < 0.006; });
  return solid;
}

bool same_bits(const auto& a, const auto& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (std::memcmp(a[k].data(), b[k].data(), sizeof(a[k][0]) * a[k].size()) != 0) return false;
  return true;
}

template <class Parameters>
void check_restart(const Parameters& params, const char* label) {
  using Solid = decltype(make_solid(std::declval<System&>(), params));
  using Body = CoupledBody<RepulsiveForce<double>, Solid>;
  using Sim = Simulation<System, SymplecticVerlet, Body>;
  constexpr std::size_t total_steps = 40, checkpoint_step = 17;
  const fs::path file = checkpoint_dir() / fmt::format("{}.chk", label);

  const auto build = [&](System& system) {
    return Sim(system, FluidParameters<2, double>{}, {}, Body(RepulsiveForce<double>{}, make_solid(system, params)));
  };
  System reference_system = make_scene();
  Sim reference = build(reference_system);
  for (std::size_t s = 0; s < total_steps; ++s) reference.step();
  {
    System first_system = make_scene();
    Sim first = build(first_system);
    for (std::size_t s = 0; s < checkpoint_step; ++s) first.step();
    io::write_checkpoint(file, first);
  }
  System resumed_system = make_scene();  // the scene is rebuilt, then the checkpoint replaces its state
  Sim resumed = build(resumed_system);
  io::read_checkpoint(file, resumed);
  for (std::size_t s = checkpoint_step; s < total_steps; ++s) resumed.step();

  const auto& p = reference_system.particles();
  const auto& q = resumed_system.particles();
  INFO(label);
  CHECK(reference.template model<0>().solid().sub_step_total() == resumed.template model<0>().solid().sub_step_total());
  CHECK(reference.template model<0>().solid().sub_step_total() > total_steps);  // it did sub-cycle
  if constexpr (requires { params.reference_update; })
    if (params.reference_update > 0) {  // the restart crossed new reference configurations of the kernel sums
      CHECK(reference.template model<0>().solid().reference_update_count() > 0);
      CHECK(reference.template model<0>().solid().reference_update_count() ==
            resumed.template model<0>().solid().reference_update_count());
    }
  CHECK(same_bits(p.position, q.position));
  CHECK(same_bits(p.velocity, q.velocity));
  CHECK(std::memcmp(p.density.data(), q.density.data(), p.density.size() * sizeof(double)) == 0);
  const std::uint32_t probe = reference.template model<0>().solid().particle_ids().back();
  const auto sa = reference.template model<0>().solid().cauchy_stress(probe);
  const auto sb = resumed.template model<0>().solid().cauchy_stress(probe);
  CHECK(sa.norm() > 0);
  CHECK(std::memcmp(sa.data(), sb.data(), sizeof(double) * 4) == 0);
}

}  // namespace

TEST_CASE("Checkpoint: a coupled total-Lagrangian run resumes bit-identically", "[robustness][checkpoint][solid]") {
  TotalLagrangianParameters<2, double> params;
  params.artificial_viscosity = 0.5;  // so the saved internal acceleration (half-step velocity) matters
  check_restart(params, "total_lagrangian");
}

TEST_CASE("Checkpoint: a coupled updated-Lagrangian run resumes bit-identically", "[robustness][checkpoint][solid]") {
  check_restart(UpdatedLagrangianParameters<2, double>{}, "updated_lagrangian");
}

TEST_CASE("Checkpoint: an updated-Lagrangian run with new reference configurations resumes bit-identically",
          "[robustness][checkpoint][solid]") {
  UpdatedLagrangianParameters<2, double> params;
  params.reference_update = 0.01;  // a new reference configuration every few steps of this scene
  check_restart(params, "updated_lagrangian_reference");
}

TEST_CASE("Checkpoint: an original Gray-Monaghan-Swift run resumes bit-identically",
          "[robustness][checkpoint][solid]") {
  UpdatedLagrangianParameters<2, double> params;
  params.formulation = UpdatedLagrangianFormulation::gray_monaghan_swift;
  params.artificial_stress = 0.3;
  check_restart(params, "updated_lagrangian_gms");
}

TEST_CASE("Checkpoint: a solid checkpoint read into another scene gives a clear error",
          "[robustness][checkpoint][solid]") {
  using Tl = TotalLagrangianSolid<System>;
  using Ul = UpdatedLagrangianSolid<System>;
  using TlBody = CoupledBody<RepulsiveForce<double>, Tl>;
  using UlBody = CoupledBody<RepulsiveForce<double>, Ul>;
  const fs::path file = checkpoint_dir() / "other_scene.chk";
  {
    System system = make_scene();
    Simulation<System, SymplecticVerlet, TlBody> sim(
        system, FluidParameters<2, double>{}, {},
        TlBody({}, make_solid(system, TotalLagrangianParameters<2, double>{})));
    for (int s = 0; s < 3; ++s) sim.step();
    io::write_checkpoint(file, sim);
  }
  SECTION("another solid model") {
    System system = make_scene();
    Simulation<System, SymplecticVerlet, UlBody> sim(
        system, FluidParameters<2, double>{}, {},
        UlBody({}, make_solid(system, UpdatedLagrangianParameters<2, double>{})));
    CHECK_THROWS_WITH(io::read_checkpoint(file, sim), Catch::Contains("updated_lagrangian_solid.1.particle_count") &&
                                                          Catch::Contains("total_lagrangian_solid.1.particle_count"));
  }
  SECTION("a solid with a different particle count") {
    System system(Domain<2, double>(V(-0.1, -0.1), V(0.3, 0.3)), Tait<double>(1000, 20));
    const Resolution<double> res{0.005, 1.3};
    add_fluid_block(system, V(0, 0), V(0.05, 0.06), res, 0.06, 9.81);
    add_solid_block(system, V(0.05, 0), V(0.065, 0.07), res, rubber(), 1);  // two rows shorter
    Simulation<System, SymplecticVerlet, TlBody> sim(
        system, FluidParameters<2, double>{}, {},
        TlBody({}, make_solid(system, TotalLagrangianParameters<2, double>{})));
    CHECK_THROWS_WITH(io::read_checkpoint(file, sim), Catch::Contains("solid body 1 was saved with"));
  }
}

TEST_CASE("solid body: particles added after others were removed (ids above the particle count)", "[solid]") {
  // The solid models index their particles by id (solid/body.hpp): the index must span the id capacity, not the
  // particle count, once particles were removed before the solid was built.
  System system(Domain<2, double>(V(-0.1, -0.1), V(0.3, 0.3)), Tait<double>(1000, 20));
  const Resolution<double> res{0.005, 1.3};
  add_fluid_block(system, V(0, 0), V(0.05, 0.06), res, 0.06, 9.81);
  auto& p = system.particles();
  for (std::size_t k = p.size(); k-- > 10;) p.remove(k);
  add_solid_block(system, V(0.05, 0), V(0.065, 0.08), res, rubber(), 1);
  REQUIRE(p.id_capacity() > p.size());
  TotalLagrangianParameters<2, double> params;
  TotalLagrangianSolid<System> solid = make_solid(system, params);
  std::size_t solids = 0;
  for (std::size_t k = 0; k < p.size(); ++k) solids += p.kind[k] == Kind::solid ? 1 : 0;
  CHECK(solid.particle_ids().size() == solids);
  CHECK(solid.body_data().local_index(p.id[p.size() - 1]) == static_cast<std::int64_t>(solids - 1));
  // Undeformed: identity deformation gradient at the particle with the largest id, and one step leaves it there.
  CHECK((solid.deformation_gradient(p.id[p.size() - 1]) - Eigen::Matrix2d::Identity()).norm() < 1e-12);
  solid.compute_rates(system, 0);
  solid.advance(system, 0, solid.solid_time_step());
  CHECK(solid.max_stretch() == Approx(1).margin(1e-9));
}
