// sphfsi tool: wave height along a flume, H(x), from wave-gauge records (the gauges.csv of examples/wave_flume or
// any CSV with a time column "t" and one column "eta_<x>" per gauge, x in m, eta in m).
//
// Each gauge is analysed by zero up-crossing (analysis/zero_crossing.hpp) over [from + x / c_g, to]: with
// --group-velocity c_g > 0 the window opens later at gauges further away, when the full-amplitude waves have
// arrived there (give from = ramp time + one period). Writes x, H (mean), H_std, H_rms, T, number of waves.
#include <sphfsi/analysis/zero_crossing.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/waves/gauges.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <limits>

using namespace sphfsi;

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv, "wave_height_profile: H(x) from wave-gauge CSVs by zero up-crossing analysis.");
  const std::string input = cli.get("input", "out/wave_flume/gauges.csv", "gauge CSV (t, eta_<x> ...)");
  const std::string output = cli.get("output", "out/wave_flume/H_of_x.csv", "H(x) CSV to write");
  const double from = cli.get_number("from", 0, "analysis window start at x = 0, s");
  const double to = cli.get_number("to", 0, "analysis window end, s (0: end of the record)");
  const double cg = cli.get_number("group-velocity", 0, "delay the window by x / c_g at each gauge, m/s (0: no delay)");
  const std::string crossing = cli.get("crossing", "up", "zero crossing: up | down");
  if (!cli.finish()) return 0;
  if (crossing != "up" && crossing != "down")
    throw InputError(fmt::format("--crossing '{}': valid are up, down", crossing));
  if (cg < 0) throw InputError(fmt::format("--group-velocity = {} m/s: valid range is [0, inf)", cg));

  const auto table = io::read_csv(input);
  const auto t = table.column("t");
  if (t.empty()) throw InputError(fmt::format("{}: no rows", input));
  const double end = to > 0 ? to : t.back();
  io::CsvWriter out(output, {"x", "H", "H_std", "H_rms", "T", "waves"},
                    fmt::format("wave_height_profile: zero {}-crossing analysis of {}, window [{} s + x / c_g, {} s], "
                                "c_g = {} m/s",
                                crossing, input, from, end, cg));
  fmt::print("    x (m)    H (m)     H_std (m)  T (s)   waves\n");
  std::size_t gauges = 0;
  for (const auto& name : table.column_names()) {
    const auto x = waves::gauge_position(name);
    if (!x) continue;
    ++gauges;
    const double start = from + (cg > 0 ? *x / cg : 0.0);
    try {
      const auto w = analysis::zero_crossing_analysis(
          t, table.column(name), start, end, crossing == "up" ? analysis::Crossing::up : analysis::Crossing::down);
      out.write_row({*x, w.mean_height, w.height_std, w.rms_height, w.mean_period, double(w.count())});
      fmt::print("{:9.4f}  {:.5f}  {:.5f}   {:.4f}  {}\n", *x, w.mean_height, w.height_std, w.mean_period, w.count());
    } catch (const InputError& e) {
      fmt::print("{:9.4f}  skipped: {}\n", *x, e.what());
    }
  }
  if (gauges == 0) throw InputError(fmt::format("{}: no gauge column (named eta_<x>)", input));
  fmt::print("wrote {}\n", output);
  return 0;
} catch (const std::exception& e) {
  fmt::print(stderr, "wave_height_profile: error: {}\n", e.what());
  return 1;
}
