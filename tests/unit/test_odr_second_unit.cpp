// One-definition-rule check, part 2 of 2: a second translation unit including the umbrella header (see
// test_odr.cpp). A header function or variable missing `inline` makes the unit-test executable fail to link.
#include <sphfsi/sphfsi.hpp>

namespace sphfsi::odr_check {

double second_unit_kernel_peak() { return CubicSpline<2>{}.value(0.0, 1.0); }

std::size_t second_unit_neighbour_count() {
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
