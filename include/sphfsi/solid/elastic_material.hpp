// sphfsi: isotropic linear-elastic material constants of a solid body.
//
// From Young's modulus E and Poisson's ratio nu (Landau & Lifshitz, Theory of Elasticity, sec. 4-5):
//   shear modulus      G      = E / (2 (1 + nu))
//   bulk modulus       K      = E / (3 (1 - 2 nu))
//   Lame constant      lambda = E nu / ((1 + nu)(1 - 2 nu))
//   bulk sound speed   c0     = sqrt(K / rho)          (Gray, Monaghan & Swift 2001, CMAME 190:6641, eq. 2.10)
//   P-wave speed       c_p    = sqrt((K + 4 G / 3) / rho)  (fastest signal: the solid's CFL condition)
//   plane-strain modulus E'   = E / (1 - nu^2)         (2D bending stiffness of a plate in plane strain)
// Two-dimensional solids are in plane strain: the 3D constants above are used unchanged. A 2D body in plane stress
// (a plate narrow across the third direction, free to contract in it) has the in-plane law
// sigma = lambda' tr(eps) I + 2 G eps with lambda' = 2 lambda G / (lambda + 2 G) = E nu / (1 - nu^2); the plane-strain
// solids reproduce it exactly with the material plane_stress_equivalent(): nu* = nu / (1 + nu),
// E* = E (1 + 2 nu) / (1 + nu)^2 (same G, lambda* = lambda'; e.g. Timoshenko & Goodier, Theory of Elasticity, sec. 16).
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/types.hpp>

#include <cmath>

namespace sphfsi {

/// Isotropic elastic material. A small trivially copyable aggregate: fill it with designated initialisers
/// and call validate() (the solid models do) before use.
template <Real T>
struct ElasticMaterial {
  T density{T(1000)};        ///< rho0, reference density, kg/m^3
  T youngs_modulus{T(2e6)};  ///< E, Pa
  T poisson_ratio{T(0.3)};   ///< nu, dimensionless, (-1, 0.5)

  /// Throws InputError naming the first invalid constant.
  void validate() const {
    require_positive("ElasticMaterial::density (rho0, kg/m^3)", density);
    require_positive("ElasticMaterial::youngs_modulus (E, Pa)", youngs_modulus);
    require_in_open_range("ElasticMaterial::poisson_ratio (nu)", poisson_ratio, T(-1), T(0.5));
  }

  T shear_modulus() const { return youngs_modulus / (T(2) * (T(1) + poisson_ratio)); }        ///< G, Pa
  T bulk_modulus() const { return youngs_modulus / (T(3) * (T(1) - T(2) * poisson_ratio)); }  ///< K, Pa
  T lame_lambda() const {                                                                     ///< Pa
    return youngs_modulus * poisson_ratio / ((T(1) + poisson_ratio) * (T(1) - T(2) * poisson_ratio));
  }
  T sound_speed() const { return std::sqrt(bulk_modulus() / density); }  ///< c0, m/s
  T p_wave_speed() const {                                               ///< c_p, m/s
    return std::sqrt((bulk_modulus() + T(4) / T(3) * shear_modulus()) / density);
  }
  T plane_strain_modulus() const {  ///< E', Pa
    return youngs_modulus / (T(1) - poisson_ratio * poisson_ratio);
  }
  /// The material whose plane-strain (2D) constants are this material's plane-stress ones (see the header comment).
  ElasticMaterial plane_stress_equivalent() const {
    const T nu = poisson_ratio;
    return {density, youngs_modulus * (T(1) + T(2) * nu) / ((T(1) + nu) * (T(1) + nu)), nu / (T(1) + nu)};
  }
};

}  // namespace sphfsi
