#include "renderer/diagnose/spectra/flat_patch.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "renderer/spectral/spectra/units.h"

namespace ofl {

nlohmann::json flat_patch_scene(const nlohmann::json& material, const WavelengthGrid& grid,
                                const std::vector<double>& excitation, double band_min_nm, double band_max_nm,
                                const PatchRenderOptions& o) {
  if (static_cast<int>(excitation.size()) != grid.size()) throw std::invalid_argument("flat_patch_scene: excitation not on the grid");
  // The bin values as a piecewise-constant table (two points per bin), so that the scene's bin
  // means give back exactly these values.
  nlohmann::json pts = nlohmann::json::array();
  double area = 0;
  const double eps = 1e-4 * grid.step_nm;
  for (int i = 0; i < grid.size(); ++i) {
    double v = std::max(excitation[i], 0.0);
    pts.push_back({grid.bin_lo(i) + eps, v});
    pts.push_back({grid.bin_hi(i) - eps, v});
    area += v * grid.step_nm;
  }
  if (!(area > 0)) throw std::invalid_argument("flat_patch_scene: the excitation is zero");
  // LED at (d, 0, d) aimed at the origin: white radiance at the centre = I(l) cos(45) / (2 d^2) / pi.
  const double d = 0.07, r2 = 2 * d * d, cos_i = std::sqrt(0.5);
  const double i0 = kPi * r2 / cos_i * area;
  auto snap = [&](double nm) { return grid.wavelength(std::clamp(static_cast<int>(std::lround((nm - grid.min_nm) / grid.step_nm)), 0, grid.size() - 1)); };
  double bmin = snap(std::max(band_min_nm, grid.min_nm + grid.step_nm)), bmax = snap(std::min(band_max_nm, grid.max_nm - grid.step_nm));
  return {{"format", "oralfluor-scene"},
          {"version", 1},
          {"integrator",
           {{"spp", o.spp},
            {"max_depth", 1},
            {"seed", o.seed},
            {"wavelengths", {{"min_nm", grid.min_nm}, {"max_nm", grid.max_nm}, {"step_nm", grid.step_nm}}},
            {"output_bands", {{"min_nm", bmin}, {"max_nm", bmax}, {"step_nm", grid.step_nm}}}}},
          {"camera", {{"position", {0, 0, 0.1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 2}, {"resolution", {o.resolution, o.resolution}}}},
          {"materials", {{"patch", material}}},
          {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.1, 0, 0}}, {"v", {0, 0.1, 0}}, {"material", "patch"}}}},
          {"lights", {{{"name", "measured LED"}, {"spd", {{"type", "points"}, {"points", pts}}}, {"radiant_intensity_W_sr", i0},
                       {"position", {d, 0, d}}, {"target", {0, 0, 0}}}}}};
}

}  // namespace ofl
