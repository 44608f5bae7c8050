// sphfsi: checkpoint and restart of a Simulation.
//
// A checkpoint holds everything the next step reads, so that a run resumed from it is bit-identical to the
// uninterrupted run at the same thread count: every particle array in slot order (the cell sort is stable, so
// the order matters), the rates of the last evaluation (the integrators reuse them: acceleration, density_rate,
// xsph_velocity), the *_old arrays, the id -> slot map, the fluid's per-particle signal speeds (they enter the
// next time step), the initial positions of moving walls, time, step count and last step. The configuration
// (integrator, domain, equation of state, fluid parameters) is stored as well and must match on reading.
//
// File layout (format version 1, native byte order, which the header records):
//   header   magic "SPHFSICP" (8 bytes), u32 format version, u32 byte-order mark 0x01020304, u32 dimension,
//            u32 scalar size in bytes, u64 particle count, u64 step count, f64 time (s), u64 payload size
//   payload  records: u32 name length, name, u32 element size, u64 element count, the elements
//   trailer  u64 FNV-1a hash of header and payload
// Files are written to "<path>.tmp", flushed (and fsync'ed on POSIX), then renamed over <path>, so a crash
// while writing leaves the previous checkpoint intact. A truncated, corrupt or incompatible file gives an
// InputError that says what is wrong.
//
// Every extra ParticleModel of the Simulation must say how it is restarted, or checkpointing does not compile
// (a model whose state were silently dropped would make the resumed run differ). Either it saves its state,
//   template <class Writer> void save_checkpoint(Writer&) const;
//   template <class Reader> void load_checkpoint(Reader&);
// with CheckpointWriter::write / CheckpointReader::read, or it declares that it keeps none between steps:
//   static constexpr bool checkpoint_stateless = true;
#pragma once

#include <sphfsi/core/error.hpp>
#include <sphfsi/core/particle_set.hpp>
#include <sphfsi/core/types.hpp>

#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <unistd.h>
#endif

namespace sphfsi::io {

/// Checkpoint format version written by this build; files of any other version are rejected.
inline constexpr std::uint32_t checkpoint_format_version = 1;

namespace detail {

inline constexpr std::array<char, 8> checkpoint_magic{'S', 'P', 'H', 'F', 'S', 'I', 'C', 'P'};
inline constexpr std::uint32_t byte_order_mark = 0x01020304u;
inline constexpr std::size_t header_bytes = 8 + 4 * 4 + 8 * 4;
inline constexpr std::size_t trailer_bytes = 8;

/// 64-bit FNV-1a hash (Fowler, Noll & Vo).
inline std::uint64_t fnv1a(const char* data, std::size_t n, std::uint64_t hash = 0xcbf29ce484222325ull) {
  for (std::size_t i = 0; i < n; ++i) {
    hash ^= static_cast<unsigned char>(data[i]);
    hash *= 0x100000001b3ull;
  }
  return hash;
}

template <class V>
concept FixedEigenVector = requires {
  typename V::Scalar;
  V::SizeAtCompileTime;
}
&&(V::SizeAtCompileTime > 0);

/// Bytes one element of V occupies in a checkpoint.
template <class V>
constexpr std::size_t element_bytes() {
  if constexpr (FixedEigenVector<V>) return sizeof(typename V::Scalar) * V::SizeAtCompileTime;
  else return sizeof(V);
}

template <class V>
constexpr bool storable = std::is_trivially_copyable_v<V> || FixedEigenVector<V>;

}  // namespace detail

/// Builds the payload of a checkpoint: named arrays of trivially copyable values or fixed-size Eigen vectors.
class CheckpointWriter {
 public:
  template <class V>
    requires detail::storable<V>
  void write(std::string_view name, const std::vector<V>& values) {
    begin_record(name, detail::element_bytes<V>(), values.size());
    if constexpr (detail::FixedEigenVector<V>) {
      for (const V& v : values) append(v.data(), detail::element_bytes<V>());
    } else {
      append(values.data(), values.size() * sizeof(V));
    }
  }

  template <class V>
    requires detail::storable<V>
  void write(std::string_view name, const V& value) { write(name, std::vector<V>{value}); }

  void write(std::string_view name, std::string_view text) { write(name, std::vector<char>(text.begin(), text.end())); }

  const std::vector<char>& bytes() const noexcept { return bytes_; }

 private:
  void begin_record(std::string_view name, std::size_t element_size, std::size_t count) {
    const auto name_size = static_cast<std::uint32_t>(name.size());
    const auto size = static_cast<std::uint32_t>(element_size);
    const auto n = static_cast<std::uint64_t>(count);
    append(&name_size, sizeof name_size);
    append(name.data(), name.size());
    append(&size, sizeof size);
    append(&n, sizeof n);
  }
  void append(const void* data, std::size_t n) {
    const char* c = static_cast<const char*>(data);
    bytes_.insert(bytes_.end(), c, c + n);
  }

  std::vector<char> bytes_;
};

/// Reads the records of a checkpoint payload in the order they were written; any mismatch is an InputError.
class CheckpointReader {
 public:
  CheckpointReader(const char* data, std::size_t size, std::string source)
      : data_(data), size_(size), source_(std::move(source)) {}

  template <class V>
    requires detail::storable<V>
  void read(std::string_view name, std::vector<V>& values) {
    const std::uint64_t count = begin_record(name, detail::element_bytes<V>());
    values.resize(count);
    if constexpr (detail::FixedEigenVector<V>) {
      for (V& v : values) take(v.data(), detail::element_bytes<V>(), name);
    } else {
      take(values.data(), count * sizeof(V), name);
    }
  }

  template <class V>
    requires detail::storable<V>
  void read(std::string_view name, V& value) {
    std::vector<V> one;
    read(name, one);
    if (one.size() != 1) fail(fmt::format("field '{}' holds {} values, expected 1", name, one.size()));
    value = one[0];
  }

  std::string read_text(std::string_view name) {
    std::vector<char> text;
    read(name, text);
    return std::string(text.begin(), text.end());
  }

  /// Reads an array that must have exactly `expected` elements.
  template <class V>
  void read_exact(std::string_view name, std::vector<V>& values, std::size_t expected) {
    read(name, values);
    if (values.size() != expected)
      fail(fmt::format("field '{}' holds {} values, expected {}", name, values.size(), expected));
  }

  bool at_end() const noexcept { return offset_ == size_; }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("checkpoint '{}' is corrupt or incompatible: {}", source_, what));
  }

 private:
  std::uint64_t begin_record(std::string_view name, std::size_t element_size) {
    std::uint32_t name_size = 0, size = 0;
    std::uint64_t count = 0;
    take(&name_size, sizeof name_size, name);
    if (name_size > 256) fail(fmt::format("field name length {} where '{}' was expected", name_size, name));
    std::string found(name_size, '\0');
    take(found.data(), name_size, name);
    if (found != name) fail(fmt::format("field '{}' found where '{}' was expected", found, name));
    take(&size, sizeof size, name);
    take(&count, sizeof count, name);
    if (size != element_size)
      fail(fmt::format("field '{}' has {}-byte elements, this build expects {}", name, size, element_size));
    if (count > (size_ - offset_) / std::max<std::size_t>(element_size, 1))
      fail(fmt::format("field '{}' claims {} elements, more than the file holds", name, count));
    return count;
  }
  void take(void* out, std::size_t n, std::string_view name) {
    if (n > size_ - offset_) fail(fmt::format("payload ends inside field '{}'", name));
    if (n > 0) std::memcpy(out, data_ + offset_, n);
    offset_ += n;
  }

  const char* data_;
  std::size_t size_;
  std::size_t offset_{0};
  std::string source_;
};

/// What the header of a checkpoint says (read_checkpoint_info checks the whole file first).
struct CheckpointInfo {
  std::uint32_t format_version{0};
  std::uint32_t dimension{0};
  std::uint32_t scalar_bytes{0};
  std::uint64_t particle_count{0};
  std::uint64_t step_count{0};
  double time{0};  ///< s
};

namespace detail {

template <class Model>
concept CheckpointableModel = requires(const Model& cm, Model& m, CheckpointWriter& w, CheckpointReader& r) {
  cm.save_checkpoint(w);
  m.load_checkpoint(r);
};

template <class Model>
concept StatelessModel = requires {
  requires Model::checkpoint_stateless;
};

template <class Model>
constexpr void require_restartable() {
  static_assert(CheckpointableModel<Model> || StatelessModel<Model>,
                "sphfsi checkpoint: this ParticleModel does not say how it restarts: give it "
                "save_checkpoint(Writer&) const and load_checkpoint(Reader&), or declare "
                "static constexpr bool checkpoint_stateless = true if it keeps no state between steps");
}

/// Writes bytes to path atomically: a temporary file next to it, flushed to disk, then renamed over it.
inline void write_file_atomically(const std::filesystem::path& path, const std::vector<char>& bytes) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error(fmt::format("cannot open '{}' for writing a checkpoint", tmp.string()));
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  ok = (std::fflush(f) == 0) && ok;
#if defined(__unix__) || defined(__APPLE__)
  ok = (::fsync(::fileno(f)) == 0) && ok;
#endif
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error(fmt::format("writing the checkpoint '{}' failed (disk full?)", tmp.string()));
  }
  std::filesystem::rename(tmp, path);
}

inline std::vector<char> read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("checkpoint '{}' cannot be opened", path.string()));
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return bytes;
}

template <class V>
void put(std::vector<char>& out, const V& v) {
  const char* c = reinterpret_cast<const char*>(&v);
  out.insert(out.end(), c, c + sizeof(V));
}
template <class V>
V get(const std::vector<char>& in, std::size_t& offset) {
  V v;
  std::memcpy(&v, in.data() + offset, sizeof(V));
  offset += sizeof(V);
  return v;
}

/// Checks magic, version, byte order, size and hash; returns the header. The payload starts at header_bytes.
inline CheckpointInfo check_file(const std::vector<char>& bytes, const std::string& source) {
  const auto fail = [&](const std::string& what) {
    throw InputError(fmt::format("checkpoint '{}' is corrupt or incompatible: {}", source, what));
  };
  if (bytes.size() < checkpoint_magic.size() ||
      std::memcmp(bytes.data(), checkpoint_magic.data(), checkpoint_magic.size()) != 0)
    fail("magic string 'SPHFSICP' missing: not an sphfsi checkpoint");
  if (bytes.size() < header_bytes + trailer_bytes)
    fail(fmt::format("{} bytes is shorter than a checkpoint header (truncated file?)", bytes.size()));
  std::size_t offset = checkpoint_magic.size();
  CheckpointInfo info;
  info.format_version = get<std::uint32_t>(bytes, offset);
  if (info.format_version != checkpoint_format_version)
    fail(fmt::format("format version = {}, this build reads format version {} only", info.format_version,
                     checkpoint_format_version));
  const auto mark = get<std::uint32_t>(bytes, offset);
  if (mark != byte_order_mark) fail("written on a machine of the other byte order");
  info.dimension = get<std::uint32_t>(bytes, offset);
  info.scalar_bytes = get<std::uint32_t>(bytes, offset);
  info.particle_count = get<std::uint64_t>(bytes, offset);
  info.step_count = get<std::uint64_t>(bytes, offset);
  info.time = get<double>(bytes, offset);
  const auto payload = get<std::uint64_t>(bytes, offset);
  if (bytes.size() != header_bytes + payload + trailer_bytes)
    fail(fmt::format("file has {} bytes, its header announces {} (truncated file?)", bytes.size(),
                     header_bytes + payload + trailer_bytes));
  std::size_t trailer = header_bytes + payload;
  const auto stored = get<std::uint64_t>(bytes, trailer);
  const auto computed = fnv1a(bytes.data(), header_bytes + payload);
  if (stored != computed)
    fail(fmt::format("checksum mismatch (stored {:016x}, computed {:016x}): the file was modified or damaged", stored,
                     computed));
  return info;
}

/// The integrator's name (TimeIntegrator::name), or "unnamed" for one without.
template <class Integrator>
std::string integrator_name() {
  if constexpr (requires { Integrator::name; }) return std::string(Integrator::name);
  else return "unnamed";
}

template <class Sim>
std::vector<typename Sim::scalar_type> fluid_parameter_list(const Sim& sim) {
  using T = typename Sim::scalar_type;
  const auto& f = sim.fluid().parameters();
  std::vector<T> v{f.artificial_viscosity,
                   f.density_diffusion,
                   f.xsph,
                   f.kinematic_viscosity,
                   T(static_cast<int>(f.walls)),
                   f.repulsive.boundary_spacing,
                   f.repulsive.water_level,
                   f.repulsive.local_depth,
                   T(f.repulsive.vertical_axis),
                   T(f.same_resolution_pairs ? 1 : 0),
                   f.viscosity_reference_smoothing_length};
  for (int d = 0; d < Sim::Dim; ++d) v.push_back(f.gravity[d]);
  return v;
}

}  // namespace detail

/// Validates a checkpoint file (magic, version, size, checksum) and returns its header.
inline CheckpointInfo read_checkpoint_info(const std::filesystem::path& path) {
  return detail::check_file(detail::read_file(path), path.string());
}

/// Writes the complete state of `sim` to `path` atomically (see the header comment for the format).
template <class Sim>
void write_checkpoint(const std::filesystem::path& path, const Sim& sim) {
  using T = typename Sim::scalar_type;
  constexpr int Dim = Sim::Dim;
  const auto& p = sim.system().particles();
  CheckpointWriter w;
  w.write("simulation.last_dt", sim.last_time_step());
  w.write("simulation.rates_evaluated", static_cast<std::uint8_t>(sim.rates_evaluated() ? 1 : 0));
  w.write("simulation.integrator", detail::integrator_name<typename Sim::integrator_type>());
  w.write("system.domain.lower", sim.system().domain().lower);
  w.write("system.domain.upper", sim.system().domain().upper);
  w.write("system.eos.reference_density", sim.system().eos().reference_density());
  w.write("system.eos.reference_sound_speed", sim.system().eos().reference_sound_speed());
  w.write("system.kernel.support", static_cast<double>(Sim::system_type::kernel_type::support));
  w.write("fluid.parameters", detail::fluid_parameter_list(sim));
  w.write("particles.position", p.position);
  w.write("particles.velocity", p.velocity);
  w.write("particles.density", p.density);
  w.write("particles.mass", p.mass);
  w.write("particles.smoothing_length", p.smoothing_length);
  w.write("particles.kind", p.kind);
  w.write("particles.body", p.body);
  w.write("particles.id", p.id);
  w.write("particles.normal", p.normal);
  w.write("particles.passive", p.passive);
  w.write("particles.pressure", p.pressure);
  w.write("particles.sound_speed", p.sound_speed);
  w.write("particles.acceleration", p.acceleration);
  w.write("particles.density_rate", p.density_rate);
  w.write("particles.xsph_velocity", p.xsph_velocity);
  w.write("particles.position_old", p.position_old);
  w.write("particles.velocity_old", p.velocity_old);
  w.write("particles.density_old", p.density_old);
  // One entry per id below id_capacity() (== the particle count unless particles were removed, e.g. merged:
  // removed ids hold ParticleSet::no_slot), so the reader restores the id capacity too.
  std::vector<std::uint32_t> slot_of_id(p.id_capacity());
  for (std::size_t k = 0; k < slot_of_id.size(); ++k)
    slot_of_id[k] = static_cast<std::uint32_t>(p.slot_of_id(static_cast<std::uint32_t>(k)));
  w.write("particles.slot_of_id", slot_of_id);
  w.write("fluid.signal_speed", sim.fluid().signal_speeds());
  w.write("walls.reference_position", sim.wall_reference_positions());
  w.write("models.count", static_cast<std::uint64_t>(Sim::model_count));
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          const auto& model = sim.template model<I>();
          using Model = std::remove_cvref_t<decltype(model)>;
          detail::require_restartable<Model>();
          const std::uint8_t has_state = detail::CheckpointableModel<Model> ? 1 : 0;
          w.write(fmt::format("model.{}.has_state", I), has_state);
          if constexpr (detail::CheckpointableModel<Model>) model.save_checkpoint(w);
        }(),
        ...);
  }
  (std::make_index_sequence<Sim::model_count>{});

  std::vector<char> bytes;
  bytes.reserve(detail::header_bytes + w.bytes().size() + detail::trailer_bytes);
  bytes.insert(bytes.end(), detail::checkpoint_magic.begin(), detail::checkpoint_magic.end());
  detail::put(bytes, checkpoint_format_version);
  detail::put(bytes, detail::byte_order_mark);
  detail::put(bytes, static_cast<std::uint32_t>(Dim));
  detail::put(bytes, static_cast<std::uint32_t>(sizeof(T)));
  detail::put(bytes, static_cast<std::uint64_t>(p.size()));
  detail::put(bytes, static_cast<std::uint64_t>(sim.step_count()));
  detail::put(bytes, static_cast<double>(sim.time()));
  detail::put(bytes, static_cast<std::uint64_t>(w.bytes().size()));
  bytes.insert(bytes.end(), w.bytes().begin(), w.bytes().end());
  detail::put(bytes, detail::fnv1a(bytes.data(), bytes.size()));
  detail::write_file_atomically(path, bytes);
}

/// Restores `sim` (and its ParticleSystem) from a checkpoint written by write_checkpoint. `sim` must be built
/// with the same scene types, domain, equation of state, fluid parameters and integrator (checked), and the
/// same wall motions registered (set_wall_motion, before this call); its particle set may be empty: the
/// checkpoint replaces it. The particle state is only replaced once the whole file has been checked.
/// Throws InputError if the file is truncated, corrupt, of another format version, dimension or scalar type,
/// or written for another configuration.
template <class Sim>
void read_checkpoint(const std::filesystem::path& path, Sim& sim) {
  using T = typename Sim::scalar_type;
  constexpr int Dim = Sim::Dim;
  using Vector = Vec<Dim, T>;
  const std::string source = path.string();
  const std::vector<char> bytes = detail::read_file(path);
  const CheckpointInfo info = detail::check_file(bytes, source);
  CheckpointReader r(bytes.data() + detail::header_bytes, bytes.size() - detail::header_bytes - detail::trailer_bytes,
                     source);
  if (info.dimension != static_cast<std::uint32_t>(Dim))
    r.fail(fmt::format("dimension = {}, this simulation is {}D", info.dimension, Dim));
  if (info.scalar_bytes != sizeof(T))
    r.fail(fmt::format("scalar size = {} bytes, this simulation uses {}-byte scalars ({})", info.scalar_bytes,
                       sizeof(T), std::is_same_v<T, float> ? "float" : "double"));
  const std::size_t n = info.particle_count;

  const auto require_same = [&](std::string_view what, const auto& stored, const auto& expected) {
    if (!(stored == expected))
      r.fail(fmt::format("written with a different {}: the simulation must be built as the one that wrote it", what));
  };
  T last_dt{};
  r.read("simulation.last_dt", last_dt);
  std::uint8_t rates_evaluated = 0;
  r.read("simulation.rates_evaluated", rates_evaluated);
  require_same("integrator", r.read_text("simulation.integrator"),
               detail::integrator_name<typename Sim::integrator_type>());
  Vector lower, upper;
  r.read("system.domain.lower", lower);
  r.read("system.domain.upper", upper);
  require_same("domain lower corner", lower, sim.system().domain().lower);
  require_same("domain upper corner", upper, sim.system().domain().upper);
  T rho0{}, c0{};
  double support{};
  r.read("system.eos.reference_density", rho0);
  r.read("system.eos.reference_sound_speed", c0);
  r.read("system.kernel.support", support);
  require_same("reference density rho0", rho0, sim.system().eos().reference_density());
  require_same("reference sound speed c0", c0, sim.system().eos().reference_sound_speed());
  require_same("kernel support", support, static_cast<double>(Sim::system_type::kernel_type::support));
  std::vector<T> fluid_parameters;
  r.read("fluid.parameters", fluid_parameters);
  require_same("set of FluidParameters", fluid_parameters, detail::fluid_parameter_list(sim));

  ParticleSet<Dim, T> p;
  r.read_exact("particles.position", p.position, n);
  r.read_exact("particles.velocity", p.velocity, n);
  r.read_exact("particles.density", p.density, n);
  r.read_exact("particles.mass", p.mass, n);
  r.read_exact("particles.smoothing_length", p.smoothing_length, n);
  r.read_exact("particles.kind", p.kind, n);
  r.read_exact("particles.body", p.body, n);
  r.read_exact("particles.id", p.id, n);
  r.read_exact("particles.normal", p.normal, n);
  r.read_exact("particles.passive", p.passive, n);
  r.read_exact("particles.pressure", p.pressure, n);
  r.read_exact("particles.sound_speed", p.sound_speed, n);
  r.read_exact("particles.acceleration", p.acceleration, n);
  r.read_exact("particles.density_rate", p.density_rate, n);
  r.read_exact("particles.xsph_velocity", p.xsph_velocity, n);
  r.read_exact("particles.position_old", p.position_old, n);
  r.read_exact("particles.velocity_old", p.velocity_old, n);
  r.read_exact("particles.density_old", p.density_old, n);
  for (std::size_t i = 0; i < n; ++i) {
    if (static_cast<std::uint8_t>(p.kind[i]) > static_cast<std::uint8_t>(Kind::solid))
      r.fail(fmt::format("particle in slot {} has an unknown kind {}", i, static_cast<int>(p.kind[i])));
    if (p.passive[i] > 1)
      r.fail(fmt::format("particle in slot {} has passive = {}: valid values are 0 and 1", i, int(p.passive[i])));
  }
  std::vector<std::uint32_t> slot_of_id;
  r.read("particles.slot_of_id", slot_of_id);
  if (slot_of_id.size() < n)
    r.fail(fmt::format("field 'particles.slot_of_id' holds {} values, expected at least {}", slot_of_id.size(), n));
  try {
    p.rebuild_slot_of_id(slot_of_id.size());
  } catch (const InputError& e) {
    r.fail(e.what());
  }
  for (std::size_t k = 0; k < slot_of_id.size(); ++k)
    if (p.slot_of_id(static_cast<std::uint32_t>(k)) != slot_of_id[k])
      r.fail(fmt::format("id -> slot map disagrees with the ids at id {}", k));
  std::vector<T> signal_speed;
  r.read("fluid.signal_speed", signal_speed);
  // One per slot of the last evaluation: a particle refinement pass after it (fluid/particle_refinement.hpp) may
  // have changed the count since, so any count up to the id capacity is accepted (the fluid reads it guarded).
  if (signal_speed.size() > slot_of_id.size())
    r.fail(fmt::format("field 'fluid.signal_speed' holds {} values, expected at most {}", signal_speed.size(),
                       slot_of_id.size()));
  std::vector<Vector> wall_reference;
  r.read("walls.reference_position", wall_reference);
  if (wall_reference.size() > slot_of_id.size())
    r.fail(fmt::format("field 'walls.reference_position' holds {} values, expected at most one per id ({})",
                       wall_reference.size(), slot_of_id.size()));
  std::uint64_t models = 0;
  r.read("models.count", models);
  if (models != Sim::model_count)
    r.fail(fmt::format("written with {} particle models, this simulation has {}", models, Sim::model_count));
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          auto& model = sim.template model<I>();
          using Model = std::remove_cvref_t<decltype(model)>;
          detail::require_restartable<Model>();
          std::uint8_t has_state = 0;
          r.read(fmt::format("model.{}.has_state", I), has_state);
          if (has_state != (detail::CheckpointableModel<Model> ? 1 : 0))
            r.fail(fmt::format("model {} {} state in the file but its type {} one", I, has_state ? "has" : "has no",
                               has_state ? "does not save" : "saves"));
          if constexpr (detail::CheckpointableModel<Model>) model.load_checkpoint(r);
        }(),
        ...);
  }
  (std::make_index_sequence<Sim::model_count>{});
  if (!r.at_end()) r.fail("unexpected bytes after the last field");

  // Commit: swap the new state in; if the simulation refuses it (moving walls registered that the file does
  // not know), swap the old state back so a failed read changes nothing.
  std::swap(sim.system().particles(), p);
  std::vector<T> old_signal_speed = sim.fluid().signal_speeds();
  sim.fluid().restore_signal_speeds(std::move(signal_speed));
  try {
    sim.restore_state(static_cast<T>(info.time), static_cast<std::size_t>(info.step_count), last_dt,
                      std::move(wall_reference), rates_evaluated != 0);
  } catch (...) {
    std::swap(sim.system().particles(), p);
    sim.fluid().restore_signal_speeds(std::move(old_signal_speed));
    throw;
  }
}

}  // namespace sphfsi::io
