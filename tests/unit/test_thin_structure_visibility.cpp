// Tests of the visibility criterion across thin structures (fluid/thin_structure_visibility.hpp): the segment test,
// the pairs it hides against a brute-force search, and that the fluid on one face of a held blade no longer feels
// the other face through its sums.
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/coupling/coupled_body.hpp>
#include <sphfsi/coupling/repulsive_force.hpp>
#include <sphfsi/eos/tait.hpp>
#include <sphfsi/integrators/simulation.hpp>
#include <sphfsi/integrators/symplectic.hpp>
#include <sphfsi/kernel/wendland_c2.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/solid/elastic_rod.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
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
