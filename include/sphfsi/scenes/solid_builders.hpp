// sphfsi: scene builders for elastic solids: a block of solid particles on a lattice.
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/solid/elastic_material.hpp>

#include <cmath>
#include <cstdint>
#include <limits>

namespace sphfsi {

/// Fills the box [lower, upper] with solid particles of body `body` on a lattice of spacing res.dp
/// (mass rho0 dp^Dim, at rest). Returns the number of particles added.
template <class System>
std::size_t add_solid_block(System& system, const Vec<System::dimension, typename System::scalar_type>& lower,
                            const Vec<System::dimension, typename System::scalar_type>& upper,
                            const Resolution<typename System::scalar_type>& res,
                            const ElasticMaterial<typename System::scalar_type>& material, std::int32_t body = 0) {
  using T = typename System::scalar_type;
  constexpr int Dim = System::dimension;
  res.validate();
  material.validate();
  require_in_range("add_solid_block body index", body, std::int32_t(0), std::numeric_limits<std::int32_t>::max());
  const T mass = material.density * std::pow(res.dp, T(Dim));
  std::size_t added = 0;
  for_each_lattice_point<Dim, T>(lower, upper, res.dp, [&](const Vec<Dim, T>& x) {
    system.particles().add(Kind::solid, x, Vec<Dim, T>::Zero(), material.density, mass, res.h(), body);
    ++added;
  });
  return added;
}

}  // namespace sphfsi
