// sphfsi: surface particles and outward normals of a solid body, from the kernel-weighted colour gradient
//   c_a = sum_{b in body} V_b grad_a W_ab,   n_a = -c_a / |c_a|,   surface if |c_a| h_a > threshold
// (Randles & Libersky 1996, CMAME 139:375, the "normal from the colour gradient"). In 2D this reproduces the
// reference paper's tangent/normal construction (eqs 5-6) on a straight surface and extends it to corners,
// free ends and 3D. The normals are written into p.normal of the body's particles (zero for interior ones).
#pragma once

#include <sphfsi/core/types.hpp>
#include <sphfsi/kernel/concepts.hpp>

#include <cstdint>
#include <vector>

namespace sphfsi {

/// |c| h below which a particle counts as interior. On a flat lattice surface |c| h is about 0.5-0.7 for the
/// kernels of sphfsi, one row inside it is below 0.15, and deep inside it is zero.
template <class T>
inline constexpr T surface_threshold = T(0.25);

/// Computes surface flags (body order) and writes outward unit normals of `ids` into p.normal.
template <class System>
void update_solid_surface(System& system, const std::vector<std::uint32_t>& ids, std::int32_t body,
                          std::vector<char>& is_surface) {
  using T = typename System::scalar_type;
  using Vector = Vec<System::dimension, T>;
  auto& p = system.particles();
  const auto& kernel = system.kernel();
  is_surface.assign(ids.size(), 0);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const std::size_t a = p.slot_of_id(ids[k]);
    Vector c = Vector::Zero();
    system.for_each_neighbor(a, [&](std::size_t b, const Vector& dx, T r, T h) {
      if (p.kind[b] != Kind::solid || p.body[b] != body) return;
      c += (p.mass[b] / p.density[b]) * kernel_gradient(kernel, dx, r, h);
    });
    const T magnitude = c.norm();
    if (magnitude * p.smoothing_length[a] > surface_threshold<T>) {
      is_surface[k] = 1;
      p.normal[a] = -c / magnitude;
    } else {
      p.normal[a] = Vector::Zero();
    }
  }
}

}  // namespace sphfsi
