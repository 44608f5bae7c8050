// sphfsi: the 2D numerical wave flume: a piston or flap paddle at x = 0, a flat bed (z = 0) of still-water depth h,
// wave gauges, and an absorber at the far end (a damping zone, waves/damping_zone.hpp, and/or a sloping beach of
// wall particles). Used by examples/wave_flume and, with plants, by the vegetation examples: the builder leaves
// fluid out of the boxes listed in `fluid_exclusions` so solid bodies can be placed there afterwards, with body
// indices from WaveFlumeLayout::first_free_body on.
//
// Bodies: 0 the fixed walls (bed, end wall), 1 the paddle, 2 the beach. Dynamic walls (Crespo et al. 2007) with
// hydrostatic initial density (scenes/builders.hpp).
#pragma once

#include <sphfsi/core/domain.hpp>
#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_system.hpp>
#include <sphfsi/fluid/wcsph.hpp>
#include <sphfsi/scenes/builders.hpp>
#include <sphfsi/waves/damping_zone.hpp>
#include <sphfsi/waves/linear_theory.hpp>
#include <sphfsi/waves/wavemaker.hpp>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace sphfsi::scenes {

enum class FlumeAbsorber { damping_zone, beach, both };

template <Real T>
struct WaveFlumeGeometry {
  waves::WavemakerParameters<T> wave{};  ///< paddle type, target H, T, h (h is the flume's still-water depth)
  T particles_per_depth{T(16)};          ///< h / dp
  T smoothing_ratio{T(2)};               ///< h_sph / dp (1.3 loses waves: docs/flume.md, suspect 8)
  T sound_speed_factor{T(7)};            ///< c0 / sqrt(g h) (hydrostatic compression g h / c0^2 = 2 %)
  T wall_height_ratio{T(1.5)};           ///< height of paddle and end wall over h
  T length_wavelengths{T(7)};            ///< paddle (rest position) to end wall, in wavelengths L
  FlumeAbsorber absorber{FlumeAbsorber::damping_zone};
  T damping_wavelengths{T(1.5)};  ///< damping zone length (ending at the end wall or the beach toe), in L
  T damping_rate{T(10)};          ///< beta of the damping zone, 1/s
  T beach_slope{T(0.1)};          ///< rise over run of the beach
  int wall_layers{3};             ///< rows of dynamic wall particles
  std::vector<std::pair<Vec<2, T>, Vec<2, T>>> fluid_exclusions{};  ///< boxes (lower, upper) left without fluid, m

  void validate() const {
    wave.validate();
    require_in_range("WaveFlumeGeometry::particles_per_depth (h/dp)", particles_per_depth, T(4), T(2000));
    require_in_range("WaveFlumeGeometry::smoothing_ratio (h/dp)", smoothing_ratio, T(1), T(3));
    require_in_range("WaveFlumeGeometry::sound_speed_factor (c0/sqrt(gh))", sound_speed_factor, T(3), T(1000));
    require_in_range("WaveFlumeGeometry::wall_height_ratio", wall_height_ratio, T(1.05), T(20));
    require_in_range("WaveFlumeGeometry::length_wavelengths", length_wavelengths, T(0.5), T(1000));
    require_in_range("WaveFlumeGeometry::damping_wavelengths", damping_wavelengths, T(0.05), length_wavelengths);
    require_in_range("WaveFlumeGeometry::damping_rate (1/s)", damping_rate, T(0), T(1e4));
    require_in_range("WaveFlumeGeometry::beach_slope (rise/run)", beach_slope, T(0.01), T(1));
    require_in_range("WaveFlumeGeometry::wall_layers", wall_layers, 1, 8);
  }
  T depth() const { return wave.depth; }
  T dp() const { return wave.depth / particles_per_depth; }
  T wall_height() const { return wall_height_ratio * wave.depth; }
  T sound_speed() const { return sound_speed_factor * std::sqrt(wave.gravity * wave.depth); }
  waves::LinearWave<T> linear() const { return waves::linear_wave(wave.period, wave.depth, wave.gravity); }
  T wavelength() const { return linear().wavelength; }
  T length() const { return length_wavelengths * wavelength(); }
  bool has_beach() const { return absorber != FlumeAbsorber::damping_zone; }
  bool has_damping_zone() const { return absorber != FlumeAbsorber::beach; }
  /// x of the beach toe (the beach rises from there to the wall height at the end wall).
  T beach_toe() const { return length() - wall_height() / beach_slope; }
  /// The damping zone: damping_wavelengths long, ending where the still water ends (end wall or shoreline).
  waves::DampingZone<T> damping_zone() const {
    const T end = has_beach() ? beach_toe() + depth() / beach_slope : length();
    waves::DampingZone<T> z{end - damping_wavelengths * wavelength(), end, damping_rate};
    z.validate();
    return z;
  }
};

/// What build_wave_flume made and where.
template <Real T>
struct WaveFlumeLayout {
  static constexpr std::int32_t wall_body = 0, paddle_body = 1, beach_body = 2, first_free_body = 3;
  std::size_t fluid_particles{0}, wall_particles{0}, paddle_particles{0}, beach_particles{0};
  T paddle_x{0};     ///< rest position of the paddle face, m
  T end_x{0};        ///< end wall face, m
  T still_level{0};  ///< z of the still-water surface, m
};

/// Domain of the flume with a margin of 5 particle spacings (room behind the paddle for its stroke).
template <Real T>
Domain<2, T> wave_flume_domain(const WaveFlumeGeometry<T>& g) {
  const T m = T(5) * g.dp(), layers = T(g.wall_layers) * g.dp();
  const T back = T(2) * g.wave.depth + layers;  // behind the paddle: its stroke (< h) and rows
  return Domain<2, T>(Vec<2, T>(-back - m, -layers - m), Vec<2, T>(g.length() + layers + m, T(2) * g.wall_height()));
}

/// Fills `system` (empty, built on wave_flume_domain) with the fluid at hydrostatic rest, bed, end wall, paddle and
/// beach. The paddle's motion is registered separately (Simulation::set_wall_motion / set_wall_kinematics).
template <class System>
WaveFlumeLayout<typename System::scalar_type> build_wave_flume(
    System& system, const WaveFlumeGeometry<typename System::scalar_type>& g) {
  using T = typename System::scalar_type;
  using V = Vec<2, T>;
  static_assert(System::dimension == 2, "the wave flume scene is 2D");
  g.validate();
  const waves::Wavemaker<T> maker(g.wave);  // rejects a stroke larger than the depth
  const T dp = g.dp(), h = g.depth(), L = g.length(), top = g.wall_height();
  const T layers = T(g.wall_layers) * dp;
  const Resolution<T> res{dp, g.smoothing_ratio};
  auto& p = system.particles();
  const auto& eos = system.eos();
  const T rho0 = eos.reference_density(), mass = rho0 * dp * dp;
  WaveFlumeLayout<T> out;
  out.end_x = L;
  out.still_level = h;

  const T slope = g.beach_slope, toe = g.beach_toe(), cos_beach = T(1) / std::sqrt(T(1) + slope * slope);
  auto above_beach = [&](const V& x, T clearance) {  // distance above the beach surface >= clearance
    return !g.has_beach() || (x[1] - slope * (x[0] - toe)) * cos_beach >= clearance;
  };
  auto excluded = [&](const V& x) {
    for (const auto& [lo, hi] : g.fluid_exclusions)
      if (x[0] > lo[0] && x[0] < hi[0] && x[1] > lo[1] && x[1] < hi[1]) return true;
    return false;
  };
  // fluid: x in (0, L), z in (0, h), above the beach by dp/2, outside the exclusions
  for_each_lattice_point<2, T>(V(0, 0), V(L, h), dp, [&](const V& x) {
    if (!above_beach(x, T(0.5) * dp) || excluded(x)) return;
    p.add(Kind::fluid, x, V::Zero(), eos.density(rho0 * g.wave.gravity * (h - x[1])), mass, res.h());
    ++out.fluid_particles;
  });
  // bed (extending behind the paddle so that it slides over it) and end wall
  const T bed_start = -(maker.stroke() + layers + T(2) * dp);
  for_each_lattice_point<2, T>(V(bed_start, -layers), V(L + layers, T(0)), dp, [&](const V& x) {
    p.add(Kind::wall, x, V::Zero(), rho0, mass, res.h(), out.wall_body);
    ++out.wall_particles;
  });
  for_each_lattice_point<2, T>(V(L, T(0)), V(L + layers, top), dp, [&](const V& x) {
    p.add(Kind::wall, x, V::Zero(), rho0, mass, res.h(), out.wall_body);
    ++out.wall_particles;
  });
  // paddle: rows behind its face x = 0, from the bed to the wall height
  for_each_lattice_point<2, T>(V(-layers, T(0)), V(T(0), top), dp, [&](const V& x) {
    p.add(Kind::wall, x, V::Zero(), rho0, mass, res.h(), out.paddle_body);
    ++out.paddle_particles;
  });
  // beach: rows parallel to the slope, below its surface, from the toe to the end wall
  if (g.has_beach()) {
    const V tangent = V(T(1), slope) * cos_beach, inward = V(slope, T(-1)) * cos_beach;
    const T run = (L - toe) / cos_beach;
    const auto n = std::int64_t(std::floor(run / dp));
    for (std::int64_t i = 0; i <= n; ++i) {
      for (int k = 0; k < g.wall_layers; ++k) {
        const V x = V(toe, T(0)) + (T(i) + T(0.5)) * dp * tangent + (T(k) + T(0.5)) * dp * inward;
        if (x[1] < T(0.5) * dp || x[0] > L) continue;  // the bed and end wall are there
        p.add(Kind::wall, x, V::Zero(), rho0, mass, res.h(), out.beach_body);
        ++out.beach_particles;
      }
    }
  }
  set_hydrostatic_wall_density(system, h, g.wave.gravity);
  return out;
}

/// The bed from x_from to x_to built again at a finer `spacing`, beside the coarse bed of build_wave_flume and as
/// thick (wall_layers dp), for a refined region that reaches the bed (fluid/adaptive_refinement.hpp: each resolution
/// sees only its own walls); wall densities set hydrostatic again, as build_wave_flume does. Returns the particle
/// count.
template <class System>
std::size_t add_fine_bed(System& system, const WaveFlumeGeometry<typename System::scalar_type>& g,
                         typename System::scalar_type x_from, typename System::scalar_type x_to,
                         typename System::scalar_type spacing) {
  using T = typename System::scalar_type;
  using V = Vec<2, T>;
  require_in_open_range("add_fine_bed spacing (m)", spacing, T(0), g.dp());
  if (!(x_to > x_from))
    throw InputError(fmt::format("add_fine_bed: x_to = {} m must be greater than x_from = {} m", x_to, x_from));
  const T rho0 = system.eos().reference_density(), mass = rho0 * spacing * spacing;
  std::size_t added = 0;
  for_each_lattice_point<2, T>(V(x_from, -T(g.wall_layers) * g.dp()), V(x_to, T(0)), spacing, [&](const V& x) {
    system.particles().add(Kind::wall, x, V::Zero(), rho0, mass, g.smoothing_ratio * spacing,
                           WaveFlumeLayout<T>::wall_body);
    ++added;
  });
  set_hydrostatic_wall_density(system, g.depth(), g.wave.gravity);
  return added;
}

/// Fluid parameters of the flume: gravity, the artificial viscosity and delta-SPH given (defaults: alpha = 0.01,
/// delta = 0.1, FluidParameters' defaults), dynamic walls.
template <Real T>
FluidParameters<2, T> wave_flume_fluid(const WaveFlumeGeometry<T>& g) {
  FluidParameters<2, T> f;
  f.gravity = Vec<2, T>(0, -g.wave.gravity);
  f.walls = WallModel::dynamic;
  return f;
}

/// Default gauge positions: one, two, ... n spacings from the paddle (spacing in wavelengths, default one).
template <Real T>
std::vector<T> wave_flume_gauges(const WaveFlumeGeometry<T>& g, int count, T spacing = T(1)) {
  require_in_range("wave_flume_gauges count", count, 1, 1000);
  require_in_range("wave_flume_gauges spacing (wavelengths)", spacing, T(0.01), g.length_wavelengths);
  std::vector<T> x;
  for (int i = 1; i <= count; ++i) x.push_back(T(i) * spacing * g.wavelength());
  return x;
}

}  // namespace sphfsi::scenes
