// sphfsi tool: bulk drag coefficient C_D of a meadow from a wave-height profile H(x) (any CSV), with the decay law
// of Dalrymple, Kirby & Hwang (1984), H = H0 / (1 + alpha x), alpha = C_D b_v N H0 K(k, h, l_s)
// (analysis/vegetation_drag.hpp). H0 and alpha are fitted by least squares; the standard error of C_D propagates
// the fit's covariance of (H0, alpha) to first order. Heights may be relative (H/H0): --scale converts them to m.
// Example (the measured Luhar et al. 2017 meadow, flexible blades: use their effective length as stem height):
//   fit_drag_coefficient --input data/luhar2017_meadow_H1_wave_decay.csv --h-column H_over_H0 --scale 0.028
//       --depth 0.16 --period 1.4286 --stem-height 0.13 --frontal-width 0.003 --stem-density 7200
#include <sphfsi/analysis/vegetation_drag.hpp>
#include <sphfsi/io/command_line.hpp>
#include <sphfsi/io/csv.hpp>
#include <sphfsi/waves/linear_theory.hpp>

#include <fmt/format.h>

#include <cmath>
#include <optional>

using namespace sphfsi;

int main(int argc, char** argv) try {
  io::CommandLine cli(argc, argv,
                      "fit_drag_coefficient: fits H(x) = H0 / (1 + alpha x) (Dalrymple et al. 1984) to a CSV and "
                      "inverts alpha for the bulk drag coefficient C_D with its standard error.");
  const std::string input = cli.get("input", SPHFSI_SHARED_DATA_DIR "/luhar2017_meadow_H1_wave_decay.csv", "H(x) CSV");
  const std::string x_column = cli.get("x-column", "x", "column of x, m (from the meadow's leading edge)");
  const std::string h_column = cli.get("h-column", "H_over_H0", "column of the wave height");
  const double scale = cli.get_number("scale", 0.028, "m per unit of the height column (1 for heights in m)");
  const double fixed_h0 = cli.get_number("fixed-h0", 0, "fix H0 (m; 0: fit it)");
  const double depth = cli.get_number("depth", 0.16, "still-water depth h, m");
  const double period = cli.get_number("period", 1.4286, "wave period T, s");
  const double gravity = cli.get_number("gravity", 9.81, "m/s^2");
  analysis::StemField stems;
  stems.stem_height =
      cli.get_number("stem-height", 0.13, "stem height l_s (effective length l_e of flexible blades), m");
  stems.frontal_width = cli.get_number("frontal-width", 0.003, "stem frontal width b_v, m");
  stems.density = cli.get_number("stem-density", 7200, "stems per m^2, N");
  const double x_min = cli.get_number("x-min", -1e30, "use points with x >= x-min, m");
  const double x_max = cli.get_number("x-max", 1e30, "use points with x <= x-max, m");
  if (!cli.finish()) return 0;
  require_positive("--scale", scale);

  const auto table = io::read_csv(input);
  const auto xs = table.column(x_column), hs = table.column(h_column);
  std::vector<double> x, H;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    if (!std::isfinite(xs[i]) || !std::isfinite(hs[i]) || xs[i] < x_min || xs[i] > x_max) continue;
    x.push_back(xs[i]);
    H.push_back(hs[i] * scale);
  }
  const auto wave = waves::linear_wave(period, depth, gravity);
  const auto fit = analysis::fit_decay(x, H, fixed_h0 > 0 ? std::optional<double>(fixed_h0) : std::nullopt);
  const auto cd = analysis::drag_coefficient(fit, stems, wave.wave_number, depth);
  fmt::print("{}: {} points, x from {} to {} m\n", input, x.size(), x.front(), x.back());
  fmt::print("wave: h = {} m, T = {} s, k = {:.4f} 1/m, kh = {:.3f}, L = {:.3f} m\n", depth, period, wave.wave_number,
             wave.kh(), wave.wavelength);
  fmt::print("stems: l_s = {} m, b_v = {} m, N = {} 1/m^2 (b_v N = {:.3g} 1/m)\n", stems.stem_height,
             stems.frontal_width, stems.density, stems.frontal_width * stems.density);
  if (fit.incident_height_fixed) fmt::print("H0    = {:.5f} m (fixed)\n", fit.incident_height);
  else fmt::print("H0    = {:.5f} +- {:.5f} m\n", fit.incident_height, fit.se_height());
  fmt::print("alpha = {:.5f} +- {:.5f} 1/m   (RMS residual {:.2e} m)\n", fit.alpha, fit.se_alpha(), fit.rms_residual);
  fmt::print(
      "C_D   = {:.3f} +- {:.3f}   (standard error: fit covariance propagated to first order; scatter that is "
      "correlated along x, e.g. partial standing waves, makes it an underestimate)\n",
      cd.value, cd.standard_error);
  return 0;
} catch (const std::exception& e) {
  fmt::print(stderr, "fit_drag_coefficient: error: {}\n", e.what());
  return 1;
}
