// Oscillating cantilever plate (Gray, Monaghan & Swift 2001, CMAME 190:6641, sec. 6; validation-cases.md sec. 2)
// and the static cantilever under its own weight, with either solid model.
//
//   oscillating_plate [--model tl|ul] [--resolution H/dp] [--vf V_f] [--periods n] [--output file.csv]
//   oscillating_plate --sag [--model tl|ul] [--resolution H/dp] [--youngs E] [--damping c_d] [--end t]
//
// Plate: L = 0.2 m, H = 0.02 m, rho = 1000 kg/m^3, E = 2 MPa, nu = 0.3975, plane strain; the part x < 0
// (as long as the kernel support) is clamped, as if embedded in a wall. Initial transverse velocity of the first
// bending mode, v_y(x) = V_f c0 [M (cos kx - cosh kx) - N (sin kx - sinh kx)] / Q with kL = 1.875. The period
// (from zero crossings of the tip deflection) is compared with Euler-Bernoulli in plane strain,
// omega^2 = E' H^2 k^4 / (12 rho), E' = E / (1 - nu^2); the amplitude decay per period is reported.
// Sag: the plate starts at rest under gravity with velocity damping c_d until static; the tip deflection is
// compared with w(x) = q x^2 (6 L^2 - 4 L x + x^2) / (24 E' I), q = rho g H, I = H^3 / 12 (w(L) = q L^4 / (8 E' I)),
// evaluated at the tip particles' x.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/linear.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/solid_builders.hpp>
#include <sphfsi/solid/concepts.hpp>
#include <sphfsi/solid/total_lagrangian.hpp>
#include <sphfsi/solid/updated_lagrangian.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

using T = double;
using Vector = sphfsi::Vec<2, T>;
using System = sphfsi::ParticleSystem<2, T, sphfsi::WendlandC2<2>, sphfsi::LinearEos<T>>;

struct Options {
  std::string model = "tl";
  int resolution = 6;              // particles across the thickness H
  T vf = 0.01;                     // amplitude factor V_f
  T periods = 3;                   // simulated time in Euler-Bernoulli periods
  bool sag = false;                // static cantilever under gravity instead of the free oscillation
  T youngs = -1;                   // E, Pa (default 2e6 for the plate, 2e7 for the sag)
  T damping = -1;                  // c_d, 1/s (default 0 for the plate, the first-mode omega for the sag)
  T end_time = -1;                 // s (sag)
  T hourglass = 0.1;               // TLSPH alpha_hg
  T h_ratio = 1.3;                 // h / dp
  T cfl = 0.3;                     // solid CFL number
  bool fixed_clamp = false;        // hold the wall part at rest instead of the reflected clamp
  bool linear_correction = false;  // Bonet-Lok gradient (exact for linear fields only) everywhere
  bool gms = false;                // ULSPH: the original Gray-Monaghan-Swift sums (no correction)
  T viscosity = -1;                // artificial viscosity alpha (default 0 TL, 0.5 UL)
  T reference_update = 0;          // ULSPH (corrected): new kernel reference once max |F - I| exceeds this
  T artificial_stress = -1;        // ULSPH: epsilon of the artificial stress (default 0 corrected, 0.3 GMS)
  std::string output = "oscillating_plate.csv";
};

constexpr T L = 0.2, H = 0.02, rho = 1000, nu = 0.3975, kL = 1.875;

void print_help() {
  fmt::print(
      "oscillating_plate: Gray, Monaghan & Swift (2001) cantilever plate with an elastic SPH solid\n"
      "  --model tl|ul       total-Lagrangian (default) or updated-Lagrangian (Gray et al.) solid\n"
      "  --resolution N      particles across the thickness H = 0.02 m (default 6)\n"
      "  --vf V              amplitude factor V_f of the initial velocity (default 0.01)\n"
      "  --periods n         simulated time in Euler-Bernoulli periods (default 3)\n"
      "  --sag               static cantilever under its own weight instead (damped to rest)\n"
      "  --youngs E          Young's modulus, Pa (default 2e6; 2e7 with --sag)\n"
      "  --damping c         velocity damping, 1/s (default 0; the first-mode omega with --sag)\n"
      "  --end t             end time, s (sag, default 12 first-mode periods)\n"
      "  --hourglass a       hourglass coefficient of TLSPH and corrected ULSPH (default 0.1)\n"
      "  --fixed-clamp       wall part held at rest (default: clamped by odd reflection at x = 0)\n"
      "  --linear-correction Bonet-Lok gradient correction only (no quadratic correction)\n"
      "  --gms               ULSPH: the original Gray, Monaghan & Swift (2001) sums (the paper's eq. 13)\n"
      "  --artificial-stress e  ULSPH: epsilon of Monaghan's artificial stress (default 0; 0.3 with --gms)\n"
      "  --reference-update d   ULSPH: new kernel reference configuration once max |F - I| > d (default 0: never)\n"
      "  --h-ratio r         smoothing length over particle spacing (default 1.3)\n"
      "  --cfl c             solid CFL number (default 0.3)\n"
      "  --viscosity a       artificial viscosity alpha (default 0 for tl, 0.5 for ul)\n"
      "  --output file.csv   time series t, tip deflection, energies, max stretch\n");
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw sphfsi::InputError(fmt::format("option {} needs a value", a));
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      print_help();
      std::exit(0);
    } else if (a == "--model") o.model = value();
    else if (a == "--resolution") o.resolution = std::stoi(value());
    else if (a == "--vf") o.vf = std::stod(value());
    else if (a == "--periods") o.periods = std::stod(value());
    else if (a == "--sag") o.sag = true;
    else if (a == "--youngs") o.youngs = std::stod(value());
    else if (a == "--damping") o.damping = std::stod(value());
    else if (a == "--end") o.end_time = std::stod(value());
    else if (a == "--hourglass") o.hourglass = std::stod(value());
    else if (a == "--h-ratio") o.h_ratio = std::stod(value());
    else if (a == "--cfl") o.cfl = std::stod(value());
    else if (a == "--gms") o.gms = true;
    else if (a == "--artificial-stress") o.artificial_stress = std::stod(value());
    else if (a == "--reference-update") o.reference_update = std::stod(value());
    else if (a == "--linear-correction") o.linear_correction = true;
    else if (a == "--fixed-clamp") o.fixed_clamp = true;
    else if (a == "--viscosity") o.viscosity = std::stod(value());
    else if (a == "--output") o.output = value();
    else throw sphfsi::InputError(fmt::format("unknown option {} (see --help)", a));
  }
  if (o.model != "tl" && o.model != "ul")
    throw sphfsi::InputError(fmt::format("--model = {} is invalid: valid values are tl, ul", o.model));
  sphfsi::require_in_range("--resolution (H/dp)", o.resolution, 2, 64);
  sphfsi::require_in_range("--vf", o.vf, T(0), T(0.2));
  sphfsi::require_positive("--periods", o.periods);
  if (o.youngs < 0) o.youngs = o.sag ? 2e7 : 2e6;
  if (o.viscosity < 0) o.viscosity = o.model == "ul" ? 0.5 : 0.0;
  if (o.artificial_stress < 0) o.artificial_stress = o.gms ? 0.3 : 0.0;
  return o;
}

/// First-mode Euler-Bernoulli angular frequency in plane strain, rad/s.
T bending_omega(const sphfsi::ElasticMaterial<T>& m) {
  const T k = kL / L;
  return std::sqrt(m.plane_strain_modulus() * H * H * k * k * k * k / (12 * rho));
}

template <class Model>
int run(const Options& o) {
  const sphfsi::ElasticMaterial<T> material{.density = rho, .youngs_modulus = o.youngs, .poisson_ratio = nu};
  const T dp = H / o.resolution;
  const sphfsi::Resolution<T> res{.dp = dp, .smoothing_ratio = o.h_ratio};
  const T clamp_length = std::ceil(2 * res.h() / dp) * dp;  // one kernel support inside the wall
  System system(sphfsi::Domain<2, T>(Vector(-0.1, -0.3), Vector(0.4, 0.3)), sphfsi::LinearEos<T>(rho, 10));
  sphfsi::add_solid_block(system, Vector(-clamp_length, -H / 2), Vector(L, H / 2), res, material, 0);

  const T omega = bending_omega(material), period = 2 * std::numbers::pi / omega;
  typename Model::Parameters params{};
  params.gravity = o.sag ? Vector(0, -9.81) : Vector(0, 0);
  params.artificial_viscosity = o.viscosity;
  params.cfl = o.cfl;
  params.damping = o.damping >= 0 ? o.damping : (o.sag ? omega : T(0));
  if constexpr (requires { params.hourglass; }) params.hourglass = o.hourglass;
  if constexpr (requires { params.quadratic_correction; }) params.quadratic_correction = !o.linear_correction;
  if constexpr (requires { params.formulation; }) {
    params.formulation = o.gms ? sphfsi::UpdatedLagrangianFormulation::gray_monaghan_swift
                               : sphfsi::UpdatedLagrangianFormulation::corrected;
    params.artificial_stress = o.artificial_stress;
    params.reference_update = o.reference_update;
    params.quadratic_correction = !o.linear_correction;
  }
  Model solid(system, 0, material, params);
  static_assert(sphfsi::SolidModel<Model, System>);
  std::size_t clamped = 0;
  if constexpr (requires { solid.clamp_by_reflection(Vector(0, 0), Vector(1, 0)); })
    if (!o.fixed_clamp) clamped = solid.clamp_by_reflection(Vector(0, 0), Vector(1, 0));
  if (!clamped) clamped = solid.clamp_where([](const Vector& X) { return X.x() < 0; });

  // Initial velocity of the first bending mode (zero in the sag case).
  auto& p = system.particles();
  const T c0 = material.sound_speed(), k = kL / L;
  const T M = std::sin(kL) + std::sinh(kL), N = std::cos(kL) + std::cosh(kL);
  const T Q = 2 * (std::cos(kL) * std::sinh(kL) - std::sin(kL) * std::cosh(kL));
  std::vector<std::uint32_t> tip;
  T x_tip = -1;
  for (std::size_t i = 0; i < p.size(); ++i) x_tip = std::max(x_tip, p.position[i].x());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const T x = p.position[i].x();
    if (x > x_tip - 0.5 * dp) tip.push_back(p.id[i]);
    if (o.sag || x < 0) continue;
    p.velocity[i].y() =
        o.vf * c0 * (M * (std::cos(k * x) - std::cosh(k * x)) - N * (std::sin(k * x) - std::sinh(k * x))) / Q;
  }
  auto tip_deflection = [&]() {
    T y = 0;
    for (auto id : tip) y += system.particles().position[system.particles().slot_of_id(id)].y();
    return y / T(tip.size());
  };
  const T y0 = tip_deflection();

  const T sample = period / 200;
  const T end_time = o.sag ? (o.end_time > 0 ? o.end_time : 12 * period) : o.periods * period;
  sphfsi::FluidParameters<2, T> fluid{};
  sphfsi::Simulation<System, sphfsi::SymplecticVerlet, Model> sim(
      system, fluid, sphfsi::TimeStepParameters<T>{.max_dt = sample}, std::move(solid));
  auto& model = sim.template model<0>();
  model.compute_rates(system, T(0));  // reads the initial velocities into the model (energies of row 0)

  auto csv = fmt::output_file(o.output);
  // Internal energy: the stored strain energy (TLSPH) or the work of the stresses (ULSPH, see stress_work()).
  auto internal_energy = [&]() {
    if constexpr (requires { model.stress_work(); }) return model.stress_work();
    else return model.strain_energy();
  };
  csv.print("t,tip_deflection,kinetic_energy,internal_energy,max_stretch\n");
  std::vector<T> t_series{0}, w_series{0};
  csv.print("{:.6e},{:.6e},{:.6e},{:.6e},{:.6f}\n", 0.0, 0.0, model.kinetic_energy(), internal_energy(), 1.0);
  T stretch_max = 1;
  const auto start = std::chrono::steady_clock::now();
  sim.run(end_time, [&](auto& s) {
    const T w = tip_deflection() - y0;
    const T stretch = model.max_stretch();
    stretch_max = std::max(stretch_max, stretch);
    t_series.push_back(s.time());
    w_series.push_back(w);
    csv.print("{:.6e},{:.6e},{:.6e},{:.6e},{:.6f}\n", s.time(), w, model.kinetic_energy(), internal_energy(), stretch);
  });
  const T seconds = std::chrono::duration<T>(std::chrono::steady_clock::now() - start).count();
  csv.close();
  if constexpr (requires { model.reference_update_count(); })
    if (model.reference_update_count() > 0) fmt::print("reference updates: {}\n", model.reference_update_count());

  fmt::print(
      "model {} | H/dp = {} | dp = {:.4g} m | particles {} ({} clamped) | solid dt = {:.3g} s | "
      "sub-steps {} | wall time {:.2f} s\n",
      o.model, o.resolution, dp, p.size(), clamped, model.solid_time_step(), model.sub_step_total(), seconds);
  if (o.sag) {
    const T q = rho * 9.81 * H, I = H * H * H / 12, Ep = material.plane_strain_modulus();
    const T xt = x_tip;
    const T w_theory = q * xt * xt * (6 * L * L - 4 * L * xt + xt * xt) / (24 * Ep * I);
    const T w = -w_series.back();
    fmt::print(
        "sag: E = {:.3g} Pa, c_d = {:.3g} 1/s, t_end = {:.3g} s: tip deflection {:.5e} m, beam theory "
        "(x = {:.4g} m) {:.5e} m, error {:+.2f} %, last-sample tip speed {:.2e} m/s\n",
        o.youngs, params.damping, end_time, w, xt, w_theory, 100 * (w - w_theory) / w_theory,
        std::abs(w_series.back() - w_series[w_series.size() - 2]) / sample);
    return 0;
  }
  // Zero crossings in both directions after the start (linear interpolation) -> half periods; positive
  // peaks -> decay per period. The first sample (w = 0 exactly, at t = 0) is not a crossing.
  std::vector<T> crossings, peaks;
  for (std::size_t i = 2; i < w_series.size(); ++i) {
    if ((w_series[i - 1] < 0) != (w_series[i] < 0))
      crossings.push_back(t_series[i - 1] +
                          (t_series[i] - t_series[i - 1]) * (-w_series[i - 1]) / (w_series[i] - w_series[i - 1]));
    if (i + 1 < w_series.size() && w_series[i] > 0 && w_series[i] >= w_series[i - 1] && w_series[i] > w_series[i + 1])
      peaks.push_back(w_series[i]);
  }
  if (crossings.size() < 3) {
    fmt::print("not enough oscillations to measure a period (run longer: --periods)\n");
    return 1;
  }
  const T measured = 2 * (crossings.back() - crossings.front()) / T(crossings.size() - 1);
  const std::size_t half_periods = crossings.size() - 1;
  T decay = 0;
  if (peaks.size() >= 2) decay = 1 - std::pow(peaks.back() / peaks.front(), 1 / T(peaks.size() - 1));
  fmt::print(
      "V_f = {} | period {:.5f} s (from {} half periods) | Euler-Bernoulli {:.5f} s | error {:+.2f} % | "
      "first amplitude {:.4e} m | decay per period {:.2f} % | max stretch {:.4f}\n",
      o.vf, measured, half_periods, period, 100 * (measured - period) / period, peaks.empty() ? 0.0 : peaks.front(),
      100 * decay, stretch_max);
  return 0;
}

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    if (o.model == "tl") return run<sphfsi::TotalLagrangianSolid<System>>(o);
    return run<sphfsi::UpdatedLagrangianSolid<System>>(o);
  } catch (const std::exception& e) {
    fmt::print(stderr, "oscillating_plate: {}\n", e.what());
    return 2;
  }
}
