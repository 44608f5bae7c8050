// sphfsi: VTK XML output of particle snapshots for ParaView.
//
//   sphfsi::io::VtkSeriesWriter writer(directory, "dam_break");
//   writer.write(system.particles(), time);   // -> directory/dam_break_000000.vtu, rewrites dam_break.pvd
//
// Each snapshot is one VTK XML UnstructuredGrid file (.vtu, format version 1.0, UInt64 byte-count headers) holding
// every particle field as point data and one VTK_VERTEX cell per particle, so ParaView draws the particles as points
// without a "Glyph" or "Table To Points" filter. Floating-point fields are written in the scene's precision
// (Float32 for float scenes, Float64 for double); 2D vectors get a zero z component. Two binary encodings:
//   - appended_raw: one raw binary block after the XML (smallest, fastest; the default);
//   - inline_base64: base64 inside each DataArray (about 4/3 larger, but the file is valid text/XML).
// The series file (.pvd) lists every snapshot with its time and is rewritten atomically after each snapshot (written
// to a temporary file, then renamed), as is each .vtu, so a run that dies mid-write leaves a valid series behind.
// Fields are written in slot order (the order of the arrays at the time of the call); the stable `id` field lets
// a reader follow particles across snapshots although the library re-sorts them every step.
//
// Format reference: "VTK File Formats", VTK User's Guide (Kitware, 11th ed.), section "XML File Formats".
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_set.hpp>
#include <sphfsi/core/types.hpp>

#include <fmt/format.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace sphfsi::io {

/// How binary data is stored in a .vtu file.
enum class VtkEncoding {
  appended_raw,   ///< raw bytes in one <AppendedData> block after the XML (default: smallest and fastest)
  inline_base64,  ///< base64 text inside each <DataArray> (larger, but the whole file is plain text)
};

/// An extra per-particle field written next to the built-in ones: a scalar or a Dim-vector per slot.
/// The span is read during the write() call only and must have one entry per particle, in slot order.
template <int Dim, Real T>
  requires SpatialDimension<Dim>
class PointField {
 public:
  PointField(std::string_view name, std::span<const T> scalars) : name_(name), values_(scalars) {}
  PointField(std::string_view name, std::span<const Vec<Dim, T>> vectors) : name_(name), values_(vectors) {}
  PointField(std::string_view name, const std::vector<T>& scalars) : PointField(name, std::span<const T>(scalars)) {}
  PointField(std::string_view name, const std::vector<Vec<Dim, T>>& vectors)
      : PointField(name, std::span<const Vec<Dim, T>>(vectors)) {}

  const std::string& name() const noexcept { return name_; }
  bool is_vector() const noexcept { return values_.index() == 1; }
  std::size_t size() const noexcept {
    return std::visit([](const auto& s) { return s.size(); }, values_);
  }
  std::span<const T> scalars() const { return std::get<0>(values_); }
  std::span<const Vec<Dim, T>> vectors() const { return std::get<1>(values_); }

 private:
  std::string name_;
  std::variant<std::span<const T>, std::span<const Vec<Dim, T>>> values_;
};

namespace detail {

inline constexpr std::uint8_t vtk_vertex = 1;  // VTK cell type id of a single point

template <class E>
constexpr std::string_view vtk_type_name() {
  if constexpr (std::is_same_v<E, float>) return "Float32";
  else if constexpr (std::is_same_v<E, double>) return "Float64";
  else if constexpr (std::is_same_v<E, std::uint8_t>) return "UInt8";
  else if constexpr (std::is_same_v<E, std::int32_t>) return "Int32";
  else if constexpr (std::is_same_v<E, std::uint32_t>) return "UInt32";
  else if constexpr (std::is_same_v<E, std::int64_t>) return "Int64";
  else static_assert(sizeof(E) == 0, "no VTK type for this element type");
}

/// Standard base64 (RFC 4648) with '=' padding, appended to `out`.
inline void base64_append(std::string& out, const unsigned char* data, std::size_t n) {
  static constexpr char table[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const std::size_t start = out.size();
  out.resize(start + 4 * ((n + 2) / 3));
  char* o = out.data() + start;
  std::size_t i = 0;
  for (; i + 3 <= n; i += 3, o += 4) {
    const std::uint32_t v = (std::uint32_t(data[i]) << 16) | (std::uint32_t(data[i + 1]) << 8) | data[i + 2];
    o[0] = table[(v >> 18) & 63];
    o[1] = table[(v >> 12) & 63];
    o[2] = table[(v >> 6) & 63];
    o[3] = table[v & 63];
  }
  if (const std::size_t rest = n - i; rest > 0) {
    std::uint32_t v = std::uint32_t(data[i]) << 16;
    if (rest == 2) v |= std::uint32_t(data[i + 1]) << 8;
    o[0] = table[(v >> 18) & 63];
    o[1] = table[(v >> 12) & 63];
    o[2] = rest == 2 ? table[(v >> 6) & 63] : '=';
    o[3] = '=';
  }
}

/// Escapes the five XML special characters for use in an attribute value.
inline std::string xml_escape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

/// One DataArray: its XML attributes and a function that fills its bytes (tuples * components * element size).
struct DataArraySpec {
  std::string name;
  std::string_view type;
  int components;
  std::size_t bytes;
  std::function<void(unsigned char*)> fill;
};

/// Array of `count` tuples of `components` elements of type E, element (i, c) = value(i, c).
template <class E, class F>
DataArraySpec make_array(std::string name, int components, std::size_t count, F value) {
  const std::size_t bytes = count * static_cast<std::size_t>(components) * sizeof(E);
  return DataArraySpec{std::move(name), vtk_type_name<E>(), components, bytes,
                       [count, components, value](unsigned char* dst) {
                         for (std::size_t i = 0; i < count; ++i)
                           for (int c = 0; c < components; ++c) {
                             const E v = static_cast<E>(value(i, c));
                             std::memcpy(dst, &v, sizeof(E));
                             dst += sizeof(E);
                           }
                       }};
}

/// Array of 3-component vectors from Dim-vectors (z = 0 in 2D).
template <int Dim, Real T>
DataArraySpec vector_array(std::string name, std::span<const Vec<Dim, T>> v) {
  return make_array<T>(std::move(name), 3, v.size(), [v](std::size_t i, int c) { return c < Dim ? v[i][c] : T(0); });
}

template <class E>
DataArraySpec scalar_array(std::string name, std::span<const E> v) {
  const std::size_t bytes = v.size() * sizeof(E);
  return DataArraySpec{std::move(name), vtk_type_name<E>(), 1, bytes, [v, bytes](unsigned char* dst) {
                         if (bytes) std::memcpy(dst, v.data(), bytes);
                       }};
}

[[noreturn]] inline void throw_io(std::string_view what, const std::filesystem::path& path) {
  throw std::runtime_error(fmt::format("{} '{}': {}", what, path.string(), std::strerror(errno)));
}

/// Renames tmp to target (atomic on POSIX within one directory), throwing with both paths on failure.
inline void commit_file(const std::filesystem::path& tmp, const std::filesystem::path& target) {
  std::error_code ec;
  std::filesystem::rename(tmp, target, ec);
  if (ec)
    throw std::runtime_error(
        fmt::format("cannot rename '{}' to '{}': {}", tmp.string(), target.string(), ec.message()));
}

inline constexpr const char* byte_order() {
  return std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
}

/// Writes one .vtu file (through `path`.tmp and a rename). `scratch` is a reusable staging buffer.
inline void write_vtu_file(const std::filesystem::path& path, std::size_t n, double time,
                           const std::vector<DataArraySpec>& point_data, const DataArraySpec& points,
                           VtkEncoding encoding, std::vector<unsigned char>& scratch) {
  using Header = std::uint64_t;  // header_type="UInt64": byte count before each array's data
  const auto cells = std::vector<DataArraySpec>{
      make_array<std::int64_t>("connectivity", 1, n, [](std::size_t i, int) { return std::int64_t(i); }),
      make_array<std::int64_t>("offsets", 1, n, [](std::size_t i, int) { return std::int64_t(i + 1); }),
      make_array<std::uint8_t>("types", 1, n, [](std::size_t, int) { return vtk_vertex; })};

  const std::filesystem::path tmp = std::filesystem::path(path) += ".tmp";
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  if (!out) throw_io("cannot open VTK file for writing", tmp);
  auto put = [&out](std::string_view s) { out.write(s.data(), static_cast<std::streamsize>(s.size())); };

  // Fills scratch with [byte count][data] of one array.
  auto stage = [&](const DataArraySpec& a) {
    scratch.resize(sizeof(Header) + a.bytes);
    const Header h = a.bytes;
    std::memcpy(scratch.data(), &h, sizeof(Header));
    a.fill(scratch.data() + sizeof(Header));
  };

  const bool raw = encoding == VtkEncoding::appended_raw;
  std::size_t appended_offset = 0;
  std::string text;
  auto put_array = [&](const DataArraySpec& a) {
    text = fmt::format("        <DataArray type=\"{}\" Name=\"{}\"", a.type, xml_escape(a.name));
    if (a.components != 1) text += fmt::format(" NumberOfComponents=\"{}\"", a.components);
    if (raw) {
      text += fmt::format(" format=\"appended\" offset=\"{}\"/>\n", appended_offset);
      appended_offset += sizeof(Header) + a.bytes;
      put(text);
    } else {
      // Header and data are encoded as one base64 stream, which is what VTK's reader expects uncompressed.
      text += " format=\"binary\">";
      stage(a);
      base64_append(text, scratch.data(), scratch.size());
      text += "</DataArray>\n";
      put(text);
    }
  };

  put(fmt::format(
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{}\" header_type=\"UInt64\">\n"
      "  <UnstructuredGrid>\n"
      "    <FieldData>\n"
      "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>\n"
      "    </FieldData>\n"
      "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n"
      "      <PointData Scalars=\"density\" Vectors=\"velocity\">\n",
      byte_order(), time, n, n));
  for (const auto& a : point_data) put_array(a);
  put("      </PointData>\n      <Points>\n");
  put_array(points);
  put("      </Points>\n      <Cells>\n");
  for (const auto& a : cells) put_array(a);
  put("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
  if (raw) {
    put("  <AppendedData encoding=\"raw\">\n   _");
    auto put_data = [&](const DataArraySpec& a) {
      stage(a);
      out.write(reinterpret_cast<const char*>(scratch.data()), static_cast<std::streamsize>(scratch.size()));
    };
    for (const auto& a : point_data) put_data(a);
    put_data(points);
    for (const auto& a : cells) put_data(a);
    put("\n  </AppendedData>\n");
  }
  put("</VTKFile>\n");
  out.close();
  if (!out) throw_io("error while writing VTK file", tmp);
  commit_file(tmp, path);
}

/// Built-in field names: extra fields may not reuse them.
inline constexpr std::string_view builtin_fields[] = {
    "velocity",    "acceleration", "normal",        "density", "pressure", "mass", "smoothing_length",
    "sound_speed", "density_rate", "xsph_velocity", "kind",    "body",     "id",   "position"};

template <int Dim, Real T>
std::vector<DataArraySpec> point_data_arrays(const ParticleSet<Dim, T>& p, std::span<const PointField<Dim, T>> extra) {
  const std::size_t n = p.size();
  using V = Vec<Dim, T>;
  std::vector<DataArraySpec> a;
  a.reserve(14 + extra.size());
  a.push_back(vector_array<Dim, T>("velocity", std::span<const V>(p.velocity)));
  a.push_back(vector_array<Dim, T>("acceleration", std::span<const V>(p.acceleration)));
  a.push_back(vector_array<Dim, T>("normal", std::span<const V>(p.normal)));
  a.push_back(vector_array<Dim, T>("xsph_velocity", std::span<const V>(p.xsph_velocity)));
  a.push_back(scalar_array<T>("density", p.density));
  a.push_back(scalar_array<T>("pressure", p.pressure));
  a.push_back(scalar_array<T>("mass", p.mass));
  a.push_back(scalar_array<T>("smoothing_length", p.smoothing_length));
  a.push_back(scalar_array<T>("sound_speed", p.sound_speed));
  a.push_back(scalar_array<T>("density_rate", p.density_rate));
  a.push_back(make_array<std::uint8_t>(
      "kind", 1, n, [k = p.kind.data()](std::size_t i, int) { return static_cast<std::uint8_t>(k[i]); }));
  a.push_back(scalar_array<std::int32_t>("body", p.body));
  a.push_back(scalar_array<std::uint32_t>("id", p.id));

  for (std::size_t f = 0; f < extra.size(); ++f) {
    const auto& e = extra[f];
    if (e.name().empty()) throw InputError(fmt::format("VTK extra field #{} has an empty name", f));
    for (auto b : builtin_fields)
      if (e.name() == b)
        throw InputError(fmt::format("VTK extra field name '{}' clashes with a built-in particle field", e.name()));
    for (std::size_t g = 0; g < f; ++g)
      if (extra[g].name() == e.name())
        throw InputError(fmt::format("VTK extra field name '{}' is given twice", e.name()));
    if (e.size() != n)
      throw InputError(fmt::format("VTK extra field '{}' has {} values but the particle set has {} particles", e.name(),
                                   e.size(), n));
    if (e.is_vector()) a.push_back(vector_array<Dim, T>(e.name(), e.vectors()));
    else a.push_back(scalar_array<T>(e.name(), e.scalars()));
  }
  return a;
}

}  // namespace detail

/// Writes one snapshot of a particle set to a .vtu file (all fields, plus `extra`) with the time as field data.
/// The file appears atomically (written to `path`.tmp, then renamed). Throws InputError on bad extra fields and
/// std::runtime_error when the file cannot be written.
template <int Dim, Real T>
void write_vtu(const std::filesystem::path& path, const ParticleSet<Dim, T>& particles, double time = 0.0,
               VtkEncoding encoding = VtkEncoding::appended_raw,
               std::type_identity_t<std::span<const PointField<Dim, T>>> extra = {},
               std::vector<unsigned char>* scratch = nullptr) {
  require_finite("VTK snapshot time (s)", time);
  const auto point_data = detail::point_data_arrays(particles, extra);
  const auto points = detail::vector_array<Dim, T>("position", std::span<const Vec<Dim, T>>(particles.position));
  std::vector<unsigned char> local;
  detail::write_vtu_file(path, particles.size(), time, point_data, points, encoding, scratch ? *scratch : local);
}

/// A time series of .vtu snapshots plus the .pvd collection that ParaView opens as one animated data set.
///
/// Snapshots are named `<name>_<index, 6 digits>.vtu` in `directory`; the collection is `<name>.pvd`. A new writer
/// starts a new series: it overwrites `<name>.pvd` with its first snapshot (older .vtu files are left in place).
/// Not thread-safe: call write() from one thread.
class VtkSeriesWriter {
 public:
  /// Creates `directory` if needed. Throws InputError if the name is empty or contains a path separator, or if the
  /// directory cannot be created or is not a directory.
  VtkSeriesWriter(std::filesystem::path directory, std::string name, VtkEncoding encoding = VtkEncoding::appended_raw)
      : directory_(std::move(directory)), name_(std::move(name)), encoding_(encoding) {
    if (name_.empty()) throw InputError("VtkSeriesWriter: the series name is empty");
    if (name_.find_first_of("/\\") != std::string::npos || name_ == "." || name_ == "..")
      throw InputError(
          fmt::format("VtkSeriesWriter: the series name '{}' must be a plain file name "
                      "(no '/' or '\\'); put folders in the directory argument",
                      name_));
    if (directory_.empty()) directory_ = ".";
    std::error_code ec;
    std::filesystem::create_directories(directory_, ec);
    if (ec || !std::filesystem::is_directory(directory_))
      throw InputError(fmt::format("VtkSeriesWriter: cannot create output directory '{}'{}", directory_.string(),
                                   ec ? ": " + ec.message() : std::string(": a file of that name exists")));
  }

  /// Writes the next snapshot and rewrites the .pvd collection. Returns the path of the new .vtu file.
  /// `time` must be finite; `extra` fields (one value per slot) are added as point data.
  template <int Dim, Real T>
  std::filesystem::path write(const ParticleSet<Dim, T>& particles, double time,
                              std::type_identity_t<std::span<const PointField<Dim, T>>> extra = {}) {
    require_finite("VtkSeriesWriter::write time (s)", time);
    const std::string file = fmt::format("{}_{:06d}.vtu", name_, entries_.size());
    std::filesystem::path path = directory_ / file;
    write_vtu(path, particles, time, encoding_, extra, &scratch_);
    entries_.push_back({time, file});
    write_collection();
    return path;
  }

  /// Overload for a braced list of extra fields: writer.write(p, t, {{"vorticity", w}}).
  template <int Dim, Real T>
  std::filesystem::path write(const ParticleSet<Dim, T>& particles, double time,
                              std::type_identity_t<std::initializer_list<PointField<Dim, T>>> extra) {
    return write(particles, time, std::span<const PointField<Dim, T>>(extra.begin(), extra.size()));
  }

  /// Path of the .pvd collection file (exists after the first write()).
  std::filesystem::path collection_path() const { return directory_ / (name_ + ".pvd"); }
  const std::filesystem::path& directory() const noexcept { return directory_; }
  const std::string& name() const noexcept { return name_; }
  VtkEncoding encoding() const noexcept { return encoding_; }
  /// Number of snapshots written so far.
  std::size_t snapshot_count() const noexcept { return entries_.size(); }

 private:
  struct Entry {
    double time;       // s
    std::string file;  // relative to directory_
  };

  void write_collection() const {
    std::string xml = fmt::format(
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"{}\">\n"
        "  <Collection>\n",
        detail::byte_order());
    for (const auto& e : entries_)
      xml += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n", e.time,
                         detail::xml_escape(e.file));
    xml += "  </Collection>\n</VTKFile>\n";
    const auto target = collection_path();
    const auto tmp = std::filesystem::path(target) += ".tmp";
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) detail::throw_io("cannot open VTK collection file for writing", tmp);
      out.write(xml.data(), static_cast<std::streamsize>(xml.size()));
      out.flush();
      if (!out) detail::throw_io("error while writing VTK collection file", tmp);
    }
    detail::commit_file(tmp, target);
  }

  std::filesystem::path directory_;
  std::string name_;
  VtkEncoding encoding_;
  std::vector<Entry> entries_;
  std::vector<unsigned char> scratch_;  // staging buffer reused across snapshots
};

}  // namespace sphfsi::io
