// Validation runs of the planar elastic rod (solid/elastic_rod.hpp, issue 6; docs/thin-blades.md).
//
//   elastic_rod --case static    [--nodes n] [--load alpha]   cantilever under a dead tip load P, alpha = P L^2/(EI),
//                                                             against the elastica (RK4 shooting); n or alpha 0: sweep
//   elastic_rod --case vibration [--nodes n]                  first bending period against Euler-Bernoulli,
//                                                             T1 = 2 pi / (1.8751^2 sqrt(EI / (rho A L^4)))
//   elastic_rod --case subcycle  [--nodes n] [--ratio r]      real Posidonia blade (Table 3 of the reference paper:
//                                                             t = 0.1 mm, E = 4.7e8 Pa, rho = 910 kg/m^3) in an
//                                                             oscillatory current: outer step r rod steps vs 1
// Every case writes a CSV (--output) for plot.py.
#include <sphfsi/analysis/elastica.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/eos/linear.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/solid/elastic_rod.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

using T = double;
using V = sphfsi::Vec<2, T>;
using System = sphfsi::ParticleSystem<2, T, sphfsi::WendlandC2<2>, sphfsi::LinearEos<T>>;
using Rod = sphfsi::ElasticRod<System>;

namespace {

System make_system() { return System(sphfsi::Domain<2, T>(V(-1, -1), V(1, 1)), sphfsi::LinearEos<T>(1000, 10)); }

// Test blade of the static and vibration cases: L/t = 100 (axial strain at alpha = 10: 8e-5).
constexpr T L = 0.1;
const sphfsi::ElasticMaterial<T> blade{.density = 1000, .youngs_modulus = 1e7, .poisson_ratio = 0.3};
const sphfsi::RodSection<T> section{.thickness = 1e-3, .width = 0.01};
const T EI = blade.youngs_modulus * section.second_moment(), rhoA = blade.density * section.area();
const T kL = 1.8751040687;
const T omega1 = kL * kL * std::sqrt(EI / (rhoA * L * L * L * L));

using sphfsi::analysis::elastica_tip_load;

void run_static(int nodes, T alpha, fmt::ostream& out) {
  System system = make_system();
  sphfsi::add_elastic_rod(system, V(0, 0), V(1, 0), L, nodes, blade, section, L / (nodes - 1), 0);
  Rod rod(system, 0, blade, {.section = section, .gravity = V::Zero(), .damping = 2 * omega1});
  rod.clamp_base();
  const T P = alpha * EI / (L * L);
  const auto tip = rod.particle_ids().back();
  const T dt = 200 * rod.solid_time_step();
  const auto start = std::chrono::steady_clock::now();
  T t = 0;
  for (int step = 0; t < 40 * 2 * std::numbers::pi / omega1; ++step) {
    system.particles().acceleration[system.particles().slot_of_id(tip)] = V(0, -P / rod.node_masses().back());
    rod.advance(system, t, dt);
    t += dt;
    T v_max = 0;
    for (const auto& v : rod.velocities()) v_max = std::max(v_max, v.norm());
    if (step > 10 && v_max < 1e-11 * L * omega1) break;
  }
  const T wall = std::chrono::duration<T>(std::chrono::steady_clock::now() - start).count();
  const auto [d_ref, s_ref] = elastica_tip_load(alpha);
  const T d = -rod.tip_position().y() / L, s = (L - rod.tip_position().x()) / L;
  fmt::print(
      "static  nodes {:4d} alpha {:5.2f}: deflection/L {:.6f} (elastica {:.6f}, {:+.4f} %), shortening/L "
      "{:.6f} (elastica {:.6f}, {:+.4f} %), {} sub-steps, {:.2f} s\n",
      nodes, alpha, d, d_ref, 100 * (d / d_ref - 1), s, s_ref, 100 * (s / s_ref - 1), rod.sub_step_total(), wall);
  out.print("{},{},{:.9g},{:.9g},{:.9g},{:.9g},{},{:.4g}\n", nodes, alpha, d, d_ref, s, s_ref, rod.sub_step_total(),
            wall);
}

void run_vibration(int nodes, fmt::ostream& out) {
  System system = make_system();
  sphfsi::add_elastic_rod(system, V(0, 0), V(1, 0), L, nodes, blade, section, L / (nodes - 1), 0);
  const T ratio = (std::cos(kL) + std::cosh(kL)) / (std::sin(kL) + std::sinh(kL));
  const auto mode = [&](T x) {
    const T k = kL / L;
    return (std::cos(k * x) - std::cosh(k * x)) - ratio * (std::sin(k * x) - std::sinh(k * x));
  };
  auto& p = system.particles();
  const T v_tip = 1e-3 * L * omega1;
  for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = V(0, v_tip * mode(p.position[i].x()) / mode(L));
  Rod rod(system, 0, blade, {.section = section, .gravity = V::Zero()});
  rod.clamp_base();
  rod.compute_rates(system, 0);
  const T period_eb = 2 * std::numbers::pi / omega1, dt = period_eb / 4000;
  const T e0 = rod.kinetic_energy() + rod.strain_energy();
  T t = 0, y_old = 0, energy_band = 0;
  std::vector<T> up;
  const auto start = std::chrono::steady_clock::now();
  while (t < 5.2 * period_eb) {
    rod.advance(system, t, dt);
    t += dt;
    const T y = rod.tip_position().y();
    if (y_old < 0 && y >= 0) up.push_back(t - dt * y / (y - y_old));
    y_old = y;
    energy_band = std::max(energy_band, std::abs(rod.kinetic_energy() + rod.strain_energy() - e0) / e0);
  }
  const T wall = std::chrono::duration<T>(std::chrono::steady_clock::now() - start).count();
  const T period = (up.back() - up.front()) / T(up.size() - 1);
  fmt::print(
      "vibration nodes {:4d}: period {:.7f} s, Euler-Bernoulli {:.7f} s, error {:+.4f} %, energy band {:.2e}, "
      "{} sub-steps, {:.2f} s\n",
      nodes, period, period_eb, 100 * (period / period_eb - 1), energy_band, rod.sub_step_total(), wall);
  out.print("{},{:.9g},{:.9g},{:.3g},{},{:.4g}\n", nodes, period, period_eb, energy_band, rod.sub_step_total(), wall);
}

/// Real Posidonia blade, clamped at the bed, buoyant (rho = 910 in sea water 1025), in the current
/// U(t) = U0 sin(2 pi t / Tw) with a Morison normal drag (C_D = 1.95, the flat-plate value) written into
/// p.acceleration once per outer step, as a coupling does. Returns the tip path sampled every outer step of the
/// sub-cycled run and the wall time.
std::pair<std::vector<V>, T> run_posidonia(int nodes, int rod_steps_per_outer, int ratio, T t_end,
                                           std::size_t& sub_steps, T& dt_rod) {
  const sphfsi::ElasticMaterial<T> posidonia{.density = 910, .youngs_modulus = 4.7e8, .poisson_ratio = 0.35};
  const sphfsi::RodSection<T> leaf{.thickness = 1e-4, .width = 8e-3};
  const T length = 0.1, rho_w = 1025, c_d = 1.95, U0 = 0.1, Tw = 1.0;
  System system = make_system();
  sphfsi::add_elastic_rod(system, V(0, 0), V(0, 1), length, nodes, posidonia, leaf, length / (nodes - 1), 0);
  Rod rod(system, 0, posidonia, {.section = leaf, .ambient_density = rho_w});
  rod.clamp_base();
  rod.compute_rates(system, 0);
  dt_rod = rod.solid_time_step();
  const T dt = rod_steps_per_outer * dt_rod;
  auto& p = system.particles();
  std::vector<V> path;
  const auto start = std::chrono::steady_clock::now();
  T t = 0;
  for (long step = 0; t < t_end; ++step) {
    const V current(U0 * std::sin(2 * std::numbers::pi * t / Tw), 0);
    for (auto id : rod.particle_ids()) {
      const std::size_t s = p.slot_of_id(id);
      const T u_n = (current - p.velocity[s]).dot(p.normal[s]);
      // force per unit length 0.5 rho_w C_D b |u_n| u_n over the mass per unit length rho t b
      p.acceleration[s] =
          (0.5 * rho_w * c_d * std::abs(u_n) * u_n / (posidonia.density * leaf.thickness)) * p.normal[s];
    }
    rod.advance(system, t, dt);
    t += dt;
    if ((step + 1) % (ratio / rod_steps_per_outer) == 0) path.push_back(rod.tip_position());
  }
  sub_steps = rod.sub_step_total();
  return {path, std::chrono::duration<T>(std::chrono::steady_clock::now() - start).count()};
}

}  // namespace

int main(int argc, char** argv) {
  try {
    sphfsi::io::CommandLine cli(argc, argv,
                                "elastic_rod: validation of the planar discrete elastic rod (docs/thin-blades.md)");
    const std::string which = cli.get("case", "static", "static | vibration | subcycle");
    const int nodes = static_cast<int>(cli.get_number("nodes", 0, "node count (0: the sweep 11, 21, 41, 81)"));
    const T load = cli.get_number("load", 0, "static: alpha = P L^2 / (E I) (0: the sweep 0.1 .. 10)");
    const int ratio = static_cast<int>(cli.get_number("ratio", 20, "subcycle: rod steps per outer (fluid) step"));
    const T t_end = cli.get_number("end", 2, "subcycle: simulated time, s");
    const std::string output = cli.get("output", "", "CSV file (default elastic_rod_<case>.csv)");
    if (!cli.finish()) return 0;
    if (nodes != 0) sphfsi::require_in_range("--nodes", nodes, 3, 100000);
    const std::string file = output.empty() ? "elastic_rod_" + which + ".csv" : output;
    auto out = fmt::output_file(file);
    const std::vector<int> node_list = nodes ? std::vector<int>{nodes} : std::vector<int>{11, 21, 41, 81};
    if (which == "static") {
      out.print("nodes,alpha,deflection,deflection_elastica,shortening,shortening_elastica,sub_steps,wall_s\n");
      const std::vector<T> loads = load > 0 ? std::vector<T>{load} : std::vector<T>{0.1, 0.5, 1, 2, 5, 10};
      for (T alpha : loads)
        for (int n : node_list) run_static(n, alpha, out);
    } else if (which == "vibration") {
      out.print("nodes,period,period_euler_bernoulli,energy_band,sub_steps,wall_s\n");
      for (int n : node_list) run_vibration(n, out);
    } else if (which == "subcycle") {
      sphfsi::require_in_range("--ratio", ratio, 1, 100000);
      const int n = nodes ? nodes : 51;
      std::size_t sub_a = 0, sub_b = 0;
      T dt_rod = 0;
      const auto [cycled, wall_a] = run_posidonia(n, ratio, ratio, t_end, sub_a, dt_rod);
      const auto [global, wall_b] = run_posidonia(n, 1, ratio, t_end, sub_b, dt_rod);
      T difference = 0, excursion = 0;
      out.print("t,tip_x_subcycled,tip_y_subcycled,tip_x_global,tip_y_global\n");
      for (std::size_t i = 0; i < std::min(cycled.size(), global.size()); ++i) {
        difference = std::max(difference, (cycled[i] - global[i]).norm());
        excursion = std::max(excursion, std::abs(global[i].x()));
        out.print("{:.6g},{:.9g},{:.9g},{:.9g},{:.9g}\n", (i + 1) * ratio * dt_rod, cycled[i].x(), cycled[i].y(),
                  global[i].x(), global[i].y());
      }
      fmt::print("subcycle: Posidonia blade, {} nodes, rod step {:.3e} s, outer step {:.3e} s ({} rod steps)\n", n,
                 dt_rod, ratio * dt_rod, ratio);
      fmt::print("  sub-cycled: {} outer steps, {} rod steps, {:.3f} s wall\n", cycled.size(), sub_a, wall_a);
      fmt::print("  global:     {} outer steps, {} rod steps, {:.3f} s wall\n", sub_b, sub_b, wall_b);
      fmt::print("  largest tip difference {:.3e} m = {:.3f} % of the largest tip excursion {:.4f} m\n", difference,
                 100 * difference / excursion, excursion);
    } else {
      throw sphfsi::InputError(
          fmt::format("--case = '{}' is invalid: valid values are static, vibration, subcycle", which));
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "elastic_rod: {}\n", e.what());
    return 1;
  }
}
