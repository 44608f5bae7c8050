// Tests of sphfsi/io: VTK XML snapshots and series (decoded back here byte by byte), CSV writer and reader.
// An independent check with VTK's own reader is tests/python/check_vtk.py.
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/io/vtk_writer.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using sphfsi::InputError;
using sphfsi::Kind;
using sphfsi::io::VtkEncoding;

namespace {

/// A fresh, empty folder for one test case (test cases may run in parallel under ctest).
fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(SPHFSI_TEST_OUTPUT_DIR) / "io" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// n particles with values that depend on the id, then reversed so slot != id.
template <int Dim, class T>
sphfsi::ParticleSet<Dim, T> sample_set(std::size_t n) {
  sphfsi::ParticleSet<Dim, T> p;
  for (std::size_t i = 0; i < n; ++i) {
    using V = sphfsi::Vec<Dim, T>;
    V x, v;
    for (int d = 0; d < Dim; ++d) {
      x[d] = T(0.1) * T(i) + T(d);
      v[d] = T(-0.5) * T(i) + T(10 * d);
    }
    const Kind k = static_cast<Kind>(i % 3);
    p.add(k, x, v, T(1000) + T(i), T(0.01), T(0.013), static_cast<std::int32_t>(i % 2) - 1);
    p.pressure[i] = T(100) * T(i);
  }
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(n - 1 - i);
  p.permute(order);
  return p;
}

std::vector<unsigned char> base64_decode(std::string_view s) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::vector<unsigned char> out;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    const int v = value(c);
    if (v < 0) continue;  // '=' padding and whitespace
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

/// Attribute value `attr` of the XML tag starting at `tag_pos`.
std::string attribute(const std::string& xml, std::size_t tag_pos, const std::string& attr) {
  const auto end = xml.find('>', tag_pos);
  const auto a = xml.find(" " + attr + "=\"", tag_pos);
  if (a == std::string::npos || a > end) return {};
  const auto b = a + attr.size() + 3;
  return xml.substr(b, xml.find('"', b) - b);
}

/// Decodes the named DataArray of a .vtu written by sphfsi (either encoding) into elements of type E.
template <class E>
std::vector<E> read_array(const std::string& vtu, const std::string& name, int* components = nullptr) {
  const auto tag =
      vtu.find("<DataArray type=\"" + std::string(sphfsi::io::detail::vtk_type_name<E>()) + "\" Name=\"" + name + "\"");
  REQUIRE(tag != std::string::npos);
  if (components) {
    const auto c = attribute(vtu, tag, "NumberOfComponents");
    *components = c.empty() ? 1 : std::stoi(c);
  }
  std::vector<unsigned char> block;  // 8-byte count + data
  if (attribute(vtu, tag, "format") == "appended") {
    const auto start = vtu.find('_', vtu.find("<AppendedData encoding=\"raw\">")) + 1;
    const auto offset = std::stoull(attribute(vtu, tag, "offset"));
    std::uint64_t bytes = 0;
    std::memcpy(&bytes, vtu.data() + start + offset, 8);
    block.assign(vtu.data() + start + offset, vtu.data() + start + offset + 8 + bytes);
  } else {
    REQUIRE(attribute(vtu, tag, "format") == "binary");
    const auto open = vtu.find('>', tag) + 1;
    block = base64_decode(std::string_view(vtu).substr(open, vtu.find("</DataArray>", open) - open));
  }
  std::uint64_t bytes = 0;
  std::memcpy(&bytes, block.data(), 8);
  REQUIRE(bytes + 8 == block.size());
  REQUIRE(bytes % sizeof(E) == 0);
  std::vector<E> v(bytes / sizeof(E));
  std::memcpy(v.data(), block.data() + 8, bytes);
  return v;
}

template <int Dim, class T>
void check_snapshot(const fs::path& file, const sphfsi::ParticleSet<Dim, T>& p) {
  REQUIRE(fs::exists(file));
  const std::string vtu = read_text(file);
  const std::size_t n = p.size();
  CHECK(vtu.find(fmt::format("NumberOfPoints=\"{}\" NumberOfCells=\"{}\"", n, n)) != std::string::npos);
  for (const char* f : {"velocity", "acceleration", "normal", "xsph_velocity", "density", "pressure", "mass",
                        "smoothing_length", "sound_speed", "density_rate", "kind", "body", "id", "position",
                        "connectivity", "offsets", "types", "TimeValue"})
    CHECK(vtu.find(fmt::format("Name=\"{}\"", f)) != std::string::npos);

  int comps = 0;
  const auto x = read_array<T>(vtu, "position", &comps);
  CHECK(comps == 3);
  const auto v = read_array<T>(vtu, "velocity");
  const auto rho = read_array<T>(vtu, "density");
  const auto pr = read_array<T>(vtu, "pressure");
  const auto ids = read_array<std::uint32_t>(vtu, "id");
  const auto kinds = read_array<std::uint8_t>(vtu, "kind");
  const auto body = read_array<std::int32_t>(vtu, "body");
  const auto types = read_array<std::uint8_t>(vtu, "types");
  const auto offsets = read_array<std::int64_t>(vtu, "offsets");
  REQUIRE(x.size() == 3 * n);
  REQUIRE(v.size() == 3 * n);
  REQUIRE(ids.size() == n);
  for (std::size_t s = 0; s < n; ++s) {
    const std::uint32_t i = ids[s];
    CHECK(i == p.id[s]);
    for (int d = 0; d < 3; ++d) {
      CHECK(x[3 * s + d] == (d < Dim ? T(0.1) * T(i) + T(d) : T(0)));
      CHECK(v[3 * s + d] == (d < Dim ? T(-0.5) * T(i) + T(10 * d) : T(0)));
    }
    CHECK(rho[s] == T(1000) + T(i));
    CHECK(pr[s] == T(100) * T(i));
    CHECK(kinds[s] == i % 3);
    CHECK(body[s] == static_cast<std::int32_t>(i % 2) - 1);
    CHECK(types[s] == 1);
    CHECK(offsets[s] == static_cast<std::int64_t>(s + 1));
  }
}

}  // namespace

TEMPLATE_TEST_CASE("VtkSeriesWriter writes decodable 2D and 3D snapshots in both encodings", "[io][vtk]", float,
                   double) {
  using T = TestType;
  const std::string type = std::is_same_v<T, float> ? "float" : "double";
  for (VtkEncoding enc : {VtkEncoding::appended_raw, VtkEncoding::inline_base64}) {
    const std::string tag = type + (enc == VtkEncoding::appended_raw ? "_raw" : "_base64");
    const fs::path dir = fresh_dir("series_" + tag);

    const auto p2 = sample_set<2, T>(7);
    const auto p3 = sample_set<3, T>(5);
    sphfsi::io::VtkSeriesWriter w2(dir, "two", enc);
    sphfsi::io::VtkSeriesWriter w3(dir / "sub" / "folder", "three", enc);  // nested folder is created
    std::vector<fs::path> files2;
    for (int k = 0; k < 3; ++k) files2.push_back(w2.write(p2, 0.25 * k));
    const fs::path f3 = w3.write(p3, 1e-3);

    CHECK(files2[0] == dir / "two_000000.vtu");
    CHECK(files2[2] == dir / "two_000002.vtu");
    CHECK(w2.snapshot_count() == 3);
    CHECK(f3 == dir / "sub" / "folder" / "three_000000.vtu");
    for (const auto& f : files2) check_snapshot(f, p2);
    check_snapshot(f3, p3);

    const std::string fp = std::is_same_v<T, float> ? "Float32" : "Float64";
    CHECK(read_text(f3).find("type=\"" + fp + "\" Name=\"density\"") != std::string::npos);
    CHECK(read_text(files2[1]).find(">0.25</DataArray>") != std::string::npos);  // TimeValue field data
    if (enc == VtkEncoding::inline_base64) CHECK(read_text(f3).find("AppendedData") == std::string::npos);

    // The .pvd lists every snapshot with its time, and no temporary file is left behind.
    REQUIRE(w2.collection_path() == dir / "two.pvd");
    const std::string pvd = read_text(w2.collection_path());
    CHECK(pvd.find("type=\"Collection\"") != std::string::npos);
    CHECK(pvd.find("timestep=\"0\" group=\"\" part=\"0\" file=\"two_000000.vtu\"") != std::string::npos);
    CHECK(pvd.find("timestep=\"0.25\" group=\"\" part=\"0\" file=\"two_000001.vtu\"") != std::string::npos);
    CHECK(pvd.find("timestep=\"0.5\" group=\"\" part=\"0\" file=\"two_000002.vtu\"") != std::string::npos);
    CHECK(read_text(w3.collection_path()).find("timestep=\"0.001\"") != std::string::npos);
    for (const auto& e : fs::recursive_directory_iterator(dir)) CHECK(e.path().extension() != ".tmp");
  }
}

TEST_CASE("VTK extra point fields are written and validated", "[io][vtk]") {
  const fs::path dir = fresh_dir("extra");
  const auto p = sample_set<2, double>(4);
  std::vector<double> vorticity{1.5, -2.0, 3.25, 0.0};
  std::vector<sphfsi::Vec<2, double>> force(4, sphfsi::Vec<2, double>(1.0, 2.0));
  sphfsi::io::VtkSeriesWriter w(dir, "extra");
  const auto f = w.write(p, 0.0, {{"vorticity", vorticity}, {"force", force}});
  const std::string vtu = read_text(f);
  CHECK(read_array<double>(vtu, "vorticity") == vorticity);
  int comps = 0;
  CHECK(read_array<double>(vtu, "force", &comps) == std::vector<double>{1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0});
  CHECK(comps == 3);

  // A std::vector of fields and the free function write_vtu work as well.
  std::vector<sphfsi::io::PointField<2, double>> fields{{"vorticity", vorticity}};
  sphfsi::io::write_vtu(dir / "single.vtu", p, 2.0, VtkEncoding::inline_base64, fields);
  CHECK(read_array<double>(read_text(dir / "single.vtu"), "vorticity") == vorticity);

  std::vector<double> short_field{1.0, 2.0};
  CHECK_THROWS_WITH(w.write(p, 0.0, {{"short", short_field}}),
                    Catch::Contains("'short' has 2 values but the particle set has 4"));
  CHECK_THROWS_WITH(w.write(p, 0.0, {{"density", vorticity}}), Catch::Contains("clashes with a built-in"));
  CHECK_THROWS_WITH(w.write(p, 0.0, {{"a", vorticity}, {"a", vorticity}}), Catch::Contains("given twice"));
  CHECK_THROWS_WITH(w.write(p, 0.0, {{"", vorticity}}), Catch::Contains("empty name"));
  CHECK(w.snapshot_count() == 1);  // failed writes add nothing to the series
}

TEST_CASE("VtkSeriesWriter validates its arguments", "[io][vtk]") {
  const fs::path dir = fresh_dir("validate");
  CHECK_THROWS_AS(sphfsi::io::VtkSeriesWriter(dir, ""), InputError);
  CHECK_THROWS_WITH(sphfsi::io::VtkSeriesWriter(dir, "a/b"), Catch::Contains("plain file name"));
  std::ofstream(dir / "not_a_dir") << "x";
  CHECK_THROWS_WITH(sphfsi::io::VtkSeriesWriter(dir / "not_a_dir", "s"), Catch::Contains("cannot create output"));
  CHECK_THROWS_WITH(sphfsi::io::VtkSeriesWriter(dir / "not_a_dir" / "below", "s"),
                    Catch::Contains("cannot create output"));

  sphfsi::io::VtkSeriesWriter w(dir, "ok");
  const auto p = sample_set<3, float>(2);
  CHECK_THROWS_AS(w.write(p, std::nan("")), InputError);
  CHECK_FALSE(fs::exists(w.collection_path()));

  // An empty particle set is still a valid file.
  const sphfsi::ParticleSet<3, float> empty;
  const auto f = w.write(empty, 0.0);
  CHECK(read_text(f).find("NumberOfPoints=\"0\"") != std::string::npos);
}

TEST_CASE("CsvWriter and read_csv round trip", "[io][csv]") {
  const fs::path dir = fresh_dir("csv");
  const fs::path file = dir / "nested" / "probe.csv";
  {
    sphfsi::io::CsvWriter w(file, {"t", "dx", "dy"}, "gate tip probe\nunits: s, m, m");
    w.write_row({0.0, 1.0 / 3.0, -2.5e-7});
    // Each row is on disk as soon as it is written (flushed), before the writer closes.
    CHECK(read_text(file).find("0,0.333333333,-2.5e-07\n") != std::string::npos);
    const std::vector<double> row{0.04, 1.2889280e-02, std::nan("")};
    w.write_row(row);
    CHECK(w.row_count() == 2);
    CHECK_THROWS_WITH(w.write_row({1.0, 2.0}), Catch::Contains("row has 2 values but the header has 3 columns"));
  }
  CHECK(read_text(file).starts_with("# gate tip probe\n# units: s, m, m\nt,dx,dy\n"));

  const auto table = sphfsi::io::read_csv(file);
  CHECK(table.column_names() == std::vector<std::string>{"t", "dx", "dy"});
  CHECK(table.row_count() == 2);
  CHECK(table.column("t") == std::vector<double>{0.0, 0.04});
  const auto dx = table.column("dx");
  CHECK(dx[0] == Approx(1.0 / 3.0).epsilon(1e-9));
  CHECK(dx[1] == 1.2889280e-02);
  const auto dy = table.column("dy");
  CHECK(dy[0] == -2.5e-7);
  CHECK(std::isnan(dy[1]));

  // Float values survive exactly at 9 significant digits.
  {
    sphfsi::io::CsvWriter w(dir / "float.csv", {"x"});
    w.write_row({static_cast<double>(0.1f)});
  }
  CHECK(static_cast<float>(sphfsi::io::read_csv(dir / "float.csv").column("x")[0]) == 0.1f);

  CHECK_THROWS_AS(sphfsi::io::CsvWriter(dir / "x.csv", {}), InputError);
  CHECK_THROWS_WITH(sphfsi::io::CsvWriter(dir / "x.csv", {"a", "a"}), Catch::Contains("'a' is given twice"));
  CHECK_THROWS_WITH(sphfsi::io::CsvWriter(dir / "x.csv", {"a,b"}), Catch::Contains("contains ','"));
}

TEST_CASE("read_csv parses comments, blanks, empty fields and labels, with clear errors", "[io][csv]") {
  const fs::path dir = fresh_dir("csv_read");
  std::ofstream(dir / "data.csv") << "# comment line\n"
                                     "   # indented comment\n"
                                     "\n"
                                     "method, t ,x\r\n"
                                     "Antoci2007 SPH,0.00,-2.877659e-04\r\n"
                                     "# comment between rows\n"
                                     "Yang2012 SPH-FEM, 4e-2 ,\n"
                                     "exp,+1.5,nan\n";
  const auto table = sphfsi::io::read_csv(dir / "data.csv");
  CHECK(table.column_names() == std::vector<std::string>{"method", "t", "x"});
  CHECK(table.column("t") == std::vector<double>{0.0, 0.04, 1.5});
  const auto x = table.column("x");
  CHECK(x[0] == -2.877659e-04);
  CHECK(std::isnan(x[1]));
  CHECK(std::isnan(x[2]));
  CHECK(table.text_column("method") == std::vector<std::string>{"Antoci2007 SPH", "Yang2012 SPH-FEM", "exp"});
  CHECK(table.has_column("t"));
  CHECK_FALSE(table.has_column("y"));

  CHECK_THROWS_WITH(table.column("y"), Catch::Contains("column 'y' not found") && Catch::Contains("data.csv") &&
                                           Catch::Contains("available columns: method, t, x"));
  CHECK_THROWS_WITH(table.column("method"),
                    Catch::Contains("data.csv:5: column 'method': field 'Antoci2007 SPH' is not a number"));
  CHECK_THROWS_WITH(sphfsi::io::read_csv(dir / "missing.csv"),
                    Catch::Contains("cannot open CSV file") && Catch::Contains("missing.csv"));
  CHECK_THROWS_AS(sphfsi::io::read_csv(dir / "missing.csv"), InputError);

  std::ofstream(dir / "ragged.csv") << "a,b\n1,2\n3\n";
  CHECK_THROWS_WITH(sphfsi::io::read_csv(dir / "ragged.csv"),
                    Catch::Contains("ragged.csv:3: row has 1 fields but the header has 2 columns"));
  std::ofstream(dir / "only_comments.csv") << "# nothing\n\n";
  CHECK_THROWS_WITH(sphfsi::io::read_csv(dir / "only_comments.csv"), Catch::Contains("has no header line"));
  std::ofstream(dir / "trailing.csv") << "x\n1.5abc\n";
  CHECK_THROWS_WITH(sphfsi::io::read_csv(dir / "trailing.csv").column("x"),
                    Catch::Contains("'1.5abc' is not a number"));
}

TEST_CASE("read_csv reads the shipped validation data", "[io][csv]") {
  const fs::path file = fs::path(SPHFSI_SHARED_DATA_DIR) / "martin_moyce1952_surge_front.csv";
  if (!fs::exists(file)) {
    WARN("validation data not found at " << file << "; test skipped");
    return;
  }
  const auto table = sphfsi::io::read_csv(file);
  const auto t = table.column("time");
  const auto z = table.column("surge_front");
  REQUIRE(t.size() == z.size());
  REQUIRE(t.size() > 5);
  CHECK(t[0] == 0.43012);
  CHECK(z[0] == 1.10782);
}

TEST_CASE("CommandLine::get_numbers: a comma-separated list, the default, and a clear error otherwise", "[io]") {
  std::vector<std::string> words{"prog", "--x", "0.6,1,1.25e-1", "--bad", "0.6,,1", "--word", "0.6,one", "--empty", ""};
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  sphfsi::io::CommandLine cli(int(argv.size()), argv.data(), "test");
  CHECK(cli.get_numbers("x", "", "a list") == std::vector<double>{0.6, 1.0, 0.125});
  CHECK(cli.get_numbers("absent", "2,3", "absent: the default") == std::vector<double>{2.0, 3.0});
  CHECK(cli.get_numbers("empty", "1", "an empty value").empty());
  CHECK_THROWS_WITH(cli.get_numbers("bad", "", "a list"), Catch::Contains("--bad") && Catch::Contains("item ''"));
  CHECK_THROWS_WITH(cli.get_numbers("word", "", "a list"),
                    Catch::Contains("--word") && Catch::Contains("item 'one' is not a number"));
}

TEST_CASE("CommandLine::get_switch: on, off, the default, and a clear error otherwise", "[io]") {
  std::vector<std::string> words{"prog", "--a", "on", "--b", "off", "--c", "yes"};
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  sphfsi::io::CommandLine cli(int(argv.size()), argv.data(), "test");
  CHECK(cli.get_switch("a", false, "a switch"));
  CHECK_FALSE(cli.get_switch("b", true, "a switch"));
  CHECK(cli.get_switch("d", true, "absent: the default"));
  CHECK_THROWS_WITH(cli.get_switch("c", false, "a switch"),
                    Catch::Contains("--c = 'yes'") && Catch::Contains("valid values are on, off"));
}
