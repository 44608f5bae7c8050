// sphfsi example: the Antoci et al. (2007) dam break through an elastic rubber gate, the README's main example.
//
// Water (Table 1: A = 0.1 m, H = 0.14 m) pushes open a rubber gate (L = 0.079 m, s = 0.005 m, Table 2:
// rho = 1100 kg/m^3, E = 12 MPa, nu = 0.4) clamped at its top. The gate's free-end displacement (dx, dy) is
// compared with the experiment at t = 0.04 ... 0.36 s and plotted with the published simulations.
// Choose the coupling (--coupling stress|interface|repulsive) and the solid model (--solid tl|ul) at run time:
// one small switch below instantiates the chosen pair of compile-time policies.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/coupling/coupled_body.hpp>
#include <sphfsi/coupling/interface_pressure.hpp>
#include <sphfsi/coupling/repulsive_force.hpp>
#include <sphfsi/coupling/stress_continuity.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/io/checkpoint.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/io/progress.hpp>
#include <sphfsi/io/vtk_writer.hpp>
#include <sphfsi/kernel/cubic_spline.hpp>
#include <sphfsi/scenes/antoci_gate.hpp>
#include <sphfsi/scenes/gate_tip_comparison.hpp>
#include <sphfsi/solid/total_lagrangian.hpp>
#include <sphfsi/solid/updated_lagrangian.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>

using namespace sphfsi;
using Scalar = double;
using System = ParticleSystem<2, Scalar, CubicSpline<2>, Tait<Scalar>>;  // the paper's kernel, Tait water
using TotalLagrangian = TotalLagrangianSolid<System>;
using UpdatedLagrangian = UpdatedLagrangianSolid<System>;

struct Options {
  scenes::AntociGate<Scalar> scene;
  Scalar end_time = 0.4, snapshot_interval = 0.02;
  std::filesystem::path output;
  std::string data_dir;
  Scalar max_rms_dx = 1, max_rms_dy = 1;  // m; the exit status is non-zero above these
  Scalar checkpoint_interval = 0;         // s of simulated time between checkpoints (0: none)
  bool resume = false;                    // continue from <output>/antoci_gate.chk
  bool gray_monaghan_swift = false;       // --solid ul-gms: the paper's eq. 13 sums (GMS 2001) instead of corrected
};

// The gate's solid model with gravity and a stretch limit (a gate stretched 3x has broken: stop with a diagnosis).
template <class Solid>
Solid make_gate(const System& system, const scenes::AntociGate<Scalar>& scene, std::int32_t body,
                bool gray_monaghan_swift) {
  typename Solid::Parameters params;
  params.gravity = Vec<2, Scalar>(0, -scene.gravity);
  params.stretch_limit = 3;
  if constexpr (std::is_same_v<Solid, UpdatedLagrangian>) {
    if (gray_monaghan_swift) {  // the reference paper's eq. 13 as published: current-configuration sums
      params.formulation = UpdatedLagrangianFormulation::gray_monaghan_swift;
      params.artificial_stress = 0.3;  // Monaghan's artificial stress against tensile instability
    }
  }
  return Solid(system, body, scene.solid_material(), params);
}

template <class Solid, class Coupling>
int run(const Options& opt, const Coupling& coupling) {
  const auto& scene = opt.scene;
  System system(scene.domain(), Tait<Scalar>(scene.fluid_density, scene.fluid_sound_speed));
  const scenes::AntociGateIds ids = scenes::build_antoci_gate(system, scene);

  Solid solid = make_gate<Solid>(system, scene, ids.gate_body, opt.gray_monaghan_swift);
  // The clamp: the rows above the clamp plane are embedded in the rigid wall. The total-Lagrangian model moves them
  // as the mirror image of the free part (the clamp acts on the wall plane); the other model holds them at rest.
  const Scalar clamp_y = scene.clamp_height();
  if constexpr (requires { solid.clamp_by_reflection(Vec<2, Scalar>(), Vec<2, Scalar>()); })
    solid.clamp_by_reflection(Vec<2, Scalar>(0, clamp_y), Vec<2, Scalar>(0, -1));
  else solid.clamp_where([&](const Vec<2, Scalar>& X) { return X[1] > clamp_y; });
  using Gate = CoupledBody<Coupling, Solid>;
  Simulation<System, SymplecticVerlet, Gate> sim(system, scene.fluid(), {}, Gate(coupling, std::move(solid)));

  fmt::print(
      "Antoci gate, {} coupling, {} solid: dp = {:.4g} m (gate {:.4g} m), {} fluid, {} wall, {} solid particles; "
      "c0 fluid {} m/s, solid P-wave {:.3g} m/s\n",
      Coupling::name,
      std::is_same_v<Solid, TotalLagrangian>
          ? "total-Lagrangian"
          : (opt.gray_monaghan_swift ? "updated-Lagrangian (GMS 2001 sums)" : "updated-Lagrangian"),
      scene.dp(), scene.solid_dp(), system.particles().count(Kind::fluid), system.particles().count(Kind::wall),
      system.particles().count(Kind::solid), scene.fluid_sound_speed, scene.solid_material().p_wave_speed());

  std::filesystem::create_directories(opt.output);
  const Vec<2, Scalar> tip0 = scenes::gate_tip_position(system.particles(), ids.tip);  // built scene: the rest state
  // Checkpoint / restart (io/checkpoint.hpp): the whole state, solid included, in one file replaced atomically;
  // a resumed run continues bit-identically and keeps the tip record written up to the checkpoint.
  const std::filesystem::path checkpoint = opt.output / "antoci_gate.chk";
  scenes::GateTipRecord<Scalar> record;
  std::vector<std::vector<Scalar>> earlier_rows;
  Scalar max_stretch = 1;
  std::size_t max_inside = 0;
  if (opt.resume) {
    io::read_checkpoint(checkpoint, sim);
    const io::CsvTable old = io::read_csv(opt.output / "gate_tip.csv");
    const auto t = old.column("t"), dx = old.column("dx"), dy = old.column("dy"), st = old.column("max_stretch"),
               in = old.column("fluid_inside_gate");
    for (std::size_t k = 0; k < t.size() && t[k] <= sim.time() + 1e-12; ++k) {
      earlier_rows.push_back({t[k], dx[k], dy[k], st[k], in[k]});
      record.add(t[k], dx[k], dy[k]);
      max_stretch = std::max(max_stretch, st[k]);
      max_inside = std::max(max_inside, static_cast<std::size_t>(in[k]));
    }
    fmt::print("resumed from {} at t = {:.4f} s, step {}\n", checkpoint.string(), sim.time(), sim.step_count());
  }
  io::CsvWriter tip_csv(opt.output / "gate_tip.csv", {"t", "dx", "dy", "max_stretch", "fluid_inside_gate"});
  for (const auto& row : earlier_rows) tip_csv.write_row(row);
  // A resumed run writes its snapshots as a series of its own (the first run's .pvd stays as it was).
  io::VtkSeriesWriter vtk(
      opt.output, opt.resume ? fmt::format("antoci_gate_resumed_at_{:.4f}s", sim.time()) : std::string("antoci_gate"));
  const Scalar sample_interval = 0.002;
  std::size_t samples = earlier_rows.size();  // sample k is taken at the first step with t >= k sample_interval
  Scalar next_sample = sample_interval * Scalar(samples);
  Scalar next_snapshot = sim.time(), next_checkpoint = sim.time() + opt.checkpoint_interval;
  std::string failure;
  const auto start = std::chrono::steady_clock::now();
  io::ProgressReporter progress(opt.end_time);  // one line in place on a terminal, periodic lines in logs
  try {
    sim.run(opt.end_time, [&](auto& s) {
      progress(s);
      if (opt.checkpoint_interval > 0 && s.time() + 1e-12 >= next_checkpoint) {
        io::write_checkpoint(checkpoint, s);  // only states that passed the step's checks get here
        next_checkpoint += opt.checkpoint_interval;
      }
      if (s.time() + 1e-12 < next_sample) return;
      const auto& p = s.system().particles();
      const Vec<2, Scalar> d = scenes::gate_tip_position(p, ids.tip) - tip0;
      const Scalar stretch = s.template model<0>().solid().max_stretch();
      const std::size_t inside = scenes::fluid_particles_inside_solid(s.system(), ids.gate_body);
      max_stretch = std::max(max_stretch, stretch);
      max_inside = std::max(max_inside, inside);
      record.add(s.time(), d[0], d[1]);
      tip_csv.write_row({s.time(), d[0], d[1], stretch, Scalar(inside)});
      next_sample = sample_interval * Scalar(++samples);
      if (s.time() + 1e-12 >= next_snapshot) {
        vtk.write(p, s.time());
        next_snapshot += opt.snapshot_interval;
      }
    });
  } catch (const BlowUpError& e) {
    failure = e.what();
    fmt::print(stderr, "run stopped: {}\n", failure);
    vtk.write(system.particles(), sim.time());
  }
  progress.finish(sim);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto cmp = scenes::compare_gate_tip(record, io::read_csv(opt.data_dir + "/antoci2007_gate_tip_experiment.csv"),
                                            opt.end_time);
  fmt::print("{} steps to t = {:.3f} s in {:.1f} s wall ({:.2f} million particle-steps/s)\n", sim.step_count(),
             sim.time(), wall, double(system.size()) * double(sim.step_count()) / wall * 1e-6);
  fmt::print(
      "RMS error vs experiment at t = 0.04 ... {:.2f} s ({} points): dx {:.2f} mm, dy {:.2f} mm "
      "(Antoci 2007 SPH: 3.9 / 1.8 mm)\n",
      std::min(0.36, opt.end_time), cmp.points, 1e3 * cmp.rms_dx, 1e3 * cmp.rms_dy);
  fmt::print("failure flags: max stretch {:.3f}, fluid particles inside the gate (max) {}, blow-up: {}\n", max_stretch,
             max_inside, failure.empty() ? "no" : failure);
  io::CsvWriter summary(opt.output / "summary.csv", {"rms_dx", "rms_dy", "wall_s", "steps", "particles", "max_stretch",
                                                     "fluid_inside_max", "blew_up", "end_time"});
  summary.write_row({cmp.rms_dx, cmp.rms_dy, wall, Scalar(sim.step_count()), Scalar(system.size()), max_stretch,
                     Scalar(max_inside), failure.empty() ? 0.0 : 1.0, sim.time()});
  const std::string plot = fmt::format("/usr/bin/python3 {}/examples/antoci_gate/plot.py {} {}", SPHFSI_SOURCE_DIR,
                                       opt.output.string(), opt.data_dir);
  if (std::system(plot.c_str()) != 0) fmt::print("(plot skipped: /usr/bin/python3 with matplotlib not available)\n");
  if (!failure.empty()) return 3;
  if (!(cmp.rms_dx <= opt.max_rms_dx && cmp.rms_dy <= opt.max_rms_dy)) {
    fmt::print("FAIL: RMS error above the limits --max-rms-dx {} mm / --max-rms-dy {} mm\n", 1e3 * opt.max_rms_dx,
               1e3 * opt.max_rms_dy);
    return 2;
  }
  fmt::print("PASS: within --max-rms-dx {} mm and --max-rms-dy {} mm\n", 1e3 * opt.max_rms_dx, 1e3 * opt.max_rms_dy);
  return 0;
}

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "antoci_gate: dam break through an elastic gate (Antoci et al. 2007); gate tip displacement vs "
                      "the experiment.");
  Options opt;
  const std::string coupling = cli.get("coupling", "repulsive", "FSI coupling: stress | interface | repulsive");
  const std::string solid = cli.get(
      "solid", "tl", "solid model: tl (total Lagrangian) | ul (updated Lagrangian) | ul-gms (eq. 13 sums of GMS 2001)");
  opt.scene.particles_across =
      cli.get_number("resolution", 80, "particles across the water column A/dp (multiple of 20)");
  opt.scene.solid_refinement = static_cast<int>(
      cli.get_number("solid-refinement", 1, "gate particle spacing dp / this: 1, 2 or 4 (finer solid than fluid)"));
  opt.scene.fluid_sound_speed = cli.get_number("fluid-sound-speed", 20, "fluid reference sound speed c0, m/s");
  opt.scene.youngs_modulus = cli.get_number("youngs-modulus", 1.2e7, "gate Young's modulus E, Pa");
  opt.scene.smoothing_ratio =
      cli.get_number("smoothing", opt.scene.smoothing_ratio, "smoothing length over spacing h / dp (fluid and gate)");
  const Scalar cli_normal_damping = cli.get_number(
      "normal-damping", 0, "repulsive coupling: beta of the normal dashpot, 0-1 (0: the paper's eqs 17-23)");
  const std::string interface_form =
      cli.get("interface-form", "integral",
              "interface coupling: integral (eqs 3, 10-16 over every solid particle near the interface) | "
              "surface-mirror (eqs 10-16 as printed: surface row, mirror-point reaction)");
  const std::string plane = cli.get(
      "plane", "strain", "2D gate: strain (plane strain, a wide plate) | stress (plane stress, free to contract)");
  opt.end_time = cli.get_number("end-time", 0.4, "simulated time, s");
  opt.snapshot_interval = cli.get_number("snapshot-interval", 0.02, "time between VTK snapshots, s");
  opt.output = cli.get("output", "out/antoci_gate", "output folder");
  opt.checkpoint_interval = cli.get_number(
      "checkpoint-interval", 0, "write <output>/antoci_gate.chk every this many simulated seconds (0: never)");
  opt.resume =
      cli.get("resume", "no", "yes: continue from <output>/antoci_gate.chk (same flags as the first run)") == "yes";
  opt.data_dir = cli.get("data", SPHFSI_SHARED_DATA_DIR, "folder with antoci2007_gate_tip_*.csv");
  opt.max_rms_dx =
      1e-3 * cli.get_number("max-rms-dx", 1000, "exit with status 2 if the RMS error in dx exceeds this, mm");
  opt.max_rms_dy =
      1e-3 * cli.get_number("max-rms-dy", 1000, "exit with status 2 if the RMS error in dy exceeds this, mm");
  if (!cli.finish()) return 0;
  require_positive("--end-time (s)", opt.end_time);
  require_non_negative("--checkpoint-interval (s)", opt.checkpoint_interval);
  if (solid != "tl" && solid != "ul" && solid != "ul-gms")
    throw InputError(fmt::format("--solid = '{}' is invalid: valid values are tl, ul, ul-gms", solid));
  opt.gray_monaghan_swift = solid == "ul-gms";
  if (plane != "strain" && plane != "stress")
    throw InputError(fmt::format("--plane = '{}' is invalid: valid values are strain, stress", plane));
  opt.scene.plane_stress = plane == "stress";
  if (interface_form != "integral" && interface_form != "surface-mirror")
    throw InputError(
        fmt::format("--interface-form = '{}' is invalid: valid values are integral, surface-mirror", interface_form));
  InterfacePressure<Scalar> interface;
  interface.form = interface_form == "integral" ? InterfaceForm::integral : InterfaceForm::surface_mirror;
  // eps(z) of eq. 22 scales the repulsion with the depth below the still-water level, like hydrostatic pressure.
  RepulsiveForce<Scalar> repulsive;
  repulsive.water_level = opt.scene.column_height;
  repulsive.local_depth = opt.scene.column_height;
  // Strength k of eq. 19 such that the still column is in equilibrium with the gate at t = 0 (first fluid row at
  // dp from the gate's surface particles): 0.0036 for c0 = 20 m/s, instead of the paper's 0.01 which kicks the gate.
  // A finer gate (spacing ds = dp / r) has its surface particles ds / 2 inside its face: the first fluid row is
  // (dp + ds) / 2 from them, and a fluid-solid pair uses the averaged smoothing length h_ab = (h_f + h_s) / 2.
  const Scalar fine = (1 + 1 / Scalar(opt.scene.solid_refinement)) / 2;
  repulsive.normal_damping = cli_normal_damping;
  repulsive.strength = repulsive_strength_for_rest_gap(
      opt.scene.column_height, opt.scene.gravity, opt.scene.fluid_sound_speed, opt.scene.smoothing_ratio * fine, fine);
  const bool tl = solid == "tl";
  if (coupling == "stress")
    return tl ? run<TotalLagrangian>(opt, StressContinuity<Scalar>{})
              : run<UpdatedLagrangian>(opt, StressContinuity<Scalar>{});
  if (coupling == "interface")
    return tl ? run<TotalLagrangian>(opt, interface) : run<UpdatedLagrangian>(opt, interface);
  if (coupling == "repulsive")
    return tl ? run<TotalLagrangian>(opt, repulsive) : run<UpdatedLagrangian>(opt, repulsive);
  throw InputError(
      fmt::format("--coupling = '{}' is invalid: valid values are stress, interface, repulsive", coupling));
} catch (const std::exception& e) {
  fmt::print(stderr, "antoci_gate: error: {}\n", e.what());
  return 1;
}
