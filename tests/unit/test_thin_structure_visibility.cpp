// Tests of the visibility criterion across thin structures (fluid/thin_structure_visibility.hpp): the segment test,
// the pairs it hides against a brute-force search, and that the fluid on one face of a held blade no longer feels
// the other face through its sums. And of the guard that keeps fluid particles on their face
// (fluid/thin_structure_guard.hpp): which moves it treats as crossings (geometry, one step by hand), and a jet
// against a held blade whose repulsion is too weak to stop it: without the guard the water goes through the blade,
// with it none does.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/coupling/blade_drag.hpp>
#include <sphfsi/coupling/coupled_body.hpp>
#include <sphfsi/coupling/repulsive_force.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/fluid/thin_structure_guard.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/solid/elastic_rod.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

using namespace sphfsi;

namespace {

using System = ParticleSystem<2, double, WendlandC2<2>, Tait<double>>;
using V = Vec<2, double>;
using Rod = ElasticRod<System>;
using Body = CoupledBody<RepulsiveForce<double>, Rod>;
using Visibility = ThinStructureVisibility<double>;

ElasticMaterial<double> blade_material() { return {.density = 950, .youngs_modulus = 1e8, .poisson_ratio = 0.3}; }
RodSection<double> blade_section() { return RodSection<double>{.thickness = 4e-4, .width = 0.01}; }

std::vector<StructureEdge> chain_edges(const std::vector<std::uint32_t>& ids) {
  std::vector<StructureEdge> edges;
  for (std::size_t k = 0; k + 1 < ids.size(); ++k) edges.push_back({ids[k], ids[k + 1]});
  return edges;
}

}  // namespace

TEST_CASE("segments_cross: proper crossings only", "[visibility]") {
  const V a(0, 0), b(1, 0);
  CHECK(Visibility::segments_cross(V(0.5, -1), V(0.5, 1), a, b));
  CHECK(Visibility::segments_cross(V(0.2, 0.3), V(0.7, -0.1), a, b));
  CHECK_FALSE(Visibility::segments_cross(V(0.5, 0.1), V(0.5, 1), a, b));  // ends short of the edge
  CHECK_FALSE(Visibility::segments_cross(V(1.5, -1), V(1.5, 1), a, b));   // beyond the edge's end
  CHECK_FALSE(Visibility::segments_cross(V(0.5, 0), V(0.5, 1), a, b));    // a particle on the edge: not crossing
  // A pair through the node between two edges (a chain bending there or running straight) is hidden by one edge.
  const V node(1, 0), next(2, 1), bent(2, -1), straight(2, 0);
  for (const V& c : {next, bent, straight}) {
    const int hits = int(Visibility::segments_cross(V(1, -1), V(1, 1), a, node)) +
                     int(Visibility::segments_cross(V(1, -1), V(1, 1), node, c));
    CHECK(hits >= 1);
  }
  CHECK(int(Visibility::segments_cross(V(1, -1), V(1, 1), a, node)) +
            int(Visibility::segments_cross(V(1, -1), V(1, 1), node, straight)) ==
        1);
  CHECK_FALSE(Visibility::segments_cross(V(0, 0.2), V(1, 0.2), a, b));  // parallel
}

TEST_CASE("thin-structure visibility hides exactly the pairs that cross a bent blade", "[visibility]") {
  // Fluid on a jittered lattice around a bent (zigzag) blade; every pair the fluid evaluates is compared with a
  // brute-force test of its segment against every edge.
  System system(Domain<2, double>(V(-0.1, -0.1), V(0.2, 0.2)), Tait<double>(1000, 20));
  const Resolution<double> res{0.005, 2.0};
  add_fluid_block(system, V(0, 0), V(0.1, 0.1), res, 0.1, 9.81);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.2 * res.dp, 0.2 * res.dp);
  for (auto& x : system.particles().position) x += V(u(rng), u(rng));
  // Blade nodes at half the fluid spacing, bent into a zigzag between x = 0.045 and 0.055.
  const int nodes = 41;
  add_elastic_rod(system, V(0.05, 0.0), V(0, 1), 0.08, nodes, blade_material(), blade_section(), res.h(), 1);
  auto& p = system.particles();
  std::vector<StructureEdge> edges;
  std::vector<std::uint32_t> node_ids;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::solid) node_ids.push_back(p.id[i]);
  std::sort(node_ids.begin(), node_ids.end());
  for (std::size_t k = 0; k < node_ids.size(); ++k)
    p.position[p.slot_of_id(node_ids[k])][0] += (k % 2 ? 1 : -1) * 0.4 * res.dp;
  for (std::size_t k = 0; k + 1 < node_ids.size(); ++k) edges.push_back({node_ids[k], node_ids[k + 1]});
  system.update_neighbors(0.0);
  Visibility visibility;
  visibility.set_edges(edges);
  visibility.update(system);
  std::size_t pairs = 0, hidden = 0, mismatches = 0;
  for (std::size_t a = 0; a < p.size(); ++a) {
    if (p.kind[a] == Kind::solid) continue;
    system.for_each_neighbor_once(a, [&](std::size_t b, const V&, double, double) {
      if (p.kind[b] == Kind::solid) return;
      ++pairs;
      bool brute = false;
      for (const auto& e : edges)
        brute = brute || Visibility::segments_cross(p.position[a], p.position[b], p.position[p.slot_of_id(e[0])],
                                                    p.position[p.slot_of_id(e[1])]);
      const bool found =
          (visibility.near(a) || visibility.near(b)) && visibility.blocks(a, b, p.position[a], p.position[b]);
      hidden += brute;
      mismatches += brute != found;
    });
  }
  INFO(pairs << " pairs, " << hidden << " hidden by the blade");
  CHECK(hidden > 500);  // the blade cuts the block: many pairs cross it
  CHECK(mismatches == 0);
  // An edge too long for the candidate search (its nodes' supports would not cover every crossing) is an error.
  p.position[p.slot_of_id(node_ids[20])] += V(0.05, 0);
  CHECK_THROWS_WITH(visibility.update(system), Catch::Contains("edge 19") && Catch::Contains("valid range"));
}

TEST_CASE("thin-structure visibility: the fluid beside a held blade does not feel the other face", "[visibility]") {
  // Still water on the left of a held blade, none on the right except a block of fast particles just across it:
  // without the criterion, their pressure and viscosity reach the left water through the blade.
  // Fluid forces on the left water (gravity removed), with or without the criterion; and the edges the fluid got.
  const auto left_force = [](bool visibility) {
    System system(Domain<2, double>(V(-0.05, -0.05), V(0.25, 0.2)), Tait<double>(1000, 20));
    const Resolution<double> res{0.005, 2.0};
    add_fluid_block(system, V(0, 0), V(0.05, 0.05), res, 0.05, 9.81);
    add_fluid_block(system, V(0.055, 0), V(0.075, 0.05), res, 0.0, 9.81);
    auto& p = system.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.position[i][0] > 0.0525) {
        p.velocity[i] = V(0, 1.0);
        p.density[i] *= 1.01;  // and a higher pressure
      }
    add_elastic_rod(system, V(0.0525, 0.0), V(0, 1), 0.06, 25, blade_material(), blade_section(), res.h(), 1);
    Rod::Parameters params;
    params.section = blade_section();
    Rod rod(system, 1, blade_material(), params);
    rod.clamp_where([](const V&) { return true; });
    FluidParameters<2, double> fluid;
    fluid.thin_structure_visibility = visibility;
    Simulation<System, SymplecticVerlet, Body> sim(system, fluid, {}, Body(RepulsiveForce<double>{}, std::move(rod)));
    sim.evaluate_rates(0.0);
    V force = V::Zero();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.kind[i] == Kind::fluid && p.position[i][0] < 0.0525) force += p.mass[i] * (p.acceleration[i] - V(0, -9.81));
    return std::pair{force, sim.fluid().structure_visibility().edges().size()};
  };
  const auto [open, edges_unused] = left_force(false);
  const auto [hidden, edges] = left_force(true);
  INFO("left water's fluid force: without the criterion " << open.transpose() << " N/m, with it " << hidden.transpose()
                                                          << " N/m");
  CHECK(edges == 24);  // the rod published its edges to the fluid (whether or not they are applied)
  CHECK(edges_unused == 24);
  // Through the blade the right block pulls the left water up (viscosity) and pushes it left (pressure); with the
  // criterion the only horizontal fluid force on the left water is its own free-surface imbalance (both runs have
  // it) plus the blade's repulsion, and no vertical drag from the right block remains.
  CHECK(open[1] > 0.0);
  CHECK(std::abs(hidden[1]) < 0.1 * std::abs(open[1]));
}

// ---- the guard (fluid/thin_structure_guard.hpp) ----

TEST_CASE("thin-structure guard: the swept test of a moving point against a moving edge", "[visibility][guard]") {
  using Guard = ThinStructureGuard<double>;
  const V o(0, 0), up(0, 1);
  // A still point swept over by an edge moving right: met halfway, 0.3 along it, from its right (x < 0 first).
  const auto swept = Guard::crossing(V(0.5, 0.3), V(0.5, 0.3), V(0, 0), V(1, 0), V(0, 1), V(1, 1));
  CHECK(swept.time == Approx(0.5));
  CHECK(swept.along == Approx(0.3));
  CHECK(swept.side == -1);
  CHECK(swept.offset == Approx(0.5));
  // A point moving past the end of a still edge: its line is crossed beyond the edge, no meeting.
  CHECK(Guard::crossing(V(-0.1, 1.2), V(0.1, 1.2), o, o, up, up).time < 0);
  // Starting on the line is not a crossing; ending on it is (at t = 1).
  CHECK(Guard::crossing(V(0, 0.5), V(0.1, 0.5), o, o, up, up).time < 0);
  CHECK(Guard::crossing(V(-0.1, 0.5), V(0, 0.5), o, o, up, up).time == Approx(1));
  // An edge turning about its base (0 to 90 degrees, its tip along a chord) sweeps a still point at 45 degrees:
  // the tip moves (1, 0) -> (0, 1) linearly: the point (0.4, 0.4) lies on the edge when the
  // tip is at (0.5, 0.5), t = 0.5, along = 0.4 / 0.5 = 0.8.
  const auto turned = Guard::crossing(V(0.4, 0.4), V(0.4, 0.4), o, o, V(1, 0), V(0, 1));
  CHECK(turned.time == Approx(0.5));
  CHECK(turned.along == Approx(0.8));
  CHECK(turned.side == 1);
  // A point that goes through and back within the step ends on its own side: no crossing.
  CHECK(Guard::crossing(V(-0.1, 0.5), V(-0.05, 0.5), o, o, up, up).time < 0);
}

TEST_CASE("thin-structure guard: a step through a blade is put back, a step round its tip or between blades is not",
          "[visibility][guard]") {
  System system(Domain<2, double>(V(-0.1, -0.1), V(0.2, 0.2)), Tait<double>(1000, 20));
  const double h = 0.0065;
  // Two vertical blades 0.1 m long, at x = 0 and x = 0.01, 21 nodes each (5 mm edges).
  const auto left = add_elastic_rod(system, V(0, 0), V(0, 1), 0.1, 21, blade_material(), blade_section(), h, 1);
  const auto right = add_elastic_rod(system, V(0.01, 0), V(0, 1), 0.1, 21, blade_material(), blade_section(), h, 2);
  auto& p = system.particles();
  const auto fluid = [&](V x) { return p.id[p.add(Kind::fluid, x, V::Zero(), 1000, 0.025, h)]; };
  const std::uint32_t through = fluid(V(-0.001, 0.05));    // steps through the left blade
  const std::uint32_t over_tip = fluid(V(-0.003, 0.102));  // passes over the tip (beyond the free end)
  const std::uint32_t between = fluid(V(0.0045, 0.03));    // between the blades, moves nearer the right one
  const std::uint32_t stays = fluid(V(-0.004, 0.07));      // moves along its face
  const std::uint32_t far = fluid(V(-0.05, 0.05));         // far from both: not a candidate
  std::vector<StructureEdge> edges = chain_edges(left);
  const auto right_edges = chain_edges(right);
  edges.insert(edges.end(), right_edges.begin(), right_edges.end());

  system.update_neighbors();
  ThinStructureVisibility<double> visibility;
  visibility.set_edges(edges);
  visibility.update(system);
  ThinStructureGuard<double> guard;
  // One step by hand: old positions as now, then the moves.
  for (std::size_t i = 0; i < p.size(); ++i) p.position_old[i] = p.position[i];
  const auto move = [&](std::uint32_t id, V to, V velocity) {
    p.position[p.slot_of_id(id)] = to;
    p.velocity[p.slot_of_id(id)] = velocity;
  };
  move(through, V(0.002, 0.0501), V(0.3, 0.1));
  move(over_tip, V(0.003, 0.102), V(0.3, 0));
  move(between, V(0.0055, 0.03), V(0.1, 0));
  move(stays, V(-0.0035, 0.072), V(0.05, 0.2));
  move(far, V(-0.049, 0.05), V(0.1, 0));
  // The left blade moves right by 0.5 mm over the step at 0.05 m/s: the edge velocity is what the particle keeps.
  for (const std::uint32_t id : left) {
    p.position[p.slot_of_id(id)] += V(0.0005, 0);
    p.velocity[p.slot_of_id(id)] = V(0.05, 0);
  }

  CHECK(guard.restore(p, visibility) == 1);
  CHECK(guard.crossings_prevented() == 1);
  // Back across the moved blade line x = 0.0005, at the 1 mm it was from the blade at the start of the step; the
  // normal velocity relative to the blade (0.3 - 0.05) is removed, the tangential one kept.
  const V x = p.position[p.slot_of_id(through)], v = p.velocity[p.slot_of_id(through)];
  CHECK(x[0] == Approx(0.0005 - 0.001).margin(1e-12));
  CHECK(x[1] == Approx(0.0501).margin(1e-12));
  CHECK(v[0] == Approx(0.05).margin(1e-12));
  CHECK(v[1] == Approx(0.1).margin(1e-12));
  CHECK(p.position[p.slot_of_id(over_tip)] == V(0.003, 0.102));
  CHECK(p.position[p.slot_of_id(between)] == V(0.0055, 0.03));
  CHECK(p.position[p.slot_of_id(stays)] == V(-0.0035, 0.072));
  CHECK(p.position[p.slot_of_id(far)] == V(-0.049, 0.05));

  // A particle that lands exactly on the blade line is put back at the 4 mm it was from it; one that started closer
  // than min_offset x the edge length (1 % of 5 mm) at that offset.
  for (std::size_t i = 0; i < p.size(); ++i) p.position_old[i] = p.position[i];
  move(stays, V(0.0005, 0.072), V(0, 0));
  CHECK(guard.restore(p, visibility) == 1);
  CHECK(p.position[p.slot_of_id(stays)][0] == Approx(0.0005 - 0.004).margin(1e-12));
  p.position[p.slot_of_id(stays)] = V(0.0005 - 1e-5, 0.072);
  for (std::size_t i = 0; i < p.size(); ++i) p.position_old[i] = p.position[i];
  move(stays, V(0.0015, 0.072), V(0, 0));
  CHECK(guard.restore(p, visibility) == 1);
  CHECK(p.position[p.slot_of_id(stays)][0] == Approx(0.0005 - 0.01 * 0.005).margin(1e-12));
  CHECK(guard.crossings_prevented() == 3);

  CHECK_THROWS_WITH(guard.set_min_offset(0.7), Catch::Contains("min_offset"));
}

namespace {

struct JetResult {
  std::size_t crossed{0};    // fluid particles right of the blade at the end
  std::size_t prevented{0};  // put back by the guard
  double momentum_x{0};      // final fluid x-momentum, kg m/s per m
};

// A 2 m/s jet of water against a held blade (0.4 mm thick, 5 mm particles) whose repulsion is 100 times weaker than
// the default (k = 1e-4): the push cannot stop the water within the blade's range, and nothing else stands in its way.
JetResult weak_blade_jet(bool visibility, bool guard) {
  System system(Domain<2, double>(V(-0.05, -0.05), V(0.25, 0.3)), Tait<double>(1000, 40));
  const Resolution<double> res{0.005, 1.3};
  add_fluid_block(system, V(0, 0), V(0.06, 0.06), res, 0.0, 0.0);
  add_box_walls(system, V(0, 0), V(0.2, 0.2), res, WallModel::dynamic);
  const double x_blade = 0.0625;
  add_elastic_rod(system, V(x_blade, 0.0), V(0, 1), 0.2, 81, blade_material(), blade_section(), res.h(), 1);
  auto& p = system.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.kind[i] == Kind::fluid) p.velocity[i] = V(2.0, 0);
  Rod::Parameters params;
  params.section = blade_section();
  Rod rod(system, 1, blade_material(), params);
  rod.clamp_where([](const V&) { return true; });
  RepulsiveForce<double> weak;
  weak.strength = 1e-4;
  FluidParameters<2, double> fluid;
  fluid.gravity = V::Zero();
  fluid.thin_structure_visibility = visibility;
  fluid.thin_structure_guard = guard;
  Simulation<System, SymplecticVerlet, Body> sim(system, fluid, {}, Body(weak, std::move(rod)));
  sim.set_warning_handler([](const std::string&) {});
  sim.run(0.02);
  JetResult out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.kind[i] != Kind::fluid) continue;
    if (p.position[i][0] > x_blade) ++out.crossed;
    out.momentum_x += p.mass[i] * p.velocity[i][0];
  }
  out.prevented = sim.fluid().structure_crossings_prevented();
  return out;
}

}  // namespace

TEST_CASE("thin-structure guard: water that a weak blade cannot stop does not go through it", "[visibility][guard]") {
  // With the visibility criterion (the faces do not see each other) and without it (one fluid across the blade).
  for (const bool visibility : {true, false}) {
    const JetResult without = weak_blade_jet(visibility, false);
    const JetResult with = weak_blade_jet(visibility, true);
    INFO("visibility " << visibility << ": without the guard " << without.crossed
                       << " fluid particles across the blade, x-momentum " << without.momentum_x << "; with it "
                       << with.crossed << " across, " << with.prevented << " put back, x-momentum " << with.momentum_x);
    CHECK(without.crossed > 10);  // the weak repulsion alone fails: the failure this guard exists for
    CHECK(without.prevented == 0);
    CHECK(with.crossed == 0);
    CHECK(with.prevented >= without.crossed);     // every would-be crossing was caught (some more than once)
    CHECK(with.momentum_x < without.momentum_x);  // the blade stops the water
  }
}

TEST_CASE("thin-structure guard: a porous (drag) blade publishes no edges", "[visibility][guard]") {
  static_assert(permeable_coupling<BladeDrag<double>> && !permeable_coupling<RepulsiveForce<double>>);
  System system(Domain<2, double>(V(-0.1, -0.1), V(0.2, 0.2)), Tait<double>(1000, 20));
  add_elastic_rod(system, V(0, 0), V(0, 1), 0.1, 11, blade_material(), blade_section(), 0.0065, 1);
  Rod::Parameters params;
  params.section = blade_section();
  const Rod rod(system, 1, blade_material(), params);
  std::vector<StructureEdge> impermeable, permeable;
  Body(RepulsiveForce<double>{}, rod).structure_edges(impermeable);
  CoupledBody<BladeDrag<double>, Rod>(BladeDrag<double>{}, rod).structure_edges(permeable);
  CHECK(impermeable.size() == 10);
  CHECK(permeable.empty());
}

TEST_CASE("thin-structure guard: candidate lists rebuilt after the particle set changed since the evaluation",
          "[visibility][guard]") {
  // A refinement model may add, remove and re-sort particles after the evaluation that built the candidate lists.
  System system(Domain<2, double>(V(-0.1, -0.1), V(0.2, 0.2)), Tait<double>(1000, 20));
  const double h = 0.0065;
  const auto rod = add_elastic_rod(system, V(0, 0), V(0, 1), 0.1, 21, blade_material(), blade_section(), h, 1);
  auto& p = system.particles();
  const std::uint32_t through = p.id[p.add(Kind::fluid, V(-0.001, 0.05), V::Zero(), 1000, 0.025, h)];
  p.add(Kind::fluid, V(-0.004, 0.03), V::Zero(), 1000, 0.025, h);
  WcsphFluid<System> fluid(FluidParameters<2, double>{});
  fluid.set_structure_edges(chain_edges(rod));
  system.update_neighbors();
  system.update_pressure();
  fluid.compute_rates(system);  // builds the candidate lists for this set
  for (int k = 0; k < 30; ++k)  // new particles, then a re-sort: every slot may hold another particle now
    p.add(Kind::fluid, V(0.05 + 0.003 * k, 0.15), V::Zero(), 1000, 0.025, h);
  system.update_neighbors();
  for (std::size_t i = 0; i < p.size(); ++i) p.position_old[i] = p.position[i];
  p.position[p.slot_of_id(through)] = V(0.002, 0.05);
  CHECK(fluid.keep_fluid_beside_structures(system) == 1);
  CHECK(p.position[p.slot_of_id(through)][0] == Approx(-0.001).margin(1e-12));
}

// ---- 3D ribbons: strip elements with lateral bands ----

TEST_CASE("visibility and guard in 3D: a ribbon hides pairs and stops steps through its strip, not beside it",
          "[visibility][guard][ribbon]") {
  using System3 = ParticleSystem<3, double, WendlandC2<3>, Tait<double>>;
  using V3 = Vec<3, double>;
  using Ribbon = ElasticRod<System3>;
  System3 system(Domain<3, double>(V3(-0.1, -0.1, -0.1), V3(0.2, 0.2, 0.2)), Tait<double>(1000, 20));
  const double h = 0.0065;
  // A strip 1 cm wide (y in [-0.005, 0.005]) standing at x = 0, 0.1 m tall, 21 rows of 4 particles.
  add_elastic_ribbon(system, V(0, 0), V(0, 1), 0.1, 21, 4, 0.0, blade_material(), blade_section(), h, 1);
  Ribbon ribbon(system, 1, blade_material(), {.section = blade_section()});
  std::vector<StructureEdge> edges;
  std::vector<std::array<double, 2>> bands;
  ribbon.structure_edges(edges, bands);
  REQUIRE(edges.size() == 20 * 4);
  CHECK(bands.front()[0] == Approx(-0.005));
  CHECK(bands[1][0] == Approx(-0.0025));  // half-way between the rows at y = -0.00375 and -0.00125
  CHECK(bands[3][1] == Approx(0.005));
  auto& p = system.particles();
  const auto fluid = [&](V3 x) { return p.id[p.add(Kind::fluid, x, V3::Zero(), 1000, 1.25e-4, h)]; };
  const std::uint32_t a = fluid(V3(-0.003, 0.002, 0.05)), b = fluid(V3(0.003, -0.001, 0.05));  // across the strip
  const std::uint32_t c = fluid(V3(-0.003, 0.007, 0.05)), d = fluid(V3(0.003, 0.007, 0.05));   // beside it
  const std::uint32_t e = fluid(V3(-0.003, 0.004, 0.05)), f = fluid(V3(0.003, 0.008, 0.05));   // meets y = 0.006
  system.update_neighbors();
  ThinStructureVisibility<double, 3> visibility;
  CHECK_THROWS_WITH(visibility.set_edges(edges), Catch::Contains("lateral bands"));
  visibility.set_edges(edges, bands);
  visibility.update(system);
  const auto hidden = [&](std::uint32_t i, std::uint32_t j) {
    const std::size_t si = p.slot_of_id(i), sj = p.slot_of_id(j);
    return visibility.blocks(si, sj, p.position[si], p.position[sj]);
  };
  CHECK(hidden(a, b));
  CHECK_FALSE(hidden(c, d));
  CHECK_FALSE(hidden(e, f));  // crosses the strip's plane at y = 0.006, past its edge at 0.005
  // The guard: a, c, e step through the plane x = 0; a and e within the strip (y 0.002 and 0.004 when they meet it)
  // are put back, c beside the strip (y = 0.007) is not.
  ThinStructureGuard<double, 3> guard;
  for (std::size_t i = 0; i < p.size(); ++i) p.position_old[i] = p.position[i];
  p.position[p.slot_of_id(a)] = V3(0.001, 0.002, 0.051);
  p.velocity[p.slot_of_id(a)] = V3(0.4, 0.1, 0.1);
  p.position[p.slot_of_id(c)] = V3(0.001, 0.007, 0.05);
  p.position[p.slot_of_id(e)] = V3(0.001, 0.0045, 0.05);
  CHECK(guard.restore(p, visibility) == 2);
  const V3 xa = p.position[p.slot_of_id(a)], va = p.velocity[p.slot_of_id(a)];
  CHECK(xa.x() == Approx(-0.003).margin(1e-12));  // back at its start distance from the strip
  CHECK(xa.y() == 0.002);                         // y and z as moved
  CHECK(xa.z() == 0.051);
  CHECK(va.x() == Approx(0).margin(1e-12));  // the normal velocity towards the strip removed
  CHECK(va.y() == 0.1);
  CHECK(va.z() == 0.1);
  CHECK(p.position[p.slot_of_id(c)] == V3(0.001, 0.007, 0.05));
  CHECK(p.position[p.slot_of_id(e)].x() < 0);
  // Bad input: a band wider than the support radius (the candidate search would miss pairs), an empty band.
  ThinStructureVisibility<double, 3> wide;
  std::vector<std::array<double, 2>> too_wide(edges.size(), {-0.01, 0.01});
  wide.set_edges(edges, too_wide);
  CHECK_THROWS_WITH(wide.update(system), Catch::Contains("lateral band 0.02 m wide"));
  too_wide[3] = {0.002, 0.002};
  CHECK_THROWS_WITH(wide.set_edges(edges, too_wide), Catch::Contains("edge 3 has the lateral band"));
}
