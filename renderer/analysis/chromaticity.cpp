#include "renderer/analysis/chromaticity.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "renderer/core/errors/error.h"

namespace ofl {

bool parse_roi(const std::string& s, Roi* roi) {
  Roi r;
  char tail;
  if (std::sscanf(s.c_str(), "%d,%d,%d,%d%c", &r.x, &r.y, &r.w, &r.h, &tail) != 4) return false;
  if (r.w <= 0 || r.h <= 0 || r.x < 0 || r.y < 0) return false;
  *roi = r;
  return true;
}

Ellipse covariance_ellipse(double cx, double cy, double a, double b, double c, double chi2) {
  Ellipse e;
  e.cx = cx;
  e.cy = cy;
  double mid = 0.5 * (a + c), d = std::sqrt(0.25 * (a - c) * (a - c) + b * b);
  double l1 = mid + d, l2 = std::max(0.0, mid - d);
  e.a = std::sqrt(chi2 * std::max(0.0, l1));
  e.b = std::sqrt(chi2 * l2);
  e.angle_rad = 0.5 * std::atan2(2.0 * b, a - c);
  return e;
}

std::array<double, 2> rg_chromaticity(double R, double G, double B) {
  double s = R + G + B;
  if (!(s > 0)) return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  return {R / s, G / s};
}

nlohmann::json ChromaStats::to_json(bool with_points) const {
  nlohmann::json j = {{"roi", {roi.x, roi.y, roi.w, roi.h}},
                      {"cells", cells},
                      {"cells_used", used},
                      {"cells_saturated", saturated},
                      {"cells_nonpositive", nonpositive},
                      {"mean_rgb_dn", mean_rgb},
                      {"mean", {{"r", mean_r}, {"g", mean_g}}},
                      {"covariance", {{"rr", cov_rr}, {"rg", cov_rg}, {"gg", cov_gg}}},
                      {"ellipse95", {{"center", {ellipse95.cx, ellipse95.cy}},
                                     {"semi_axes", {ellipse95.a, ellipse95.b}},
                                     {"angle_deg", ellipse95.angle_rad * 180.0 / 3.14159265358979323846},
                                     {"chi_square", kChiSquare2Dof95}}}};
  if (with_points) j["points_rg"] = rg;
  return j;
}

ChromaStats roi_chromaticity(const std::vector<uint16_t>& dn, int w, int h, CfaPattern cfa, double black,
                             double white, const Roi& roi, bool include_saturated, const std::vector<uint8_t>* mask) {
  if (roi.x + roi.w > w || roi.y + roi.h > h)
    throw InputError("", "--roi", "region " + std::to_string(roi.x) + "," + std::to_string(roi.y) + "," +
                                      std::to_string(roi.w) + "," + std::to_string(roi.h) + " leaves the " +
                                      std::to_string(w) + "x" + std::to_string(h) + " image");
  ChromaStats s;
  s.roi = roi;
  int x0 = (roi.x + 1) / 2 * 2, y0 = (roi.y + 1) / 2 * 2;
  double sr = 0, sg = 0, rgb[3] = {0, 0, 0};
  for (int y = y0; y + 1 < roi.y + roi.h; y += 2)
    for (int x = x0; x + 1 < roi.x + roi.w; x += 2) {
      if (mask) {
        auto in = [&](int xx, int yy) { return (*mask)[static_cast<size_t>(yy) * w + xx] != 0; };
        if (!(in(x, y) && in(x + 1, y) && in(x, y + 1) && in(x + 1, y + 1))) continue;
      }
      ++s.cells;
      double sum[3] = {0, 0, 0};
      int count[3] = {0, 0, 0};
      bool sat = false;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          uint16_t v = dn[static_cast<size_t>(y + dy) * w + x + dx];
          sat = sat || v >= white;
          int c = cfa_channel(cfa, x + dx, y + dy);
          sum[c] += v - black;
          ++count[c];
        }
      if (sat) ++s.saturated;
      if (sat && !include_saturated) continue;
      double R = sum[0] / count[0], G = sum[1] / count[1], B = sum[2] / count[2];
      auto rg = rg_chromaticity(R, G, B);
      if (std::isnan(rg[0])) {
        ++s.nonpositive;
        continue;
      }
      s.rg.push_back(rg);
      sr += rg[0];
      sg += rg[1];
      rgb[0] += R;
      rgb[1] += G;
      rgb[2] += B;
    }
  if (s.cells == 0) throw InputError("", "--roi", "holds no complete 2x2 CFA cell");
  s.used = s.rg.size();
  if (s.used == 0) return s;
  double n = static_cast<double>(s.used);
  s.mean_r = sr / n;
  s.mean_g = sg / n;
  for (int c = 0; c < 3; ++c) s.mean_rgb[c] = rgb[c] / n;
  if (s.used > 1) {
    for (auto& p : s.rg) {
      double dr = p[0] - s.mean_r, dg = p[1] - s.mean_g;
      s.cov_rr += dr * dr;
      s.cov_rg += dr * dg;
      s.cov_gg += dg * dg;
    }
    s.cov_rr /= n - 1;
    s.cov_rg /= n - 1;
    s.cov_gg /= n - 1;
  }
  s.ellipse95 = covariance_ellipse(s.mean_r, s.mean_g, s.cov_rr, s.cov_rg, s.cov_gg);
  return s;
}

}  // namespace ofl
