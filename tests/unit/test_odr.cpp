// One-definition-rule check, part 1 of 2 (part 2: test_odr_second_unit.cpp). Both translation units of the
// unit-test executable include the umbrella header, so any function or variable a header defines without
// `inline` (and that is not a template) is emitted twice and the executable fails to link: "multiple
// definition of ...". The test case below only checks that both units see the same library.
#include <sphfsi/sphfsi.hpp>

#include <catch2/catch.hpp>

namespace sphfsi::odr_check {
// Defined in test_odr_second_unit.cpp, from the same headers.
double second_unit_kernel_peak();
std::size_t second_unit_neighbour_count();

/// Particles of a 5 x 5 lattice that particle 12 (the centre) interacts with, h = 1.3 dp.
std::size_t first_unit_neighbour_count() {
  using Vector = Vec<2, double>;
  ParticleSystem<2, double, CubicSpline<2>, Tait<double>> system(Domain<2, double>(Vector::Zero(), Vector::Ones()),
                                                                 Tait<double>(1000.0, 20.0));
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      system.particles().add(Kind::fluid, Vector(0.1 + 0.1 * i, 0.1 + 0.1 * j), Vector::Zero(), 1000.0, 10.0, 0.13);
  system.update_neighbors();
  std::size_t count = 0;
  system.for_each_neighbor(system.particles().slot_of_id(12), [&](auto&&...) { ++count; });
  return count;
}
}  // namespace sphfsi::odr_check

TEST_CASE("the umbrella header links from two translation units, which see the same library", "[odr]") {
  using namespace sphfsi;
  CHECK(odr_check::second_unit_kernel_peak() == CubicSpline<2>{}.value(0.0, 1.0));
  // r < 2h = 0.26 around the centre of a 5 x 5 lattice of spacing 0.1: all 24 others but the 4 corners
  // (r = 0.1 sqrt(8) = 0.283); the 8 at r = 0.1 sqrt(5) = 0.224 are in.
  CHECK(odr_check::first_unit_neighbour_count() == 20);
  CHECK(odr_check::second_unit_neighbour_count() == odr_check::first_unit_neighbour_count());
  CHECK(std::string(kind_name(Kind::solid)) == "solid");
}
