// Writes known particle sets with sphfsi::io::VtkSeriesWriter for tests/python/check_vtk.py, which reads them back
// with VTK's own XML reader. Every value is a function of the particle id and the snapshot time; check_vtk.py
// evaluates the same formulas (keep the two in step).
//
//   sphfsi_vtk_write_sample <output folder>      writes the four series listed in `cases` below
//   sphfsi_vtk_write_sample --skip <reason>      prints the reason and exits with 77 (CTest SKIP_RETURN_CODE)
#include <sphfsi/io/vtk_writer.hpp>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

namespace {

constexpr std::size_t particle_count(int dim) { return dim == 2 ? 50 : 40; }
constexpr double snapshot_times[] = {0.0, 0.5};

template <int Dim, class T>
void write_series(const std::filesystem::path& dir, const std::string& name, sphfsi::io::VtkEncoding encoding) {
  using V = sphfsi::Vec<Dim, T>;
  const std::size_t n = particle_count(Dim);
  sphfsi::io::VtkSeriesWriter writer(dir, name, encoding);
  for (std::size_t snap = 0; snap < std::size(snapshot_times); ++snap) {
    const T t = static_cast<T>(snapshot_times[snap]);
    sphfsi::ParticleSet<Dim, T> p;
    for (std::size_t k = 0; k < n; ++k) {
      const T i = static_cast<T>(k);
      V v, x, a;
      for (int d = 0; d < Dim; ++d) {
        v[d] = T(0.1) * T(d + 1) - T(0.003) * i;
        x[d] = T(0.01) * i + T(0.5) * T(d) + v[d] * t;
        a[d] = d == Dim - 1 ? T(-9.81) : T(0.5) * i;
      }
      const auto kind = static_cast<sphfsi::Kind>(k % 3);
      const T mass = T(0.001) * T(1 + k % 4);
      p.add(kind, x, v, T(1000) + T(0.25) * i, mass, T(0.013), static_cast<std::int32_t>(k % 4) - 1);
      p.pressure[k] = T(3.5) * i - T(20);
      p.sound_speed[k] = T(20) + T(0.01) * i;
      p.acceleration[k] = a;
      p.density_rate[k] = T(0.125) * i;
      p.normal[k] = k % 2 ? V(V::Unit(0)) : V(V::Zero());
      p.xsph_velocity[k] = V::Constant(T(-0.001) * i);
    }
    // The second snapshot stores the particles in reverse order: the reader must match them by id.
    if (snap == 1) {
      std::vector<std::uint32_t> order(n);
      for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<std::uint32_t>(n - 1 - k);
      p.permute(order);
    }
    std::vector<T> temperature(n);
    std::vector<V> force(n);
    for (std::size_t s = 0; s < n; ++s) {
      temperature[s] = T(300) + T(p.id[s]);
      force[s] = V::Zero();
      force[s][0] = T(p.id[s]);
      force[s][1] = -T(p.id[s]);
    }
    const auto file = writer.write(p, snapshot_times[snap], {{"temperature", temperature}, {"force", force}});
    std::printf("wrote %s\n", file.string().c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--skip") {
    std::printf("SKIPPED: %s\n", argv[2]);
    return 77;
  }
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <output folder> | --skip <reason>\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::remove_all(dir);
    using sphfsi::io::VtkEncoding;
    // name: <dim>d_<scalar>_<encoding>, parsed by check_vtk.py.
    write_series<2, double>(dir, "2d_double_raw", VtkEncoding::appended_raw);
    write_series<3, float>(dir, "3d_float_raw", VtkEncoding::appended_raw);
    write_series<2, float>(dir, "2d_float_base64", VtkEncoding::inline_base64);
    write_series<3, double>(dir, "3d_double_base64", VtkEncoding::inline_base64);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
