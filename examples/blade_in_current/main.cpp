// sphfsi example: reconfiguration of a flexible blade in a steady current (Luhar & Nepf 2011, J. Fluid Mech.
// 680; validation-cases.md sec. 6), issue 5 part 5 and issue 6 part 3.
//
// A blade of length l, thickness t and Young's modulus E, clamped upright at its base on the bed of a closed 2D
// channel (depth 3 l, a lid instead of a free surface: the steady current has no surface waves to make), is towed
// along the bed at speed U through still water (the Galilean equivalent of a current U past a fixed blade over a
// bed moving with the current, i.e. without a bed boundary layer). The blade is one line of nodes of the
// discrete elastic rod (solid/elastic_rod.hpp) with its real thickness and modulus, coupled to the fluid by the
// repulsive force on both faces (coupling/repulsive_force.hpp). Once the flow is steady, the time-averaged drag F
// of the flexible blade over that of a rigid blade of the same length in the same flow gives the effective length
//     l_e / l = F / F_rigid,
// compared with Luhar & Nepf's model (no buoyancy here: g = 0, B = 0)
//     l_e / l = 1 - (1 - 0.9 Ca^(-1/3)) / (1 + 8 Ca^(-3/2)),   Ca = rho C_D U^2 l^3 / (2 E t^3 / 12)
// with C_D = F_rigid / (rho U^2 l / 2) measured on the rigid blade (per unit width: b cancels in 2D).
// The Cauchy number is set through E at fixed U, l, t (same Reynolds number for every case).
//
// --three-d on: the same tow in a 3D channel of width W (--channel-width, in blade widths) with the blade as a strip of
// width b in its middle (a ribbon: solid/elastic_rod.hpp, rows of particles across the width; the visibility
// criterion and the guard with lateral bands). The water then passes the strip's sides, as round the narrow blades of
// Luhar & Nepf (b / l = 0.2), instead of over the top of a full-width 2D plate; forces are per blade (N) and
// C_D = F_rigid / (rho U^2 b l / 2).
//
// Writes <output>/summary.csv (one row per case), <output>/case_<Ca>.csv (drag, tip position and the fluid under the
// folded blade vs time), <output>/shape_<Ca>.csv (over the averaging window: the mean node positions from the base
// and the mean force of the fluid on each node, N/m) and <output>/effective_length.png (plot.py).
#include <sphfsi/analysis/reconfiguration.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/coupling/blade_drag.hpp>
#include <sphfsi/coupling/coupled_body.hpp>
#include <sphfsi/coupling/repulsive_force.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/io/progress.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/scenes/meadow.hpp>
#include <sphfsi/solid/elastic_rod.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

using namespace sphfsi;
using T = double;
using V = Vec<2, T>;
using System = ParticleSystem<2, T, WendlandC2<2>, Tait<T>>;
using Rod = ElasticRod<System>;

struct Options {
  T length = 0.05;               // l, m
  T thickness = 4e-4;            // t, m (HDPE blades of Luhar & Nepf 2011: 0.4 mm)
  T density = 950;               // rho_s, kg/m^3 (neutral buoyancy does not matter: g = 0)
  T speed = 0.2;                 // U, m/s
  T particles_along = 15;        // l / dp
  T rod_spacing = 0.5;           // rod node spacing / dp
  T nominal_drag = 2.0;          // C_D used to choose E for a target Ca (the measured one is reported)
  T tow_lengths = 8;             // towing distance after the ramp, in blade lengths
  bool velocity_factor = false;  // eps(u_perp) of eq. 23: off, it rectifies the jitter of a light blade
  T normal_damping = 0;          // beta of the coupling's normal dashpot (off: see docs/thin-blades.md)
  T rod_damping = 0;       // c_d of the rod's damping relative to the carriage, 1/s (flutter only, not the posture)
  bool visibility = true;  // fluid pairs across the blade do not interact (fluid/thin_structure_visibility.hpp)
  bool guard = true;       // fluid that steps through the blade is put back (fluid/thin_structure_guard.hpp)
  T contact_gap = 2;       // resolved blade: height of its contact plane above the bed, in fluid spacings
  // Resolved blade: its structure continues this far into the bed (fluid spacings), clamped there, so that the
  // visibility criterion also parts the bed's wall particles under its two faces (0: the blade ends at the bed)
  T anchor = 0;
  // repulsive: the blade is resolved as an obstacle (eqs 17-23) | drag: porous, it exchanges its Morison drag with
  // the fluid (coupling/blade_drag.hpp), the drag law of Luhar & Nepf's model itself: a check of the rod and of the
  // fluid's response, not of the flow around the blade
  std::string coupling = "repulsive";
  T blade_cd = 1.95;  // C_D of the drag coupling
  // drag coupling: share phi of the 2D channel's width the blade covers (b / W of one blade in a flume of width W;
  // 1: a full-width row of blades, whose drag slows the whole 2D stream through it; coupling/blade_drag.hpp)
  T frontal_fraction = 1;
  bool global_step = false;          // true: the fluid steps with the rod's own stable step (no sub-cycling)
  T end_time = 0;                    // s; 0: the ramp and the whole towing distance
  T sound_speed = 20;                // c0 / U, the fluid's artificial sound speed over the towing speed
  T artificial_viscosity = T(0.02);  // alpha: nu = alpha h c0 / 8 (Re = U l / nu = 230 at the defaults)
  // Background pressure over rho U^2 (0: none). The resolved blade's repulsive faces can only push: without an ambient
  // pressure the wake's suction pulls the fluid off the lee face (g = 0: no hydrostatic pressure, unlike the flume).
  T background_pressure = 0;
  T depth_lengths = 3;  // channel depth in blade lengths (blockage l / depth)
  // The bed, walls and lid: dynamic boundary particles, or their pressure extrapolated from the fluid (Adami et al.
  // 2012): a dynamic bed that the towed blade has passed keeps the blade's stagnation pressure (session 32)
  WallModel walls = WallModel::dynamic;
  // 3D: a strip of width b (a ribbon) in the middle of a channel of width W, so that the water can pass the blade's
  // sides as round Luhar & Nepf's blades (b / l = 0.2), instead of the 2D full-width blade
  bool three_d = false;
  // no run: the static blade under the model's law and under the measured one of force_law, for each Ca of cauchy
  bool static_only = false;
  T blade_width = T(0.01);  // b, m (2D: the porous blade's added mass only)
  T channel_width = 6;      // 3D: W / b, rounded to whole fluid spacings
  int width_particles = 0;  // 3D: particles across the strip's width (0: b / (rod_spacing dp), at least 2)
  T average_from = 3;       // the drag is averaged once the blade has moved this many lengths after the ramp
  std::vector<T> cauchy{0, 1, 3, 10, 30, 100, 300, 1000};  // 0: the rigid blade
  // The force-law sweep: rigid blades inclined by these angles from the vertical (degrees, leaning downstream).
  std::vector<T> inclinations;
  T mount_height = 0;  // force-law sweep: the rigid blades' base above the bed, blade lengths (0: on the bed)
  // A double blade of length l clamped at its middle, away from the bed (its lower end at mount_height): each half is
  // the mirror image of the other, so each is a blade of length l / 2 standing on a free-slip plane, without a bed
  // and its wall particles (the Cauchy number is set for the half)
  bool clamp_middle = false;
  // A force-law sweep's inclined.csv: the flexible sweep's summary then adds the static reconfiguration under
  // that measured law (analysis/reconfiguration.hpp) beside Luhar & Nepf's.
  std::filesystem::path force_law;
  // summary.csv of an earlier sweep with the same scene: its rigid blade is the reference, so a sweep can be split
  // over several processes without running the rigid blade again
  std::filesystem::path rigid_from;
  std::filesystem::path output = "out/blade_in_current";
};

struct CaseResult {
  T target_ca, youngs_modulus, drag, drag_error, tip_x, tip_y, wall;
  std::size_t steps, particles;
  T lift = 0, lift_error = 0;  // mean vertical force on the blade (up > 0), N/m, and its standard error
  T tip_height_rms = 0;        // standard deviation of the tip's height over the averaging window, m (flutter)
  T fluid_under = 0;           // mean fluid area under the folded blade over the averaging window, in l^2
};

/// Mean of the samples and its standard error from 8 blocks (the samples are correlated within a block); NaN when
/// there are fewer than 8 samples.
std::pair<T, T> block_mean(const std::vector<T>& samples) {
  const std::size_t blocks = 8, per = samples.size() / blocks;
  if (per == 0) return {std::numeric_limits<T>::quiet_NaN(), std::numeric_limits<T>::quiet_NaN()};
  T mean = 0;
  for (T f : samples) mean += f;
  mean /= T(samples.size());
  T var = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    T m = 0;
    for (std::size_t k = b * per; k < (b + 1) * per; ++k) m += samples[k];
    m /= T(per);
    var += (m - mean) * (m - mean);
  }
  return {mean, std::sqrt(var / T(blocks * (blocks - 1)))};
}

/// Fluid under the blade: the area (per unit width, m^2) of the fluid particles that lie below the blade's lowest
/// point in their column (columns of dp / 2 over the blade's horizontal extent), i.e. between a folded blade and the
/// bed. In 2D the blade spans the whole width, so this fluid can leave only past the tip.
template <class Ids>
T fluid_under_blade(const ParticleSet<2, T>& p, const Ids& ids, T dp) {
  T x_min = std::numeric_limits<T>::max(), x_max = -x_min;
  for (auto id : ids) {
    const T x = p.position[p.slot_of_id(id)][0];
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
  }
  const T column = dp / 2;
  const std::size_t columns = static_cast<std::size_t>((x_max - x_min) / column) + 1;
  std::vector<T> lowest(columns, std::numeric_limits<T>::max());
  for (std::size_t k = 0; k + 1 < ids.size(); ++k) {
    const V a = p.position[p.slot_of_id(ids[k])], b = p.position[p.slot_of_id(ids[k + 1])];
    const auto first = static_cast<std::size_t>((std::min(a[0], b[0]) - x_min) / column);
    const auto last = static_cast<std::size_t>((std::max(a[0], b[0]) - x_min) / column);
    for (std::size_t c = first; c <= last && c < columns; ++c) lowest[c] = std::min({lowest[c], a[1], b[1]});
  }
  T area = 0;
  for (std::size_t f = 0; f < p.size(); ++f) {
    if (p.kind[f] != Kind::fluid || p.position[f][0] < x_min || p.position[f][0] > x_max) continue;
    const auto c = static_cast<std::size_t>((p.position[f][0] - x_min) / column);
    if (c < columns && p.position[f][1] < lowest[c]) area += p.mass[f] / p.density[f];
  }
  return area;
}

/// Runs one blade: flexible at the target Cauchy number, or rigid (target_ca = 0). `inclination`: the blade's rest
/// angle from the vertical, leaning downstream (rad; the rigid blades of the force-law sweep). Dim = 3: the
/// blade is a strip of width b (a ribbon, solid/elastic_rod.hpp) in the middle of a channel of width W; forces are
/// then per blade (N), in 2D per unit width (N/m).
template <int Dim, class Coupling>
CaseResult run_case(const Options& o, T target_ca, T inclination = 0) {
  using SystemD = ParticleSystem<Dim, T, WendlandC2<Dim>, Tait<T>>;
  using RodD = ElasticRod<SystemD>;
  using VD = Vec<Dim, T>;
  using Blade = CoupledBody<Coupling, RodD>;
  using Solver = Simulation<SystemD, SymplecticVerlet, Blade>;
  constexpr bool porous = std::is_same_v<Coupling, BladeDrag<T>>;
  const T l = o.length, dp = l / o.particles_along, depth = o.depth_lengths * l, U = o.speed, rho = 1000;
  const T x0 = 2 * l, ramp = T(0.25), tow = o.tow_lengths * l;
  const T tank = x0 + U * ramp / 2 + tow + 3 * l;
  const T c0 = o.sound_speed * U;  // the flow around the blade's tip reaches about 2 U: c0 >= 10 x that
  const Resolution<T> res{dp, T(1.3)};
  // (x, z) in the channel's plane; in 3D the channel spans y in [-W/2, W/2] (a whole number of spacings)
  const T half_width = T(0.5) * dp * std::max(T(1), std::round(o.channel_width * o.blade_width / dp));
  const auto at = [&](T x, T y, T z) {
    if constexpr (Dim == 2) return VD(x, z);
    else return VD(x, y, z);
  };
  SystemD system(Domain<Dim, T>(at(-4 * dp, -half_width - 4 * dp, -4 * dp),
                                at(tank + 4 * dp, half_width + 4 * dp, depth + 4 * dp)),
                 Tait<T>(rho, c0));
  add_fluid_block(system, at(0, -half_width, 0), at(tank, half_width, depth), res, depth, T(0));
  // The blade leans downstream of the towing (towards -x) by `inclination`. Upright, it lies on a lattice line with
  // the fluid columns dp/2 on either side; inclined, the fluid within dp/2 of it is taken out.
  const V direction(-std::sin(inclination), std::cos(inclination));
  const V mount(
      x0, target_ca > 0 && !o.clamp_middle ? T(0) : std::round(o.mount_height * l / dp) * dp);  // the blade's base
  // In 3D only across the strip's width (|y| < b / 2): the water beside its edges stays.
  if (inclination != 0) {
    auto& p = system.particles();
    for (std::size_t k = p.size(); k-- > 0;) {
      const VD& x = p.position[k];
      if (Dim == 3 && !(std::abs(x[1]) < o.blade_width / 2)) continue;
      const V r = V(x[0], x[Dim - 1]) - mount;
      const T along = std::clamp(r.dot(direction), T(0), l);
      if ((r - along * direction).norm() < dp / 2) p.remove(k);
    }
  }
  add_box_walls(system, at(0, -half_width, 0), at(tank, half_width, depth), res, WallModel::dynamic);
  for_each_lattice_point<Dim, T>(at(-3 * dp, -half_width - 3 * dp, depth),
                                 at(tank + 3 * dp, half_width + 3 * dp, depth + 3 * dp), dp, [&](const VD& x) {
                                   system.particles().add(Kind::wall, x, VD::Zero(), rho, rho * std::pow(dp, T(Dim)),
                                                          res.h(), 0);  // the lid
                                 });
  // The blade on a lattice line (fluid columns at dp/2 on either side), nodes every rod_spacing dp (dp/2); in 3D
  // each node a row across the strip's width at about the same spacing.
  const int nodes = static_cast<int>(std::lround(o.particles_along / o.rod_spacing)) + 1;
  // nodes buried in the bed below the base (--anchor), on the same spacing: the node at the bed stays a node
  const int buried = inclination == 0 && mount[1] == 0 ? static_cast<int>(std::lround(o.anchor / o.rod_spacing)) : 0;
  const T buried_length = T(buried) * l / T(nodes - 1);
  const V root = mount - buried_length * direction;
  ElasticMaterial<T> material;
  material.density = o.density;
  material.poisson_ratio = T(0.4);
  const T second_moment = o.thickness * o.thickness * o.thickness / 12;  // per unit width, m^3
  const T bending_length = o.clamp_middle ? l / 2 : l;                   // the length that bends from a clamp
  material.youngs_modulus =
      target_ca > 0 ? rho * o.nominal_drag * U * U * std::pow(bending_length, T(3)) / (2 * target_ca * second_moment)
                    : T(1e9);
  const RodSection<T> section{.thickness = o.thickness, .width = o.blade_width};
  if constexpr (Dim == 2) {
    add_elastic_rod(system, root, direction, l + buried_length, nodes + buried, material, section, res.h(), 1);
  } else {
    const int rows = o.width_particles > 0
                         ? o.width_particles
                         : std::max(2, static_cast<int>(std::lround(o.blade_width / (o.rod_spacing * dp))));
    add_elastic_ribbon(system, root, direction, l + buried_length, nodes + buried, rows, T(0), material, section,
                       res.h(), 1);
  }
  typename RodD::Parameters params;
  params.section = section;
  params.gravity = V::Zero();
  params.damping = o.rod_damping;
  params.damping_relative_to_clamp = true;  // towed: damp the motion about the carriage, not the tow itself
  // A porous blade does not move the fluid aside, so its added mass must be the rod's: that of a plate of width b
  // moving normal to itself, rho pi b / 4 per unit length and width. The repulsive blade pushes the fluid and gets
  // its added mass from it.
  if constexpr (porous) params.added_mass_per_area = plate_added_mass_per_area(rho, section.width);
  RodD rod(system, 1, material, params);
  // A resolved blade folding over rests contact_gap fluid spacings above the bed, so the fluid trapped under it keeps
  // room: at dp / 2 the first fluid row was crushed between the bed and the blade (a blow-up at Ca = 390); at dp,
  // once the guard stops that water escaping through the blade, it is squeezed through the bed instead (Ca = 142,
  // 0.92 s); 2 dp holds. A porous blade traps no fluid: its contact plane is the bed itself (a gap g would hold its
  // lowest g upright).
  rod.set_contact_plane(V(0, 0), V(0, 1), porous ? T(0) : o.contact_gap * dp);
  const T node_spacing = l / T(nodes - 1), middle = mount[1] + l / 2;
  if (target_ca > 0 && o.clamp_middle)  // the middle node and its two neighbours: both halves clamped there
    rod.clamp_where([&](const VD& x) { return std::abs(x[Dim - 1] - middle) <= T(1.01) * node_spacing; });
  else if (target_ca > 0 && buried == 0) rod.clamp_base();
  else if (target_ca > 0) rod.clamp_where([&](const VD& x) { return x[Dim - 1] <= T(1e-9) * dp; });  // and buried
  else rod.clamp_where([](const VD&) { return true; });  // the rigid reference blade
  // Towing: velocity U (1 - cos(pi t / ramp)) / 2 during the ramp, U after it.
  const T pi = std::numbers::pi_v<T>;
  rod.set_clamp_motion(
      [=](T t) {
        return V(t < ramp ? U * (t / 2 - ramp / (2 * pi) * std::sin(pi * t / ramp)) : U * (t - ramp / 2), 0);
      },
      [=](T t) { return V(t < ramp ? U * (1 - std::cos(pi * t / ramp)) / 2 : U, 0); });
  FluidParameters<Dim, T> fluid;
  fluid.gravity = VD::Zero();
  fluid.artificial_viscosity = o.artificial_viscosity;
  fluid.walls = o.walls;
  fluid.thin_structure_visibility = o.visibility && !porous;  // the fluid passes a porous blade
  fluid.thin_structure_guard = o.guard;
  fluid.background_pressure = o.background_pressure * rho * U * U;
  Coupling coupling;
  if constexpr (porous) {
    coupling.drag_coefficient = o.blade_cd;
    coupling.frontal_fraction = o.frontal_fraction;
  } else {  // eq. 19 with k = 0.01 (no hydrostatic load to balance here), or the strength that holds the background
            // pressure with the first fluid rows at dp / 2 on either face (their initial position)
    if (fluid.background_pressure > 0)
      coupling.strength = repulsive_strength_for_rest_pressure(fluid.background_pressure, rho, c0, res.smoothing_ratio);
    coupling.velocity_factor = o.velocity_factor;
    coupling.normal_damping = o.normal_damping;
  }
  // Sub-cycling (the default): the rod takes its own stable step inside each fluid step. With --global-step the fluid
  // is forced to the rod's step, so the rod takes one sub-step per fluid step (the reference for the saving).
  TimeStepParameters<T> time_step;
  if (o.global_step) time_step.fixed_dt = rod.solid_time_step();
  Solver sim(system, fluid, time_step, Blade(coupling, std::move(rod)));
  sim.set_expected_flow_speed(2 * U);

  const std::string label = target_ca > 0 ? fmt::format("{:g}", target_ca) : "rigid";
  io::CsvWriter csv(o.output / fmt::format("case_{}.csv", label),
                    {"t", "drag", "lift", "tip_dx", "tip_dy", "fluid_under"});
  const T t_end = o.end_time > 0 ? o.end_time : ramp + tow / U, t_avg = ramp + o.average_from * l / U;
  const RodD& blade = sim.template model<0>().solid();
  const std::size_t node_count = blade.node_count(), per_node = blade.particles_per_node();
  const auto& ids = blade.particle_ids();
  std::vector<T> samples, lift_samples;
  // node positions relative to the base and the couplings' force on each node (its row in 3D), summed over the
  // averaging window
  std::vector<V> mean_shape(node_count, V::Zero()), mean_load(node_count, V::Zero());
  // The mean flow around the blade's base in the blade's frame over the averaging window: bins of dp / 4 from -l / 2
  // to l / 2 along the tow and from 2 dp under the bed to l / 2 above it (3D: the strip's own width only), each with
  // the particles' summed pressure, velocity relative to the blade and count (wall particles below the bed).
  const T bin = dp / 4, field_x0 = -l / 2, field_z0 = -2 * dp;
  const auto bins_x = static_cast<std::size_t>(std::lround(l / bin)),
             bins_z = static_cast<std::size_t>(std::lround((l / 2 + 2 * dp) / bin));
  struct FieldBin {
    T pressure = 0, u = 0, w = 0, count = 0;
  };
  std::vector<FieldBin> base_field(bins_x * bins_z);
  std::size_t field_samples = 0;
  T tip_x = 0, tip_y = 0, tip_y_squared = 0, under_sum = 0;
  std::size_t tip_n = 0;
  io::ProgressReporter progress(t_end);
  const auto start = std::chrono::steady_clock::now();
  T next_sample = 0;
  // Fluid particles that crossed the (impermeable) blade, counted every step, and those the guard put back.
  struct OneBlade {
    const RodD& only;
    std::size_t size() const noexcept { return 1; }
    const RodD& rod(std::size_t) const noexcept { return only; }
  };
  scenes::BladeCrossingCounter<SystemD> crossings(T(1.5) * dp);
  sim.run(t_end, [&](Solver& s) {
    progress(s);
    if constexpr (!porous) crossings.update(s.system(), OneBlade{s.template model<0>().solid()});
    if (s.time() < next_sample) return;
    next_sample += T(0.005);
    const auto& p = s.system().particles();
    const VD force = s.template model<0>().solid().coupling_force(p);
    const T drag = -force[0], lift = force[Dim - 1];
    const auto& x = s.template model<0>().solid().positions();
    // the base: the node at the bed, or the double blade's middle (its upper half is then the blade reported)
    const V base = x[o.clamp_middle ? (node_count - 1) / 2 : std::size_t(buried)], tip = x.back();
    T under = std::numeric_limits<T>::quiet_NaN();  // 2D: the fluid a folded full-width blade seals off
    if constexpr (Dim == 2) under = porous ? T(0) : fluid_under_blade(p, ids, dp) / (l * l);
    csv.write_row({s.time(), drag, lift, tip[0] - base[0], tip[1] - base[1], under});
    if (s.time() >= t_avg) {
      samples.push_back(drag);
      lift_samples.push_back(lift);
      tip_x += tip[0] - base[0];
      tip_y += tip[1] - base[1];
      tip_y_squared += (tip[1] - base[1]) * (tip[1] - base[1]);
      for (std::size_t k = 0; k < node_count; ++k) mean_shape[k] += x[k] - base;
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const std::size_t slot = p.slot_of_id(ids[i]);
        const VD f = p.mass[slot] * p.acceleration[slot];
        mean_load[i / per_node] += V(f[0], f[Dim - 1]);
      }
      under_sum += under;
      ++tip_n;
      for (std::size_t f = 0; f < p.size(); ++f) {
        if (p.kind[f] == Kind::solid) continue;
        if constexpr (Dim == 3)
          if (std::abs(p.position[f][1]) > o.blade_width / 2) continue;
        const T bx = (p.position[f][0] - base[0] - field_x0) / bin,
                bz = (p.position[f][Dim - 1] - base[1] - field_z0) / bin;
        if (bx < 0 || bz < 0 || bx >= T(bins_x) || bz >= T(bins_z)) continue;
        FieldBin& c = base_field[std::size_t(bz) * bins_x + std::size_t(bx)];
        c.pressure += p.pressure[f];
        c.u += p.velocity[f][0] - U;
        c.w += p.velocity[f][Dim - 1];
        c.count += 1;
      }
      ++field_samples;
    }
  });
  progress.finish(sim);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if constexpr (!porous)
    fmt::print("fluid particles that crossed the blade: {} (put back by the guard: {})\n", crossings.total(),
               sim.fluid().structure_crossings_prevented());
  const auto [mean, se] = block_mean(samples);
  const auto [lift, lift_se] = block_mean(lift_samples);
  const T n = T(tip_n), height = tip_y / n;
  if (tip_n > 0) {  // the blade's mean posture over the averaging window, base to tip
    io::CsvWriter shape(o.output / fmt::format("shape_{}.csv", label), {"node", "dx", "dy", "force_x", "force_y"});
    for (std::size_t k = 0; k < node_count; ++k)
      shape.write_row({T(k), mean_shape[k][0] / n, mean_shape[k][1] / n, mean_load[k][0] / n, mean_load[k][1] / n});
    io::CsvWriter field(o.output / fmt::format("base_field_{}.csv", label),
                        {"x", "z", "pressure", "u", "w", "occupancy"});
    for (std::size_t k = 0; k < base_field.size(); ++k) {
      const FieldBin& c = base_field[k];
      const T x = field_x0 + (T(k % bins_x) + T(0.5)) * bin, z = field_z0 + (T(k / bins_x) + T(0.5)) * bin;
      const T nan = std::numeric_limits<T>::quiet_NaN(), per = c.count > 0 ? 1 / c.count : nan;
      field.write_row({x, z, c.pressure * per, c.u * per, c.w * per, c.count / T(field_samples)});
    }
  }
  return {target_ca,     material.youngs_modulus,
          mean,          se,
          tip_x / n,     height,
          wall,          sim.step_count(),
          system.size(), lift,
          lift_se,       std::sqrt(std::max(tip_y_squared / n - height * height, T(0))),
          under_sum / n};
}

/// The local force law of the resolved blade, measured on rigid blades inclined by theta from the vertical: per unit
/// length, in units of (1/2) rho U^2 C_N(0) (the upright blade's normal load), the normal load (on the downstream
/// face's normal) and the tangential load (along the blade, base to tip). The flexible blade at the same Ca, posed
/// as Luhar & Nepf's static balance but with this law, is analysis::static_reconfiguration. Dim = 3: strips of width
/// b in the 3D channel (forces per blade, loads per unit length of the strip, in units of (1/2) rho U^2 C_N(0) b).
template <int Dim>
int run_force_law_sweep(const Options& o) {
  if (o.coupling != "repulsive")
    throw InputError("--inclinations: the force law of the resolved blade needs --coupling repulsive");
  if (o.inclinations.front() != 0) throw InputError("--inclinations must start with 0 (the upright blade)");
  require_in_range("--mount-height (blade lengths)", o.mount_height, T(0), o.depth_lengths - T(1.5));
  for (std::size_t k = 0; k < o.inclinations.size(); ++k) {
    require_in_range("--inclinations (degrees)", o.inclinations[k], T(0), T(85));
    if (k > 0 && !(o.inclinations[k] > o.inclinations[k - 1]))
      throw InputError(fmt::format("--inclinations: {} is not above the angle before it", o.inclinations[k]));
  }
  const T pi = std::numbers::pi_v<T>, rho = 1000;
  const T dynamic = T(0.5) * rho * o.speed * o.speed * o.length * (Dim == 3 ? o.blade_width : T(1));
  io::CsvWriter csv(o.output / "inclined.csv",
                    {"inclination_deg", "drag", "drag_error", "lift", "lift_error", "normal_coefficient",
                     "tangential_coefficient", "normal_load", "tangential_load", "steps", "wall_s"});
  fmt::print(
      "| inclination | drag F_x ({0}) | lift F_z ({0}) | C_N | C_T | C_N / C_N(0) | cos^2 | C_T / C_N(0) | wall (s) "
      "|\n|---|---|---|---|---|---|---|---|---|\n",
      Dim == 3 ? "N" : "N/m");
  T upright = 0;
  for (const T degrees : o.inclinations) {
    fmt::print("--- rigid blade inclined by {:g} degrees\n", degrees);
    const T theta = degrees * pi / 180;
    const CaseResult r = run_case<Dim, RepulsiveForce<T>>(o, 0, theta);
    // Decomposed on the blade: n = (-cos, -sin) is the downstream face's normal (the blade leans towards -x, the
    // water moves along -x relative to it), t = (-sin, cos) its tangent. drag = -F_x, lift = F_z.
    const T normal = r.drag * std::cos(theta) - r.lift * std::sin(theta);
    const T tangential = r.drag * std::sin(theta) + r.lift * std::cos(theta);
    const T cn = normal / dynamic, ct = tangential / dynamic;
    if (degrees == 0) upright = cn;
    csv.write_row(
        {degrees, r.drag, r.drag_error, r.lift, r.lift_error, cn, ct, cn / upright, ct / upright, T(r.steps), r.wall});
    fmt::print("| {:g} | {:.4g} +- {:.2g} | {:.4g} +- {:.2g} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.0f} |\n",
               degrees, r.drag, r.drag_error, r.lift, r.lift_error, cn, ct, cn / upright,
               std::cos(theta) * std::cos(theta), ct / upright, r.wall);
  }
  fmt::print("wrote {}\n", (o.output / "inclined.csv").string());
  return 0;
}

/// The normal and tangential laws of a force-law sweep's inclined.csv: linear between the measured angles; beyond
/// the last one, the normal load falls linearly to 0 at a blade lying flat (no normal velocity), the tangential load
/// (skin friction) keeps its last value.
std::pair<analysis::TabulatedLoad<T>, analysis::TabulatedLoad<T>> read_force_law(const std::filesystem::path& file) {
  const auto table = io::read_csv(file);
  std::vector<T> angle = table.column("inclination_deg");
  for (T& a : angle) a *= std::numbers::pi_v<T> / 180;
  const std::vector<T> normal = table.column("normal_load"), tangential = table.column("tangential_load");
  if (angle.empty()) throw InputError(fmt::format("--force-law {}: no rows", file.string()));
  return {analysis::TabulatedLoad<T>(angle, normal, T(0)),
          analysis::TabulatedLoad<T>(angle, tangential, tangential.back())};
}

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "blade_in_current: a flexible blade towed through still water (a steady current); effective "
                      "length l_e / l = F / F_rigid against Luhar & Nepf (2011).");
  Options o;
  o.speed = cli.get_number("speed", o.speed, "towing speed U, m/s");
  o.length = cli.get_number("length", o.length, "blade length l, m");
  o.thickness = cli.get_number("thickness", o.thickness, "blade thickness t, m");
  o.density = cli.get_number("blade-density", o.density,
                             "blade density rho_s, kg/m^3 (its inertia only: g = 0; sets the mass ratio rho_s t / "
                             "(rho l)), [100, 1e6]");
  o.particles_along = cli.get_number("resolution", o.particles_along, "fluid particles along the blade, l / dp");
  o.rod_spacing = cli.get_number("rod-spacing", o.rod_spacing, "rod node spacing / dp, [0.05, 2]");
  o.rod_damping = cli.get_number("rod-damping", o.rod_damping,
                                 "the rod's damping rate c_d relative to the towing carriage, 1/s: damps the blade's "
                                 "flutter, leaves its static posture (0: none), [0, 1000]");
  o.tow_lengths = cli.get_number("tow-lengths", o.tow_lengths, "towing distance after the ramp, blade lengths");
  o.velocity_factor = cli.get_switch("velocity-factor", false, "eps(u_perp) of eq. 23 in the blade coupling: on | off");
  o.normal_damping =
      cli.get_number("normal-damping", 0, "beta of the blade coupling's normal dashpot (rate beta c0 / h), 0-1");
  o.coupling = cli.get("coupling", o.coupling,
                       "blade coupling: repulsive (the blade an obstacle, eqs 17-23) | drag (porous: its Morison drag "
                       "with --blade-cd, the model's own drag law)");
  o.blade_cd = cli.get_number("blade-cd", o.blade_cd, "C_D of --coupling drag");
  o.frontal_fraction = cli.get_number(
      "frontal-fraction", o.frontal_fraction,
      "--coupling drag: share phi of the channel's width the blade covers (b / W; 1: a full-width row), (0, 1]");
  o.visibility = cli.get_switch("visibility", true,
                                "on: fluid pairs across the blade do not interact (visibility criterion) | off");
  o.guard =
      cli.get_switch("guard", true, "on: a fluid particle that steps through the blade is put back on its face | off");
  o.contact_gap =
      cli.get_number("contact-gap", 2,
                     "resolved blade: its contact plane's height above the bed, in fluid spacings, [0.5, 10] "
                     "(session 4-7 runs: 1)");
  require_in_range("--contact-gap", o.contact_gap, T(0.5), T(10));
  o.anchor = cli.get_number("anchor", 0,
                            "resolved blade: its structure continues this far into the bed, in fluid spacings, "
                            "clamped, so that the visibility criterion parts the wall under its two faces "
                            "(0: none), [0, 3]");
  require_in_range("--anchor (fluid spacings)", o.anchor, T(0), T(3));
  o.global_step =
      cli.get_switch("global-step", false,
                     "on: the fluid steps with the rod's stable step (no sub-cycling; for the cost comparison) | off");
  o.sound_speed = cli.get_number("sound-speed", o.sound_speed,
                                 "the fluid's artificial sound speed c0 over the towing speed U, [10, 200]");
  require_in_range("--sound-speed (c0 / U)", o.sound_speed, T(10), T(200));
  o.artificial_viscosity =
      cli.get_number("alpha", o.artificial_viscosity, "alpha of the artificial viscosity, nu = alpha h c0 / 8, [0, 1]");
  require_in_range("--alpha", o.artificial_viscosity, T(0), T(1));
  o.background_pressure = cli.get_number(
      "background-pressure", o.background_pressure,
      "resolved blade: the fluid's background pressure over rho U^2, which holds the fluid on the blade's "
      "lee face in the wake's suction (0: none), [0, 100]");
  require_in_range("--background-pressure (rho U^2)", o.background_pressure, T(0), T(100));
  const std::string walls = cli.get("walls", "dynamic",
                                    "wall model of the bed, side walls and lid: dynamic (boundary particles with their "
                                    "own continuity) | extrapolated (pressure from the fluid, Adami et al. 2012)");
  if (walls != "dynamic" && walls != "extrapolated")
    throw InputError(fmt::format("--walls '{}': valid are dynamic, extrapolated", walls));
  o.walls = walls == "dynamic" ? WallModel::dynamic : WallModel::extrapolated;
  o.end_time = cli.get_number("end-time", 0, "simulated time, s (0: the ramp and the whole towing distance)");
  require_non_negative("--end-time (s)", o.end_time);
  o.depth_lengths = cli.get_number("depth", o.depth_lengths, "channel depth in blade lengths (blockage 1 / depth)");
  o.average_from = cli.get_number("average-from", o.average_from, "start of the drag average, blade lengths");
  const auto cauchy = cli.get_numbers("cauchy", "0,1,3,10,30,100,300,1000", "target Cauchy numbers (0: rigid blade)");
  const auto inclinations = cli.get_numbers(
      "inclinations", "",
      "force-law sweep instead of the Cauchy sweep: rigid blades inclined by these angles from the vertical, "
      "degrees in [0, 85], leaning downstream, the first 0 (writes inclined.csv)");
  o.mount_height = cli.get_number("mount-height", 0,
                                  "force-law sweep: the rigid blades' base above the bed, blade lengths (0: on the "
                                  "bed; > 0: a plate in open water, away from the bed)");
  o.clamp_middle = cli.get_switch(
      "clamp-middle", false,
      "on: a double blade of length --length clamped at its middle, its lower end --mount-height above the bed: each "
      "half mirrors the other, a blade of half the length on a free-slip plane without the bed's wall particles "
      "(Ca for the half) | off");
  o.force_law = cli.get("force-law", "",
                        "inclined.csv of a force-law sweep: the static reconfiguration under that measured local law "
                        "is added to the Cauchy sweep's summary (column model_2d)");
  o.static_only =
      cli.get_switch("static-only", false,
                     "on: no run; for each Ca of --cauchy (the Cauchy numbers themselves, with the measured C_D in "
                     "them) print Luhar & Nepf's fit, their static balance and the static balance under the law of "
                     "--force-law");
  o.three_d = cli.get_switch("three-d", false,
                             "on: a 3D channel with a strip of width --blade-width (a ribbon: the water passes its "
                             "sides) | off: the 2D full-width blade");
  o.blade_width = cli.get_number("blade-width", o.blade_width, "blade width b, m (2D: the drag blade's added mass)");
  o.channel_width = cli.get_number("channel-width", o.channel_width, "--three-d: channel width W / b, [2, 50]");
  o.width_particles = static_cast<int>(cli.get_number(
      "width-particles", 0, "--three-d: particles across the strip's width (0: b / (rod spacing), at least 2)"));
  o.rigid_from = cli.get("rigid-from", "",
                         "summary.csv of an earlier sweep of the same scene: its rigid blade's drag is the reference "
                         "(--cauchy then need not start with 0)");
  o.output = cli.get("output", o.output.string(), "output folder");
  if (!cli.finish()) return 0;
  require_positive("--speed (m/s)", o.speed);
  if (o.coupling != "repulsive" && o.coupling != "drag")
    throw InputError(fmt::format("--coupling '{}': valid are repulsive, drag", o.coupling));
  require_positive("--length (m)", o.length);
  require_positive("--thickness (m)", o.thickness);
  require_in_range("--blade-density (kg/m^3)", o.density, T(100), T(1e6));
  require_in_range("--resolution (l / dp)", o.particles_along, T(5), T(200));
  require_in_range("--rod-spacing (ds / dp)", o.rod_spacing, T(0.05), T(2));
  require_in_range("--rod-damping (c_d, 1/s)", o.rod_damping, T(0), T(1000));
  require_in_range("--depth (blade lengths)", o.depth_lengths, T(1.5), T(20));
  require_in_range("--average-from (blade lengths)", o.average_from, T(0), o.tow_lengths - T(1));
  require_positive("--blade-width (m)", o.blade_width);
  require_in_range("--channel-width (W / b)", o.channel_width, T(2), T(50));
  require_in_range("--width-particles", o.width_particles, 0, 64);
  if (o.clamp_middle && !(o.mount_height > 0))
    throw InputError("--clamp-middle: the double blade needs --mount-height > 0 (its lower end above the bed)");
  require_in_range("--mount-height (blade lengths)", o.mount_height, T(0), o.depth_lengths - T(1));
  if (o.three_d && o.coupling != "repulsive")
    throw InputError("--three-d: the strip is coupled by --coupling repulsive only (the drag blade is 2D)");
  o.cauchy.assign(cauchy.begin(), cauchy.end());
  o.inclinations.assign(inclinations.begin(), inclinations.end());
  std::filesystem::create_directories(o.output);
  if (!o.inclinations.empty()) return o.three_d ? run_force_law_sweep<3>(o) : run_force_law_sweep<2>(o);
  if (o.static_only) {  // the static blade under the model's law and under a measured one, no SPH run
    if (o.force_law.empty()) throw InputError("--static-only on needs --force-law (an inclined.csv)");
    if (o.cauchy.empty()) throw InputError("--static-only on needs --cauchy (one or more Cauchy numbers)");
    for (const T ca : o.cauchy) require_in_range("--cauchy (with --static-only)", ca, T(1e-3), T(1e6));
    const auto law = read_force_law(o.force_law);
    fmt::print("| Ca | l_e / l fit | static, cos^2 | static, measured law |\n|---|---|---|---|\n");
    for (const T ca : o.cauchy) {
      fmt::print("| {:g} | {:.4f} | {:.4f} | {:.4f} |\n", ca, analysis::luhar_nepf_effective_length_fit(ca),
                 analysis::luhar_nepf_reconfiguration(ca).effective_length,
                 analysis::static_reconfiguration(ca, law.first, law.second).effective_length);
    }
    return 0;
  }
  if (o.cauchy.empty() || (o.end_time == 0 && o.rigid_from.empty() && o.cauchy.front() != 0))
    throw InputError(
        "--cauchy must start with 0 (the rigid blade that every l_e / l is measured against), or give --rigid-from");
  // The measured local law, read before the runs so that a bad file stops at once.
  std::optional<std::pair<analysis::TabulatedLoad<T>, analysis::TabulatedLoad<T>>> law;
  if (!o.force_law.empty()) law = read_force_law(o.force_law);

  std::vector<CaseResult> results;
  if (!o.rigid_from.empty()) {  // the reference from an earlier sweep's rigid row
    const auto table = io::read_csv(o.rigid_from);
    const auto target = table.column("target_ca"), drag = table.column("drag"), error = table.column("drag_error");
    const auto row = std::find(target.begin(), target.end(), T(0));
    if (row == target.end())
      throw InputError(fmt::format("--rigid-from {}: no rigid row (target_ca = 0)", o.rigid_from.string()));
    const std::size_t k = std::size_t(row - target.begin());
    const T nan = std::numeric_limits<T>::quiet_NaN();
    results.push_back({0, nan, drag[k], error[k], 0, o.length, nan, 0, 0, nan, nan, 0, nan});
    if (o.cauchy.front() == 0) o.cauchy.erase(o.cauchy.begin());
  }
  for (const T ca : o.cauchy) {
    fmt::print("--- {}\n", ca > 0 ? fmt::format("Ca = {:g}", ca) : std::string("rigid blade"));
    try {
      results.push_back(o.three_d              ? run_case<3, RepulsiveForce<T>>(o, ca)
                        : o.coupling == "drag" ? run_case<2, BladeDrag<T>>(o, ca)
                                               : run_case<2, RepulsiveForce<T>>(o, ca));
    } catch (const BlowUpError& e) {  // a failed case is a result: reported in the table, the others still run
      if (ca == 0) throw;             // without the rigid reference there is nothing to compare with
      fmt::print(stderr, "Ca = {:g}: run stopped: {}\n", ca, e.what());
      const T nan = std::numeric_limits<T>::quiet_NaN();
      results.push_back({ca, nan, nan, nan, nan, nan, 0, 0, 0, nan, nan, nan, nan});
    }
  }
  if (o.end_time > 0) {  // a short run (the sub-cycling comparison): cost only, the records are in case_*.csv
    fmt::print(
        "| target Ca | E (Pa) | F (N/m) | tip (dx, dy)/l | fluid steps | wall (s) |\n|---|---|---|---|---|---|\n");
    for (const auto& r : results)
      fmt::print("| {:g} | {:.3g} | {:.4g} +- {:.2g} | ({:.2f}, {:.2f}) | {} | {:.1f} |\n", r.target_ca,
                 r.youngs_modulus, r.drag, r.drag_error, r.tip_x / o.length, r.tip_y / o.length, r.steps, r.wall);
    return 0;
  }
  const T rigid = results.front().drag, rho = 1000;
  // in 3D the drag is the strip's (N), in 2D per unit width (N/m)
  const T frontal = o.three_d ? o.length * o.blade_width : o.length;
  const T drag_coefficient = rigid / (T(0.5) * rho * o.speed * o.speed * frontal);
  fmt::print("rigid blade: F = {:.4g} +- {:.2g} {}, C_D = {:.3f} (blockage {:.3g} included)\n", rigid,
             results.front().drag_error, o.three_d ? "N" : "N/m", drag_coefficient,
             o.three_d ? 1 / (o.depth_lengths * o.channel_width) : 1 / o.depth_lengths);
  io::CsvWriter summary(
      o.output / "summary.csv",
      {"target_ca", "ca", "youngs_modulus", "drag", "drag_error", "effective_length", "effective_length_error", "model",
       "model_static", "model_2d", "tip_dx", "tip_dy", "tip_dy_rms", "steps", "particles", "wall_s", "fluid_under"});
  fmt::print(
      "| Ca | E (Pa) | F (N/m) | l_e/l SPH | l_e/l model (fit) | deviation | static model | measured-law model (SPH's "
      "deviation) | tip (dx, dy)/l | tip height rms / l | fluid under / l^2 | wall (s) |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  T worst = 0;
  for (const auto& r : results) {
    const T ca = r.target_ca > 0 ? r.target_ca * drag_coefficient / o.nominal_drag : 0;
    const T le = r.drag / rigid;
    const T le_err = le * std::hypot(r.drag_error / r.drag, results.front().drag_error / rigid);
    const T model = ca > 0 ? analysis::luhar_nepf_effective_length_fit(ca) : T(1);
    const T model_static = ca > 0 ? analysis::luhar_nepf_reconfiguration(ca).effective_length : T(1);
    const T model_2d = !law     ? std::numeric_limits<T>::quiet_NaN()
                       : ca > 0 ? analysis::static_reconfiguration(ca, law->first, law->second).effective_length
                                : T(1);
    if (ca > 0) worst = std::max(worst, std::abs(le - model) / model);
    summary.write_row({r.target_ca, ca, r.youngs_modulus, r.drag, r.drag_error, le, le_err, model, model_static,
                       model_2d, r.tip_x, r.tip_y, r.tip_height_rms, T(r.steps), T(r.particles), r.wall,
                       r.fluid_under});
    fmt::print(
        "| {} | {:.3g} | {:.4g} | {:.3f} +- {:.3f} | {:.3f} | {:+.1f} % | {:.3f} | {} | ({:.2f}, {:.2f}) | {:.2f} | "
        "{:.3f} | {:.0f} |\n",
        ca > 0 ? fmt::format("{:.3g}", ca) : std::string("rigid"), r.youngs_modulus, r.drag, le, le_err, model,
        ca > 0 ? 100 * (le - model) / model : 0.0, model_static,
        law ? fmt::format("{:.3f} ({:+.1f} %)", model_2d, 100 * (le - model_2d) / model_2d) : std::string("-"),
        r.tip_x / o.length, r.tip_y / o.length, r.tip_height_rms / o.length, r.fluid_under, r.wall);
  }
  fmt::print("largest deviation from Luhar & Nepf: {:.1f} % ({} particles, dp = {:.3g} m)\n", 100 * worst,
             results.front().particles, o.length / o.particles_along);
  const std::string plot =
      fmt::format("/usr/bin/python3 {}/examples/blade_in_current/plot.py {}", SPHFSI_SOURCE_DIR, o.output.string());
  if (std::system(plot.c_str()) != 0) fmt::print("(plot skipped: /usr/bin/python3 with matplotlib not available)\n");
  return 0;
} catch (const std::exception& e) {
  fmt::print(stderr, "blade_in_current: error: {}\n", e.what());
  return 1;
}
