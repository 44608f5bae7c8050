// Tests of the Posidonia flume scene (scenes/posidonia_flume.hpp): the blade models against the paper's Table 3
// and the preserved quantities, and the plants placed in the flume (fluid left out exactly where the blades are,
// the reflection clamp on the bed plane, input checks).
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/posidonia_flume.hpp>
#include <sphfsi/solid/total_lagrangian.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace sphfsi;
using Catch::Matchers::WithinRel;

namespace {
using System = ParticleSystem<2, double, WendlandC2<2>, Tait<double>>;
}

TEST_CASE("posidonia blade models: the paper's Table 3 and the preserved quantities", "[posidonia]") {
  scenes::PosidoniaFlume<double> s;
  s.particles_per_depth = 40;  // dp = 5 mm: 3 rows = the paper's 15 mm blade
  s.blade = scenes::BladeModel::scaled;
  REQUIRE_THAT(s.blade_thickness(), WithinRel(0.015, 1e-12));
  const auto m = s.blade_material();
  // Table 3 "modified" gives 3 significant digits (3.13e6, 2.6e6, 1.2e6): agree to the rounding of the table
  CHECK_THAT(m.youngs_modulus, WithinRel(3.13e6, 0.002));
  CHECK_THAT(m.bulk_modulus(), WithinRel(2.6e6, 0.01));
  CHECK_THAT(m.shear_modulus(), WithinRel(1.2e6, 0.01));
  CHECK(m.density == 910);
  // the paper's choice keeps E t and multiplies E t^3 by (t_m / t)^2 = 150^2 (plane strain adds 1 / (1 - nu^2))
  CHECK_THAT(m.youngs_modulus * s.blade_thickness(), WithinRel(4.7e8 * 1e-4, 1e-12));
  CHECK_THAT(s.model_bending_stiffness() * (1 - 0.09) / s.real_bending_stiffness(), WithinRel(150.0 * 150.0, 1e-9));

  s.blade = scenes::BladeModel::equivalent;
  for (double resolution : {20.0, 40.0}) {
    s.particles_per_depth = resolution;
    const auto e = s.blade_material();
    const double t = s.blade_thickness();
    CHECK_THAT(e.youngs_modulus * t * t * t, WithinRel(4.7e8 * 1e-12, 1e-9));  // E t^3 / 12 preserved
    CHECK_THAT(e.density * t, WithinRel(910 * 1e-4, 1e-12));                   // mass per length preserved
    CHECK(e.bulk_modulus() >= 0.999 * s.equivalent_bulk_modulus);              // not crushed by the water
    CHECK(e.poisson_ratio < 0.5);
  }
}

TEST_CASE("posidonia flume: plants replace exactly the fluid in their cells; reflection clamp on the bed",
          "[posidonia]") {
  scenes::PosidoniaFlume<double> s;
  s.particles_per_depth = 10;  // dp = 2 cm
  s.absorber_start = 1.8;
  s.gauges = {0.6, 1.0, 1.3, 1.7};
  s.plants = 3;
  s.spacing = 0.12;
  s.height_ratio = 0.4;  // 4 rows
  const double dp = s.dp();

  auto empty_scene = s;
  empty_scene.plants = 0;
  System empty(scenes::wave_flume_domain(empty_scene.flume()), Tait<double>(1000, empty_scene.flume().sound_speed()));
  const auto empty_layout = scenes::build_posidonia_flume(empty, empty_scene);
  CHECK(empty_layout.solid_particles == 0);

  const auto g = s.flume();
  System system(scenes::wave_flume_domain(g), Tait<double>(1000, g.sound_speed()));
  const auto layout = scenes::build_posidonia_flume(system, s);
  const std::size_t blade_cells = std::size_t(s.blade_rows * s.blade_length_rows());
  REQUIRE(layout.plant_x.size() == 3);
  CHECK(layout.solid_particles == 3 * std::size_t(s.blade_rows * (s.blade_length_rows() + s.clamp_rows)));
  CHECK(layout.flume.fluid_particles == empty_layout.flume.fluid_particles - 3 * blade_cells);
  auto& p = system.particles();
  // no fluid particle closer than one lattice spacing to a blade particle (the blades sit on the fluid lattice)
  double closest = 1e9;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::solid) continue;
    for (std::size_t j = 0; j < p.size(); ++j)
      if (p.kind[j] == Kind::fluid) closest = std::min(closest, (p.position[i] - p.position[j]).norm());
  }
  CHECK_THAT(closest, WithinRel(dp, 1e-9));
  // the plants start at x = 1.2 m (within half a lattice spacing) and keep the spacing to a lattice spacing
  CHECK(std::abs(layout.plant_x[0] - 1.2) <= 0.5 * dp + 1e-12);
  CHECK(std::abs(layout.plant_x[1] - layout.plant_x[0] - 0.12) <= dp + 1e-12);
  // tips: the top row of each plant
  for (const auto& tip : layout.tips) {
    REQUIRE(tip.size() == std::size_t(s.blade_rows));
    for (auto id : tip) CHECK_THAT(p.position[p.slot_of_id(id)][1], WithinRel(s.blade_length() - 0.5 * dp, 1e-9));
  }
  // every embedded particle has its mirror in the blade: the reflection clamp accepts the lattice
  TotalLagrangianSolid<System> blades(system, layout.plant_body, s.blade_material());
  CHECK(blades.clamp_by_reflection(Vec<2, double>(0, 0), Vec<2, double>(0, 1)) ==
        3 * std::size_t(s.blade_rows * s.clamp_rows));
}

TEST_CASE("posidonia flume: invalid plants are rejected", "[posidonia]") {
  scenes::PosidoniaFlume<double> s;
  s.plants = 2;
  s.spacing = 0.04;  // blades 3 cm thick at dp = 1 cm: the reference supports would overlap
  CHECK_THROWS_AS(s.validate(), InputError);
  s.spacing = 0.1;
  CHECK_NOTHROW(s.validate());
  s.height_ratio = 0.95;
  CHECK_THROWS_AS(s.validate(), InputError);
  s.height_ratio = 0.4;
  s.first_plant_x = 2.5;  // beyond the damping zone's entrance
  CHECK_THROWS_AS(s.validate(), InputError);
}
