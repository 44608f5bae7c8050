// Tests of the elastic solid models (issue 3): material validation, conservation in a free body, no stress
// under rigid rotation, energy of the undamped plate, sub-cycling, clamps and the stability diagnostics.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/linear.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/solid_builders.hpp>
#include <sphfsi/solid/concepts.hpp>
#include <sphfsi/solid/elastic_material.hpp>
#include <sphfsi/solid/total_lagrangian.hpp>
#include <sphfsi/solid/updated_lagrangian.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace {

template <int Dim>
using SolidSystem = sphfsi::ParticleSystem<Dim, double, sphfsi::WendlandC2<Dim>, sphfsi::LinearEos<double>>;
template <int Dim>
using TL = sphfsi::TotalLagrangianSolid<SolidSystem<Dim>>;
template <int Dim>
using UL = sphfsi::UpdatedLagrangianSolid<SolidSystem<Dim>>;

static_assert(sphfsi::SolidModel<TL<2>, SolidSystem<2>> && sphfsi::SolidModel<UL<2>, SolidSystem<2>>);
static_assert(sphfsi::SolidModel<TL<3>, SolidSystem<3>> && sphfsi::SolidModel<UL<3>, SolidSystem<3>>);
static_assert(!sphfsi::SolidModel<sphfsi::ElasticMaterial<double>, SolidSystem<2>>);

const sphfsi::ElasticMaterial<double> rubber{.density = 1000, .youngs_modulus = 2e6, .poisson_ratio = 0.3975};

template <int Dim>
SolidSystem<Dim> make_system() {
  using V = sphfsi::Vec<Dim, double>;
  return SolidSystem<Dim>(sphfsi::Domain<Dim, double>(V::Constant(-1.0), V::Constant(1.0)),
                          sphfsi::LinearEos<double>(1000, 10));
}

template <class Model>
typename Model::Parameters free_parameters() {
  typename Model::Parameters p{};
  p.gravity.setZero();
  return p;
}

template <int Dim>
sphfsi::Vec<Dim, double> axis_z_cross(const sphfsi::Vec<Dim, double>& r, double omega) {
  sphfsi::Vec<Dim, double> v = sphfsi::Vec<Dim, double>::Zero();
  v[0] = -omega * r[1];
  v[1] = omega * r[0];
  return v;
}

/// Total linear momentum and z-angular momentum of the solid particles.
template <int Dim>
std::pair<sphfsi::Vec<Dim, double>, double> momenta(const SolidSystem<Dim>& s) {
  const auto& p = s.particles();
  sphfsi::Vec<Dim, double> P = sphfsi::Vec<Dim, double>::Zero();
  double Lz = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    P += p.mass[i] * p.velocity[i];
    Lz += p.mass[i] * (p.position[i][0] * p.velocity[i][1] - p.position[i][1] * p.velocity[i][0]);
  }
  return {P, Lz};
}

/// A free block (no clamp, no gravity) that translates, spins and carries an initial shear deformation.
/// angular_tolerance: relative change of L allowed (rounding for variational or corrected forces; < 0: not checked).
template <template <int> class ModelT, int Dim>
void check_free_body_conservation(const typename ModelT<Dim>::Parameters& params, double angular_tolerance) {
  using V = sphfsi::Vec<Dim, double>;
  auto system = make_system<Dim>();
  const double dp = 0.005;
  V hi = V::Constant(4 * dp);
  hi[0] = 8 * dp;
  sphfsi::add_solid_block(system, V::Zero(), hi, sphfsi::Resolution<double>{.dp = dp}, rubber);
  ModelT<Dim> solid(system, 0, rubber, params);
  auto& p = system.particles();
  const V centre = 0.5 * hi;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const V r = p.position[i] - centre;
    p.position[i][0] += 0.05 * r[1];  // simple shear of 5 %: the block starts out of equilibrium
    p.velocity[i] = axis_z_cross<Dim>(r, 20.0);
    p.velocity[i][0] += 0.3;
    p.velocity[i][1] -= 0.2;
  }
  const auto [P0, L0] = momenta(system);
  double t = 0;
  for (int s = 0; s < 40; ++s) {
    solid.advance(system, t, 2e-4);
    t += 2e-4;
  }
  const auto [P1, L1] = momenta(system);
  // Scales: |P| ~ M * 0.36 m/s, L ~ M * 20 rad/s * r^2; pair forces cancel exactly, so only rounding remains.
  const double M = solid.body_data().mass()[0] * double(p.size());
  INFO("P0 = " << P0.transpose() << " P1 = " << P1.transpose() << " L0 = " << L0 << " L1 = " << L1);
  CHECK((P1 - P0).norm() < 1e-12 * M);
  CHECK(solid.max_stretch() > 1.01);  // the body did deform (the test exercises the stress forces)
  if (angular_tolerance >= 0) CHECK(std::abs(L1 - L0) < angular_tolerance * std::abs(L0));
}

/// A block set spinning rigidly at omega: the only physical stress is the centripetal one, of order
/// rho omega^2 R^2; an inconsistent velocity gradient would add spurious stress of order G x angle.
template <template <int> class ModelT>
void check_rigid_rotation_is_stress_free(const typename ModelT<2>::Parameters& params) {
  using V = sphfsi::Vec<2, double>;
  auto system = make_system<2>();
  const double dp = 0.005, omega = 1.0;
  sphfsi::add_solid_block(system, V(0, 0), V(8 * dp, 4 * dp), sphfsi::Resolution<double>{.dp = dp}, rubber);
  ModelT<2> solid(system, 0, rubber, params);
  auto& p = system.particles();
  const V centre(4 * dp, 2 * dp);
  for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = axis_z_cross<2>(p.position[i] - centre, omega);
  solid.advance(system, 0.0, 0.3);  // 0.3 rad, about 10^4 sub-steps
  const double R = centre.norm(), centripetal = rubber.density * omega * omega * R * R;
  double sigma_max = 0;
  for (auto id : solid.particle_ids()) sigma_max = std::max(sigma_max, solid.cauchy_stress(id).norm());
  INFO("largest |sigma| = " << sigma_max << " Pa, rho omega^2 R^2 = " << centripetal
                            << " Pa, G = " << rubber.shear_modulus() << " Pa");
  CHECK(sigma_max < 5 * centripetal);
  // the body really turned by 0.3 rad
  const auto first = p.slot_of_id(0);
  const V r0 = solid.body_data().reference_position()[0] - centre, r1 = p.position[first] - centre;
  CHECK(std::atan2(r0.x() * r1.y() - r0.y() * r1.x(), r0.dot(r1)) == Approx(0.3).margin(0.01));
  if constexpr (requires { solid.reference_update_count(); })
    if (params.reference_update > 0) CHECK(solid.reference_update_count() >= 2);  // |R(0.3) - I| = 0.42
}

/// advance(t, dt) with n sub-steps must equal n calls of advance over dt / n (the external acceleration held).
template <template <int> class ModelT>
void check_sub_cycling_equals_single_steps() {
  using V = sphfsi::Vec<2, double>;
  auto make = [&]() {
    auto system = make_system<2>();
    sphfsi::add_solid_block(system, V(0, 0), V(0.04, 0.01), sphfsi::Resolution<double>{.dp = 0.0025}, rubber);
    for (std::size_t i = 0; i < system.particles().size(); ++i) system.particles().velocity[i] = V(0, 0.2 * i / 64.0);
    return system;
  };
  auto a = make(), b = make();
  typename ModelT<2>::Parameters params{};  // with gravity
  ModelT<2> sa(a, 0, rubber, params), sb(b, 0, rubber, params);
  sa.clamp_where([](const V& X) { return X.x() < 0.006; });
  sb.clamp_where([](const V& X) { return X.x() < 0.006; });
  const V external(0.5, -1.0);  // fluid force per unit mass, as a coupling would leave it
  auto set_external = [&](auto& s) {
    for (auto& acc : s.particles().acceleration) acc = external;
  };
  const double dt_solid = sa.solid_time_step();
  const double dt = 10 * 0.999 * dt_solid;
  set_external(a);
  sa.advance(a, 0.0, dt);
  CHECK(sa.sub_step_total() == 10);
  for (int k = 0; k < 10; ++k) {
    set_external(b);
    sb.advance(b, k * dt / 10, dt / 10);
  }
  CHECK(sb.sub_step_total() == 10);
  double diff = 0, moved = 0;
  for (std::size_t i = 0; i < a.particles().size(); ++i) {
    const auto j = b.particles().slot_of_id(a.particles().id[i]);
    diff = std::max(diff, (a.particles().position[i] - b.particles().position[j]).norm());
    moved = std::max(moved, (a.particles().position[i] - a.particles().position_old[i]).norm());
  }
  CHECK(moved > 0);
  CHECK(diff <= 1e-14);  // same arithmetic in the same order: equal to rounding
}
/// Starts a plate clamped at x = 0 (length L, spacing dp) in its first Euler-Bernoulli bending mode, kL = 1.875,
/// with tip speed V_f c0 = 0.01 c0 (Gray et al. 2001), and returns the ids of its tip column (x > L - dp).
std::vector<std::uint32_t> start_first_bending_mode(SolidSystem<2>& system, double L, double dp) {
  const double kL = 1.875, k = kL / L;
  const double M = std::sin(kL) + std::sinh(kL), N = std::cos(kL) + std::cosh(kL);
  const double Q = 2 * (std::cos(kL) * std::sinh(kL) - std::sin(kL) * std::cosh(kL));
  auto& p = system.particles();
  std::vector<std::uint32_t> tip;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.position[i].x();
    if (x > L - dp) tip.push_back(p.id[i]);
    if (x > 0)
      p.velocity[i].y() = 0.01 * rubber.sound_speed() *
                          (M * (std::cos(k * x) - std::cosh(k * x)) - N * (std::sin(k * x) - std::sinh(k * x))) / Q;
  }
  return tip;
}

/// Mean vertical position of the particles `tip` (by id), m.
double mean_tip_deflection(const SolidSystem<2>& system, const std::vector<std::uint32_t>& tip) {
  double y = 0;
  for (auto id : tip) y += system.particles().position[system.particles().slot_of_id(id)].y();
  return y / double(tip.size());
}

}  // namespace

TEST_CASE("Solid models: rigid rotation produces no stress", "[solid]") {
  check_rigid_rotation_is_stress_free<TL>(free_parameters<TL<2>>());
  check_rigid_rotation_is_stress_free<UL>(free_parameters<UL<2>>());
  auto updated = free_parameters<UL<2>>();
  updated.reference_update = 0.1;  // a new reference configuration every ~0.07 rad: the stress carries over
  check_rigid_rotation_is_stress_free<UL>(updated);
}

TEST_CASE("Solid models: sub-cycling equals single stepping", "[solid]") {
  check_sub_cycling_equals_single_steps<TL>();
  check_sub_cycling_equals_single_steps<UL>();
}

TEST_CASE("TLSPH: energy of the undamped oscillating plate stays within 2 % over 5 periods", "[solid]") {
  // Gray et al. (2001) plate at H/dp = 4 without viscosity or damping. Kinetic plus stored elastic energy is
  // conserved by the variational forces and the symplectic sub-steps; the only non-conservative term is the
  // hourglass penalty (alpha_hg = 0.1), whose work is bounded by its small share of the stiffness.
  using V = sphfsi::Vec<2, double>;
  auto system = make_system<2>();
  const double L = 0.2, H = 0.02, dp = H / 4;
  sphfsi::add_solid_block(system, V(-3 * dp, -H / 2), V(L, H / 2), sphfsi::Resolution<double>{.dp = dp}, rubber);
  sphfsi::TotalLagrangianParameters<2, double> params{};
  params.gravity.setZero();
  TL<2> solid(system, 0, rubber, params);
  solid.clamp_where([](const V& X) { return X.x() < 0; });
  start_first_bending_mode(system, L, dp);
  solid.compute_rates(system, 0.0);
  const double e0 = solid.kinetic_energy() + solid.strain_energy();
  double lo = 1, hi = 1, t = 0;
  const double frame = 2e-3;
  while (t < 5 * 0.2541) {
    solid.advance(system, t, frame);
    t += frame;
    const double e = (solid.kinetic_energy() + solid.strain_energy()) / e0;
    lo = std::min(lo, e);
    hi = std::max(hi, e);
  }
  INFO("E/E0 in [" << lo << ", " << hi << "]");
  CHECK(lo > 0.98);
  CHECK(hi < 1.02);
  CHECK(solid.max_stretch() < 1.1);  // the plate stays intact
}

TEST_CASE("Solid models: clamps hold, blow-ups and tearing stop the run with a clear message", "[solid]") {
  using V = sphfsi::Vec<2, double>;
  auto system = make_system<2>();
  sphfsi::add_solid_block(system, V(0, 0), V(0.04, 0.01), sphfsi::Resolution<double>{.dp = 0.0025}, rubber);
  TL<2> solid(system, 0, rubber);  // default gravity -9.81 m/s^2
  REQUIRE(solid.clamp_where([](const V& X) { return X.x() < 0.006; }) == 8);
  const auto X = solid.body_data().reference_position();
  solid.advance(system, 0.0, 0.01);
  const auto& p = system.particles();
  double sag = 0;
  for (std::size_t k = 0; k < X.size(); ++k) {
    const auto i = p.slot_of_id(solid.particle_ids()[k]);
    if (solid.body_data().is_clamped(k)) CHECK((p.position[i] - X[k]).norm() == 0.0);
    else sag += p.position[i].y() - X[k].y();
  }
  CHECK(sag < 0);  // the free part sags under gravity
  // NaN velocity: BlowUpError naming the particle id, the quantity and the time; the particle set keeps the
  // last good state (the other particles have not moved).
  auto& q = system.particles();
  const auto before = q.position[q.slot_of_id(5)];
  q.velocity[q.slot_of_id(20)].x() = std::nan("");
  CHECK_THROWS_WITH(solid.advance(system, 0.01, 1e-4),
                    Catch::Contains("particle id 20") && Catch::Contains("position") && Catch::Contains("t = 0.01"));
  CHECK(q.position[q.slot_of_id(5)] == before);
  // Tearing: a body pulled apart beyond the stretch limit.
  auto torn = make_system<2>();
  sphfsi::add_solid_block(torn, V(0, 0), V(0.04, 0.01), sphfsi::Resolution<double>{.dp = 0.0025}, rubber);
  sphfsi::UpdatedLagrangianParameters<2, double> up{};
  up.gravity.setZero();
  up.stretch_limit = 1.5;
  UL<2> ul(torn, 0, rubber, up);
  for (std::size_t i = 0; i < torn.particles().size(); ++i)
    torn.particles().velocity[i] = V(torn.particles().position[i].x() > 0.02 ? 50.0 : -50.0, 0);
  CHECK_THROWS_WITH(ul.advance(torn, 0.0, 2e-4), Catch::Contains("stretch") && Catch::Contains("tore"));
}

TEST_CASE("ElasticMaterial: derived moduli and input validation", "[solid]") {
  const auto m = rubber;
  REQUIRE_NOTHROW(m.validate());
  CHECK(m.shear_modulus() == Approx(2e6 / (2 * 1.3975)).epsilon(1e-14));
  CHECK(m.bulk_modulus() == Approx(2e6 / (3 * (1 - 0.795))).epsilon(1e-14));
  // K = lambda + 2 G / 3 and c0^2 = K / rho (Gray et al. 2001) are the same constants written two ways.
  CHECK(m.lame_lambda() + 2.0 / 3.0 * m.shear_modulus() == Approx(m.bulk_modulus()).epsilon(1e-12));
  CHECK(m.sound_speed() == Approx(std::sqrt(m.bulk_modulus() / 1000)).epsilon(1e-14));
  // Plane stress through the plane-strain solids: same G, lambda* = E nu / (1 - nu^2), and the 2D plate modulus
  // (E* / (1 - nu*^2) of the equivalent material) is E itself.
  const auto ps = m.plane_stress_equivalent();
  const double nu = m.poisson_ratio, E = m.youngs_modulus;
  CHECK(ps.shear_modulus() == Approx(m.shear_modulus()).epsilon(1e-14));
  CHECK(ps.lame_lambda() == Approx(E * nu / (1 - nu * nu)).epsilon(1e-13));
  CHECK(ps.plane_strain_modulus() == Approx(E).epsilon(1e-13));
  CHECK(ps.density == m.density);
  auto bad = m;
  bad.youngs_modulus = 0;
  CHECK_THROWS_AS(bad.validate(), sphfsi::InputError);
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("youngs_modulus") && Catch::Contains("(0, inf)"));
  bad = m;
  bad.density = -1;
  CHECK_THROWS_AS(bad.validate(), sphfsi::InputError);
  bad = m;
  bad.poisson_ratio = 0.5;
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("poisson_ratio") && Catch::Contains("(-1, 0.5)"));
  bad.poisson_ratio = -1;
  CHECK_THROWS_AS(bad.validate(), sphfsi::InputError);
  auto system = make_system<2>();
  sphfsi::add_solid_block(system, sphfsi::Vec<2, double>(0, 0), sphfsi::Vec<2, double>(0.02, 0.01),
                          sphfsi::Resolution<double>{.dp = 0.005}, rubber);
  CHECK_THROWS_AS(TL<2>(system, 0, bad), sphfsi::InputError);
  CHECK_THROWS_AS(UL<2>(system, 0, bad), sphfsi::InputError);
  CHECK_THROWS_WITH(TL<2>(system, 7, rubber), Catch::Contains("body 7 has no particles"));
  sphfsi::TotalLagrangianParameters<2, double> tl_bad{};
  tl_bad.cfl = 2;
  CHECK_THROWS_WITH(TL<2>(system, 0, rubber, tl_bad), Catch::Contains("cfl"));
  sphfsi::UpdatedLagrangianParameters<2, double> ul_bad{};
  ul_bad.formulation = static_cast<sphfsi::UpdatedLagrangianFormulation>(7);
  CHECK_THROWS_WITH(UL<2>(system, 0, rubber, ul_bad), Catch::Contains("formulation = 7"));
  ul_bad = {};
  ul_bad.reference_update = -1;
  CHECK_THROWS_WITH(UL<2>(system, 0, rubber, ul_bad), Catch::Contains("reference_update"));
}

TEST_CASE("Solid models conserve momentum in a free, spinning, deformed body", "[solid]") {
  // TLSPH is the gradient of a rotation-invariant energy, and the corrected ULSPH force has
  // sum_b V_b x_ba (x) g_ab = I with a symmetric stress (Bonet & Lok 1999): angular momentum to rounding. The
  // artificial viscosity and the hourglass penalty act along the bond (central). The original GMS scheme
  // conserves linear momentum only: its pair force (sigma_a/rho_a^2 + sigma_b/rho_b^2) . grad is not central, and
  // its uncorrected velocity gradient turns the spin (20 rad/s) into spurious strain at the free surfaces, so the
  // angular momentum of this block changes by 35 % (2D) and 74 % (3D) in 8 ms: not checked.
  auto gms = free_parameters<UL<2>>();
  gms.formulation = sphfsi::UpdatedLagrangianFormulation::gray_monaghan_swift;
  gms.artificial_stress = 0.3;
  auto gms3 = free_parameters<UL<3>>();
  gms3.formulation = sphfsi::UpdatedLagrangianFormulation::gray_monaghan_swift;
  check_free_body_conservation<TL, 2>(free_parameters<TL<2>>(), 1e-12);
  check_free_body_conservation<UL, 2>(free_parameters<UL<2>>(), 1e-12);
  check_free_body_conservation<UL, 2>(gms, -1);
  check_free_body_conservation<TL, 3>(free_parameters<TL<3>>(), 1e-12);
  check_free_body_conservation<UL, 3>(free_parameters<UL<3>>(), 1e-12);
  check_free_body_conservation<UL, 3>(gms3, -1);
}

TEST_CASE("TLSPH: quadratic gradient correction makes F exact for a quadratic deformation, surfaces included",
          "[solid]") {
  // x = X + u with u quadratic in X: F = I + grad u is affine and must be reproduced at every particle (corners
  // and free surfaces too), to rounding. The Bonet-Lok weights alone are exact only in the symmetric interior.
  using V = sphfsi::Vec<2, double>;
  auto run = [](bool quadratic) {
    auto system = make_system<2>();
    sphfsi::add_solid_block(system, V(0, -0.01), V(0.06, 0.01), sphfsi::Resolution<double>{.dp = 0.005}, rubber);
    auto params = free_parameters<TL<2>>();
    params.quadratic_correction = quadratic;
    TL<2> solid(system, 0, rubber, params);
    auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      const V X = p.position[i];
      p.position[i] += V(X.x() * X.y() + 0.3 * X.y() * X.y(), 0.5 * X.x() * X.x() + 0.2 * X.x() * X.y());
    }
    solid.advance(system, 0.0, 1e-12);  // evaluates F at (essentially) this configuration
    double error = 0;
    for (auto id : solid.particle_ids()) {
      const V X = solid.body_data().reference_position()[static_cast<std::size_t>(solid.body_data().local_index(id))];
      sphfsi::Mat<2, double> F;
      F << 1 + X.y(), X.x() + 0.6 * X.y(), X.x() + 0.2 * X.y(), 1 + 0.2 * X.x();
      error = std::max(error, (solid.deformation_gradient(id) - F).norm());
    }
    return std::pair{error, solid.quadratic_particle_count()};
  };
  const auto [quadratic_error, count] = run(true);
  const auto [linear_error, none] = run(false);
  CHECK(count == 48);
  CHECK(none == 0);
  CHECK(quadratic_error < 1e-9);  // displacement gradients are O(0.06); the step of 1e-12 s moves nothing
  CHECK(linear_error > 1e-3);     // O(dp) error at the surface rows: the cause of the too soft plate
}

TEST_CASE("TLSPH: clamp_by_reflection needs a mirror particle for every clamped particle", "[solid]") {
  using V = sphfsi::Vec<2, double>;
  auto system = make_system<2>();
  sphfsi::add_solid_block(system, V(-0.01, 0), V(0.02, 0.01), sphfsi::Resolution<double>{.dp = 0.0025}, rubber);
  TL<2> solid(system, 0, rubber);
  CHECK(solid.clamp_by_reflection(V(0, 0), V(1, 0)) == 16);  // 4 columns x 4 rows behind x = 0
  TL<2> shifted(system, 0, rubber);
  CHECK_THROWS_WITH(shifted.clamp_by_reflection(V(0.001, 0), V(1, 0)), Catch::Contains("mirror"));
}

TEST_CASE("TLSPH: oscillating plate period at H/dp = 4 within 4 % of Euler-Bernoulli", "[solid]") {
  // Gray et al. (2001) plate, L = 0.2, H = 0.02, plane strain, clamped by reflection at x = 0. With exact
  // gradients the remaining error is the midpoint quadrature of the second moment of area (sum of y^2 dp over
  // N = 4 rows = I (1 - 1/N^2): +3.1 % on the period) plus shear and rotary inertia (+0.7 % at L/H = 10): the
  // example measures +3.74 %. The run is deterministic; the 0.26 % margin covers the coarser sampling here.
  // Before the fix (Bonet-Lok weights only, wall part held at rest) the same plate gave +29 %.
  using V = sphfsi::Vec<2, double>;
  auto system = make_system<2>();
  const double L = 0.2, H = 0.02, dp = H / 4, kL = 1.875, k = kL / L;
  sphfsi::add_solid_block(system, V(-3 * dp, -H / 2), V(L, H / 2), sphfsi::Resolution<double>{.dp = dp}, rubber);
  auto params = free_parameters<TL<2>>();
  TL<2> solid(system, 0, rubber, params);
  REQUIRE(solid.clamp_by_reflection(V(0, 0), V(1, 0)) == 12);
  const std::vector<std::uint32_t> tip = start_first_bending_mode(system, L, dp);
  auto w = [&]() { return mean_tip_deflection(system, tip); };
  const double Ep = rubber.plane_strain_modulus();
  const double period = 2 * std::numbers::pi / std::sqrt(Ep * H * H * k * k * k * k / (12 * rubber.density));
  const double frame = period / 200;
  std::vector<double> crossings;
  double t = 0, w_prev = w();
  for (int s = 0; s < 330; ++s) {  // 1.65 periods: crossings at about T/2, T, 3T/2
    solid.advance(system, t, frame);
    t += frame;
    const double w_now = w();
    if (s > 0 && (w_prev < 0) != (w_now < 0)) crossings.push_back(t - frame * w_now / (w_now - w_prev));
    w_prev = w_now;
  }
  REQUIRE(crossings.size() >= 3);
  const double measured = 2 * (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  const double error = (measured - period) / period;
  INFO("period " << measured << " s, Euler-Bernoulli " << period << " s, error " << 100 * error << " %");
  CHECK(error > 0.03);  // the quadrature deficit alone is +3.1 %: a smaller error would hide a new bias
  CHECK(error < 0.04);
}

namespace {
/// Result of an undamped oscillating-plate run (Gray et al. 2001 set-up, V_f = 0.01, clamped by reflection at x = 0).
struct PlateRun {
  double period_error;    ///< (measured - Euler-Bernoulli) / Euler-Bernoulli, from the zero crossings
  double energy_low = 1;  ///< smallest (kinetic + stored) / initial
  double energy_high = 1;
  double max_stretch = 1;
};

/// Runs a plate of length L and thickness 0.02 m with n particles across for `periods` Euler-Bernoulli periods,
/// sampling the mean tip deflection and the energy every T/200.
template <class Model>
PlateRun run_plate(typename Model::Parameters params, double L, int n, double periods) {
  using V = sphfsi::Vec<2, double>;
  auto system = make_system<2>();
  const double H = 0.02, dp = H / n, kL = 1.875, k = kL / L;
  sphfsi::add_solid_block(system, V(-3 * dp, -H / 2), V(L, H / 2), sphfsi::Resolution<double>{.dp = dp}, rubber);
  params.gravity.setZero();
  Model solid(system, 0, rubber, params);
  REQUIRE(solid.clamp_by_reflection(V(0, 0), V(1, 0)) == std::size_t(3 * n));
  const std::vector<std::uint32_t> tip = start_first_bending_mode(system, L, dp);
  auto w = [&]() { return mean_tip_deflection(system, tip); };
  solid.compute_rates(system, 0.0);
  const double e0 = solid.kinetic_energy() + solid.strain_energy();
  const double Ep = rubber.plane_strain_modulus();
  const double period = 2 * std::numbers::pi / std::sqrt(Ep * H * H * k * k * k * k / (12 * rubber.density));
  const double frame = period / 200;
  std::vector<double> crossings;
  PlateRun run{};
  double t = 0, w_prev = w();
  for (int s = 0; s < int(std::lround(periods * 200)); ++s) {
    solid.advance(system, t, frame);
    t += frame;
    const double w_now = w();
    if (s > 0 && (w_prev < 0) != (w_now < 0)) crossings.push_back(t - frame * w_now / (w_now - w_prev));
    w_prev = w_now;
    const double e = (solid.kinetic_energy() + solid.strain_energy()) / e0;
    run.energy_low = std::min(run.energy_low, e);
    run.energy_high = std::max(run.energy_high, e);
    run.max_stretch = std::max(run.max_stretch, solid.max_stretch());
  }
  REQUIRE(crossings.size() >= 3);
  const double measured = 2 * (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  run.period_error = (measured - period) / period;
  return run;
}
}  // namespace

TEST_CASE("ULSPH: oscillating plate period at H/dp = 4 within 4 % of Euler-Bernoulli", "[solid]") {
  // The corrected formulation (quadratic-consistent weights on the reference configuration of the kernel sums,
  // compatible force, reflected clamp) has the same remaining errors as the TLSPH plate: the midpoint quadrature
  // of the second moment of area (+3.1 % on the period at N = 4) and shear / rotary inertia (+0.7 %): the example
  // measures +3.73 %. The original GMS sums gave +40 % here. Default artificial viscosity (alpha = 0.5).
  const auto run = run_plate<UL<2>>(free_parameters<UL<2>>(), 0.2, 4, 1.65);
  INFO("period error " << 100 * run.period_error << " %, max stretch " << run.max_stretch);
  CHECK(run.period_error > 0.03);  // the quadrature deficit alone is +3.1 %: a smaller error would hide a new bias
  CHECK(run.period_error < 0.04);
  CHECK(run.max_stretch < 1.05);  // bending strain of the outer fibres at V_f = 0.01 is about 3 %
}

TEST_CASE("ULSPH: energy of the undamped oscillating plate stays within 1 % over 5 periods", "[solid]") {
  // A plate of half the length (period T/4, so 5 periods are cheap) at H/dp = 4, no artificial viscosity or
  // damping. Kinetic plus stored energy (S:S/4G + p^2/2K) is what the rates conserve: the force is compatible
  // with the velocity gradient (its power is minus the stress power) and the kick-drift-kick step is
  // second order; what remains is the hourglass penalty (not derived from an energy, alpha_hg = 0.1) and the
  // O(strain) difference between the hypoelastic stored energy and the work of the forces. The 1 % band is the order of
  // the strain (3 %) times alpha_hg (0.1) times 3 for the shape of the mode, and a leak of 1 % per 5 periods would show
  // as 0.2 % amplitude decay per period. Measured: E/E0 in [0.9983, 1.0000].
  auto params = free_parameters<UL<2>>();
  params.artificial_viscosity = 0;
  const auto run = run_plate<UL<2>>(params, 0.1, 4, 5);
  INFO("E/E0 in [" << run.energy_low << ", " << run.energy_high << "], max stretch " << run.max_stretch);
  CHECK(run.energy_low > 0.99);
  CHECK(run.energy_high < 1.01);
  CHECK(run.max_stretch < 1.1);  // the plate stays intact
}
