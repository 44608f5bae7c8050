// Several particle sizes in one scene (issue 9, part 1): every particle carries its own mass and smoothing length,
// and a pair uses the averaged smoothing length h_ab = (h_a + h_b) / 2 (Hernquist & Katz 1989, ApJS 70:419), so
// W_ab = W_ba and grad_a W_ab = -grad_b W_ba: pair forces cancel exactly across a resolution jump.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/builders.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <random>

using namespace sphfsi;

namespace {

using System = ParticleSystem<2, double, WendlandC2<2>, Tait<double>>;
using V = Vec<2, double>;
constexpr double coarse = 0.01, fine = 0.005;  // m: a 2:1 resolution jump at x = 0.1 m

// Fluid filling [0, 0.2] x [0, 0.1]: spacing `coarse` for x < 0.1, `fine` for x > 0.1, each particle with its own
// mass rho0 dp^2 and smoothing length 1.3 dp.
System jump_block() {
  System system(Domain<2, double>(V(-0.05, -0.05), V(0.25, 0.15)), Tait<double>(1000, 20));
  add_fluid_block(system, V(0, 0), V(0.1, 0.1), Resolution<double>{coarse, 1.3}, 0.1, 0);
  add_fluid_block(system, V(0.1, 0), V(0.2, 0.1), Resolution<double>{fine, 1.3}, 0.1, 0);
  return system;
}

}  // namespace

TEST_CASE("mixed resolution: fluid pair forces sum to zero across a 2:1 resolution jump", "[mixed_resolution]") {
  System system = jump_block();
  auto& p = system.particles();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.velocity[i] = V(0.3 * u(rng), 0.3 * u(rng));
    p.density[i] = 1000 * (1 + 0.01 * u(rng));  // pressures of up to 4 kPa either sign
  }
  FluidParameters<2, double> params;
  params.gravity = V::Zero();
  params.xsph = 0.1;
  WcsphFluid<System> fluid(params);
  system.update_neighbors();
  system.update_pressure();
  fluid.compute_rates(system);
  V total = V::Zero();
  double scale = 0, mass_rate = 0, mass_rate_scale = 0;
  std::size_t across = 0;
  for (std::size_t a = 0; a < p.size(); ++a) {
    total += p.mass[a] * p.acceleration[a];
    scale += p.mass[a] * p.acceleration[a].norm();
    mass_rate += p.mass[a] / p.density[a] * p.density_rate[a];
    mass_rate_scale += std::abs(p.mass[a] / p.density[a] * p.density_rate[a]);
    if (p.smoothing_length[a] > 1.3 * fine * 1.5)
      system.for_each_neighbor(a, [&](std::size_t b, const V&, double, double) {
        if (p.smoothing_length[b] < 1.3 * fine * 1.5) ++across;
      });
  }
  INFO("sum m a = " << total.transpose() << " of sum |m a| = " << scale << "; coarse-fine pairs " << across);
  REQUIRE(across > 100);  // the jump is crossed by many pairs
  REQUIRE(scale > 0);
  CHECK(total.norm() <= 1e-12 * scale);
}

TEST_CASE("mixed resolution: the kernel sums stay consistent across a 2:1 jump", "[mixed_resolution]") {
  // Interior particles (a full kernel support inside the fluid) near the jump: the partition of unity
  // S_a = sum_b V_b W_ab and the Shepard interpolation of a linear field f = 2 x + 3 y.
  // Bound: with averaged smoothing lengths a particle next to the jump sees its neighbours on the other side with a
  // smoothing length up to 1.5 x (coarse side) or 0.75 x (fine side) its own; on uniform lattices the sum is
  // exact to the kernel's lattice error (1.05 % for Wendland C2 at h = 1.3 dp on a square lattice, checked below
  // away from the jump with a 2 % bound). At the jump the averaged smoothing lengths change the weights: a coarse
  // particle sees its fine neighbours with a smaller h_ab and loses part of the partition of unity (measured 7.6 %,
  // bounded here by 10 %): quantities that need the partition of unity there must be Shepard-normalised.
  // The jump adds a first-moment imbalance: the Shepard interpolant's error is |grad f . (x_bar - x_a)| with x_bar
  // the weighted centroid of the neighbours, which must stay below a tenth of the coarse spacing times |grad f|
  // (a centroid offset of 0.1 dp_coarse is what a one-sided loss of a tenth of the kernel mass would give).
  System system = jump_block();
  system.update_neighbors();
  const auto& p = system.particles();
  const auto f = [](const V& x) { return 2 * x[0] + 3 * x[1]; };
  const double grad = std::sqrt(13.0);
  double worst_unity_far = 0, worst_unity_jump = 0, worst_shepard_jump = 0, worst_shepard_far = 0;
  for (std::size_t a = 0; a < p.size(); ++a) {
    const V x = p.position[a];
    const double reach = 2 * 1.3 * coarse;                                                   // the largest support
    if (x[0] < reach || x[0] > 0.2 - reach || x[1] < reach || x[1] > 0.1 - reach) continue;  // interior only
    double unity = 0, shepard = 0;
    system.for_each_neighbor(a, [&](std::size_t b, const V& dx, double r, double h) {
      const double w = p.mass[b] / p.density[b] * system.kernel().value(r, h);
      unity += w;
      shepard += w * f(p.position[b]);
      (void)dx;
    });
    unity += p.mass[a] / p.density[a] * system.kernel().value(0.0, p.smoothing_length[a]);
    shepard += p.mass[a] / p.density[a] * system.kernel().value(0.0, p.smoothing_length[a]) * f(x);
    const double shepard_error = std::abs(shepard / unity - f(x));
    const bool near_jump = std::abs(x[0] - 0.1) < reach;
    (near_jump ? worst_unity_jump : worst_unity_far) =
        std::max(near_jump ? worst_unity_jump : worst_unity_far, std::abs(unity - 1));
    (near_jump ? worst_shepard_jump : worst_shepard_far) =
        std::max(near_jump ? worst_shepard_jump : worst_shepard_far, shepard_error);
  }
  INFO("partition of unity error: " << worst_unity_far << " far, " << worst_unity_jump << " at the jump; Shepard "
                                    << worst_shepard_far << " far, " << worst_shepard_jump << " at the jump");
  CHECK(worst_unity_far < 0.02);
  CHECK(worst_unity_jump < 0.1);
  CHECK(worst_shepard_far < 1e-9);                // symmetric stencils: exact for a linear field
  CHECK(worst_shepard_jump > worst_shepard_far);  // the jump is seen
  CHECK(worst_shepard_jump < 0.1 * coarse * grad);
}

namespace {

// Viscous acceleration of every interior fluid particle of a uniform block at spacing dp under the shear wave
// u = (U sin(k y), 0): the acceleration with the artificial viscosity minus the one without (pressure, continuity
// and the lattice's own residual cancel in the difference). Returns the effective viscosity nu of the fit
// a_x = -nu k^2 u_x over the particles at least one support from every edge.
double shear_wave_viscosity(double dp, double viscosity_h, bool receding = false, double smoothing_ratio = 1.3) {
  constexpr double U = 0.05, length = 0.2, k = 2 * 3.14159265358979323846 / length;
  System system(Domain<2, double>(V(-0.05, -0.05), V(0.25, 0.25)), Tait<double>(1000, 20));
  add_fluid_block(system, V(0, 0), V(length, length), Resolution<double>{dp, smoothing_ratio}, 0.0, 0);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = V(U * std::sin(k * p.position[i][1]), 0);
  system.update_neighbors();
  system.update_pressure();
  const auto rates = [&](double alpha) {
    FluidParameters<2, double> params;
    params.gravity = V::Zero();
    params.density_diffusion = 0;
    params.artificial_viscosity = alpha;
    params.viscosity_reference_smoothing_length = viscosity_h;
    params.receding_pair_viscosity = receding;
    WcsphFluid<System> fluid(params);
    fluid.compute_rates(system);
    return p.acceleration;
  };
  const auto with = rates(0.1), without = rates(0);
  double uu = 0, ua = 0;
  const double reach = 2 * smoothing_ratio * dp;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const V x = p.position[i];
    if (x[0] < reach || x[0] > length - reach || x[1] < reach || x[1] > length - reach) continue;
    const double u = p.velocity[i][0];
    uu += u * u;
    ua += u * (with[i][0] - without[i][0]);
  }
  return -ua / uu / (k * k);
}

}  // namespace

TEST_CASE("mixed resolution: a reference smoothing length gives the artificial viscosity one nu at every resolution",
          "[mixed_resolution]") {
  // Monaghan's artificial viscosity acts as a viscosity nu proportional to alpha h c0 (Monaghan 2005, Rep. Prog. Phys.
  // 68:1703, sec. 4.5): at twice the spacing a shear wave decays twice as fast. With FluidParameters::
  // viscosity_reference_smoothing_length = h_ref a pair uses alpha h_ref / h, so both resolutions get the nu of h_ref.
  // The two lattices resolve the wave with 20 and 40 spacings per wavelength; their fitted nu differ by the coarse
  // one's discretisation error, of the order of a centred difference's (k dp)^2 / 12 = 0.8 %: bound 3 %.
  const double coarse_h = 1.3 * coarse, fine_h = 1.3 * fine;
  const double nu_fine = shear_wave_viscosity(fine, 0);
  const double nu_coarse = shear_wave_viscosity(coarse, 0);
  const double nu_coarse_referred = shear_wave_viscosity(coarse, fine_h);
  INFO("nu: fine " << nu_fine << ", coarse " << nu_coarse << ", coarse with h_ref = fine h " << nu_coarse_referred
                   << " m^2/s");
  CHECK(nu_fine > 0);
  CHECK(nu_coarse / nu_fine == Approx(coarse_h / fine_h).epsilon(0.03));  // alpha alone: nu grows with h
  CHECK(nu_coarse_referred / nu_fine == Approx(1).epsilon(0.03));
  // h_ref equal to the particles' own h is the unscaled viscosity
  CHECK(shear_wave_viscosity(coarse, coarse_h) == Approx(nu_coarse).epsilon(1e-12));
  FluidParameters<2, double> bad;
  bad.viscosity_reference_smoothing_length = -0.01;
  CHECK_THROWS_WITH(bad.validate(),
                    Catch::Contains("viscosity_reference_smoothing_length") && Catch::Contains("[0, inf)"));
}

TEST_CASE("artificial viscosity: on receding pairs too it is the viscosity alpha h c0 / 8", "[viscosity]") {
  // FluidParameters::receding_pair_viscosity: Pi_ab on every pair, the delta-SPH viscous term (Antuono et al. 2010),
  // a viscous operator of nu = alpha h c0 / (2 (Dim + 2)) = alpha h c0 / 8 in 2D (Monaghan 2005, Rep. Prog. Phys.
  // 68:1703, sec. 4.5) in the continuum limit. Monaghan's switch acts on approaching pairs only: in a shear flow
  // u = (U sin(k y), 0) every pair (dx, dy) of the lattice has its mirror (-dx, dy) with the same velocity difference,
  // one approaching and one receding, so the switch gives exactly half the viscosity (to round-off).
  constexpr double alpha = 0.1, c0 = 20;  // shear_wave_viscosity's alpha and sound speed
  std::array<double, 3> relative_error{};
  const std::array<double, 3> ratios{1.3, 2.0, 3.0};
  for (std::size_t i = 0; i < ratios.size(); ++i) {
    const double nu_switch = shear_wave_viscosity(fine, 0, false, ratios[i]);
    const double nu_all = shear_wave_viscosity(fine, 0, true, ratios[i]);
    const double theory = alpha * ratios[i] * fine * c0 / 8;
    relative_error[i] = std::abs(nu_all / theory - 1);
    INFO("h/dp = " << ratios[i] << ": nu " << nu_switch << " with the switch, " << nu_all << " on every pair, theory "
                   << theory << " m^2/s");
    CHECK(nu_all / nu_switch == Approx(2).epsilon(1e-9));
  }
  // The lattice sum falls short of the continuum integral by a kernel-moment deficit that shrinks as the support holds
  // more particles (measured 20 %, 5.7 % and 3.3 % at h/dp = 1.3, 2 and 3; halving dp at fixed h/dp, which halves
  // k h, changes it by under 0.6 %): it must shrink with h/dp and be within 5 % at h/dp = 3.
  INFO("relative error against alpha h c0 / 8: " << relative_error[0] << ", " << relative_error[1] << ", "
                                                 << relative_error[2]);
  CHECK(relative_error[1] < relative_error[0]);
  CHECK(relative_error[2] < relative_error[1]);
  CHECK(relative_error[2] < 0.05);
}
