#include "renderer/sweep/metrics/sweep_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "renderer/analysis/chromaticity.h"

namespace ofl {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPiM = 3.14159265358979323846;

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

Spread spread_of(const std::vector<CellSample>& cells, bool nf) {
  std::vector<std::array<double, 2>> rg;
  rg.reserve(cells.size());
  for (auto& c : cells) rg.push_back(nf ? c.rg_nf : c.rg);
  return chroma_spread(rg);
}
}  // namespace

double mean_of(const std::vector<double>& x) {
  if (x.empty()) return kNaN;
  double s = 0;
  for (double v : x) s += v;
  return s / double(x.size());
}

double std_of(const std::vector<double>& x) {
  if (x.size() < 2) return kNaN;
  double m = mean_of(x), s = 0;
  for (double v : x) s += (v - m) * (v - m);
  return std::sqrt(s / double(x.size() - 1));
}

double percentile(std::vector<double> x, double p) {
  if (x.empty()) return kNaN;
  std::sort(x.begin(), x.end());
  double h = p * double(x.size() - 1);
  size_t i = size_t(std::floor(h));
  if (i + 1 >= x.size()) return x.back();
  return x[i] + (h - double(i)) * (x[i + 1] - x[i]);
}

double pearson(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size() || x.size() < 3) return kNaN;
  double mx = mean_of(x), my = mean_of(y), sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (!(sxx > 0) || !(syy > 0)) return kNaN;
  return sxy / std::sqrt(sxx * syy);
}

double ls_slope(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size() || x.size() < 2) return kNaN;
  double mx = mean_of(x), my = mean_of(y), sxy = 0, sxx = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  return sxx > 0 ? sxy / sxx : kNaN;
}

double ellipse_area(double a, double b, double c) {
  double det = a * c - b * b;
  return kPiM * kChiSquare2Dof95 * std::sqrt(std::max(0.0, det));
}

IrradianceStats irradiance_stats(const std::vector<float>& irr, const std::vector<uint8_t>& mask) {
  IrradianceStats s;
  std::vector<double> v;
  for (size_t i = 0; i < irr.size() && i < mask.size(); ++i)
    if (mask[i]) v.push_back(irr[i]);
  s.pixels = v.size();
  if (v.empty()) {
    s.mean = s.min = s.max = s.p5 = s.p95 = s.cv = s.min_over_max = s.p5_over_p95 = kNaN;
    return s;
  }
  s.mean = mean_of(v);
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  s.p5 = percentile(v, 0.05);
  s.p95 = percentile(v, 0.95);
  s.cv = s.mean > 0 ? std_of(v) / s.mean : kNaN;
  s.min_over_max = s.max > 0 ? s.min / s.max : kNaN;
  s.p5_over_p95 = s.p95 > 0 ? s.p5 / s.p95 : kNaN;
  return s;
}

Spread chroma_spread(const std::vector<std::array<double, 2>>& rg) {
  Spread s;
  s.n = rg.size();
  if (rg.empty()) {
    s.mean_r = s.mean_g = s.std_r = s.std_g = s.cov_rr = s.cov_rg = s.cov_gg = s.area = kNaN;
    return s;
  }
  for (auto& p : rg) {
    s.mean_r += p[0];
    s.mean_g += p[1];
  }
  s.mean_r /= double(s.n);
  s.mean_g /= double(s.n);
  if (s.n < 2) {
    s.std_r = s.std_g = s.cov_rr = s.cov_rg = s.cov_gg = s.area = kNaN;
    return s;
  }
  for (auto& p : rg) {
    double dr = p[0] - s.mean_r, dg = p[1] - s.mean_g;
    s.cov_rr += dr * dr;
    s.cov_rg += dr * dg;
    s.cov_gg += dg * dg;
  }
  double k = 1.0 / double(s.n - 1);
  s.cov_rr *= k;
  s.cov_rg *= k;
  s.cov_gg *= k;
  s.std_r = std::sqrt(s.cov_rr);
  s.std_g = std::sqrt(s.cov_gg);
  s.area = ellipse_area(s.cov_rr, s.cov_rg, s.cov_gg);
  return s;
}

LesionContrast lesion_contrast(const std::vector<std::array<double, 2>>& a, const std::vector<std::array<double, 2>>& b) {
  LesionContrast c{kNaN, kNaN};
  if (a.empty() || b.empty()) return c;
  Spread sa = chroma_spread(a), sb = chroma_spread(b);
  double dr = sa.mean_r - sb.mean_r, dg = sa.mean_g - sb.mean_g;
  c.distance = std::sqrt(dr * dr + dg * dg);
  if (sa.n < 2 || sb.n < 2) return c;
  double wa = double(sa.n - 1), wb = double(sb.n - 1), w = wa + wb;
  double prr = (wa * sa.cov_rr + wb * sb.cov_rr) / w, prg = (wa * sa.cov_rg + wb * sb.cov_rg) / w,
         pgg = (wa * sa.cov_gg + wb * sb.cov_gg) / w;
  double det = prr * pgg - prg * prg;
  if (!(det > 0)) return c;
  // d^T S^-1 d with S^-1 = [pgg -prg; -prg prr] / det
  c.mahalanobis = std::sqrt(std::max(0.0, (dr * dr * pgg - 2 * dr * dg * prg + dg * dg * prr) / det));
  return c;
}

double emva_noise_e(double mu, const SensorDescription& s) {
  double k = s.total_gain();
  double var = std::max(0.0, mu) + s.dark_electrons() + s.read_noise_e * s.read_noise_e + s.dsnu_e * s.dsnu_e +
               (s.prnu * mu) * (s.prnu * mu) + (k > 0 ? 1.0 / (12.0 * k * k) : 0.0);
  return std::sqrt(var);
}

RoiCells roi_cells(const MetricImages& im, const std::vector<uint8_t>& mask) {
  RoiCells out;
  const int w = im.width, h = im.height;
  for (int y = 0; y + 1 < h; y += 2)
    for (int x = 0; x + 1 < w; x += 2) {
      size_t i00 = size_t(y) * w + x, i10 = i00 + 1, i01 = i00 + w, i11 = i01 + 1;
      if (!(mask[i00] && mask[i10] && mask[i01] && mask[i11])) continue;
      ++out.complete;
      double raw[3] = {0, 0, 0}, e[3] = {0, 0, 0}, ea[3] = {0, 0, 0}, eb[3] = {0, 0, 0}, irr = 0, ang = 0;
      int count[3] = {0, 0, 0};
      bool sat = false;
      for (size_t i : {i00, i10, i01, i11}) {
        int px = int(i % size_t(w)), py = int(i / size_t(w));
        int c = cfa_channel(im.cfa, px, py);
        if (im.raw) {
          sat = sat || (*im.raw)[i] >= im.white;
          raw[c] += double((*im.raw)[i]) - im.black;
        }
        if (im.channel_e) {
          for (int k = 0; k < 3; ++k) {
            e[k] += (*im.channel_e)[i * 3 + k] / 4.0;
            if (im.channel_e_a && im.channel_e_b) {
              ea[k] += (*im.channel_e_a)[i * 3 + k] / 4.0;
              eb[k] += (*im.channel_e_b)[i * 3 + k] / 4.0;
            }
          }
        } else {
          e[c] += (*im.expected)[i];
        }
        irr += im.irradiance ? (*im.irradiance)[i] : kNaN;
        ang += im.field_angle_deg ? (*im.field_angle_deg)[i] : kNaN;
        ++count[c];
      }
      if (sat) {
        ++out.saturated;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        raw[c] /= count[c];
        if (!im.channel_e) e[c] /= count[c];
      }
      CellSample s;
      s.x = x;
      s.y = y;
      s.rg = im.raw ? rg_chromaticity(raw[0], raw[1], raw[2]) : rg_chromaticity(e[0], e[1], e[2]);
      s.rg_nf = rg_chromaticity(e[0], e[1], e[2]);
      if (std::isnan(s.rg[0]) || std::isnan(s.rg_nf[0])) continue;
      bool halves = im.channel_e && im.channel_e_a && im.channel_e_b;
      s.rg_a = halves ? rg_chromaticity(ea[0], ea[1], ea[2]) : std::array<double, 2>{kNaN, kNaN};
      s.rg_b = halves ? rg_chromaticity(eb[0], eb[1], eb[2]) : std::array<double, 2>{kNaN, kNaN};
      s.intensity = e[0] + e[1] + e[2];
      s.irradiance = irr / 4.0;
      s.field_angle_deg = ang / 4.0;
      out.cells.push_back(s);
    }
  return out;
}

const std::vector<std::string>& roi_metric_names() {
  static const std::vector<std::string> n = {
      "pixels",       "cells",        "saturated_fraction", "irr_mean",   "irr_min_max",     "irr_p5_p95",
      "irr_cv",       "int_cv",       "r_mean",             "g_mean",     "r_std",           "g_std",
      "ellipse_area", "r_std_nf",     "g_std_nf",           "ellipse_area_nf", "r_std_mc",   "g_std_mc",
      "r_std_light",  "g_std_light",  "ellipse_area_light", "corr_int_r", "corr_int_g",
      "corr_irr_r",   "corr_irr_g",   "slope_r_irr",        "slope_g_irr", "slope_r_angle",    "slope_g_angle",
      "share_fluorescence", "share_reflected",
      "share_leak",   "snr_R",        "snr_G",              "snr_B",      "snr_fl"};
  return n;
}

const std::vector<std::string>& contrast_metric_names() {
  static const std::vector<std::string> n = {"dist_rg", "mahalanobis", "mahalanobis_nf"};
  return n;
}

nlohmann::ordered_json contrast_metrics(const RoiCells& lesion, const RoiCells& healthy) {
  std::vector<std::array<double, 2>> a, b, a_nf, b_nf;
  for (auto& c : lesion.cells) {
    a.push_back(c.rg);
    a_nf.push_back(c.rg_nf);
  }
  for (auto& c : healthy.cells) {
    b.push_back(c.rg);
    b_nf.push_back(c.rg_nf);
  }
  LesionContrast raw = lesion_contrast(a, b), nf = lesion_contrast(a_nf, b_nf);
  nlohmann::ordered_json j;
  j["dist_rg"] = num(raw.distance);
  j["mahalanobis"] = num(raw.mahalanobis);
  j["mahalanobis_nf"] = num(nf.mahalanobis);
  return j;
}

namespace {

// Irradiance over the ROI's pixels (aov.irradiance): mean, min/max, p5/p95, coefficient of variation.
void add_irradiance_metrics(nlohmann::ordered_json& j, const MetricImages& im, const std::vector<uint8_t>& mask) {
  IrradianceStats irr = im.irradiance ? irradiance_stats(*im.irradiance, mask) : IrradianceStats{};
  bool have_irr = im.irradiance && irr.pixels > 0;
  j["irr_mean"] = have_irr ? num(irr.mean) : nullptr;
  j["irr_min_max"] = have_irr ? num(irr.min_over_max) : nullptr;
  j["irr_p5_p95"] = have_irr ? num(irr.p5_over_p95) : nullptr;
  j["irr_cv"] = have_irr ? num(irr.cv) : nullptr;
}

// The cells' intensity spread, chromaticity spread (raw, noise-free, Monte Carlo and what is left
// without it) and how chromaticity follows intensity, irradiance and field angle.
void add_chromaticity_metrics(nlohmann::ordered_json& j, const RoiCells& rc) {
  std::vector<double> inten, r_nf, g_nf, lirr, r_irr, g_irr, irr_lin, ang10, r_ang, g_ang;
  for (auto& c : rc.cells) {
    inten.push_back(c.intensity);
    if (std::isfinite(c.field_angle_deg)) {
      ang10.push_back(c.field_angle_deg / 10.0);
      r_ang.push_back(c.rg_nf[0]);
      g_ang.push_back(c.rg_nf[1]);
    }
    r_nf.push_back(c.rg_nf[0]);
    g_nf.push_back(c.rg_nf[1]);
    if (c.irradiance > 0) {
      irr_lin.push_back(c.irradiance);
      lirr.push_back(std::log10(c.irradiance));
      r_irr.push_back(c.rg_nf[0]);
      g_irr.push_back(c.rg_nf[1]);
    }
  }
  double im_mean = mean_of(inten);
  j["int_cv"] = im_mean > 0 ? num(std_of(inten) / im_mean) : nullptr;
  Spread raw = spread_of(rc.cells, false), nf = spread_of(rc.cells, true);
  j["r_mean"] = num(raw.mean_r);
  j["g_mean"] = num(raw.mean_g);
  j["r_std"] = num(raw.std_r);
  j["g_std"] = num(raw.std_g);
  j["ellipse_area"] = num(raw.area);
  j["r_std_nf"] = num(nf.std_r);
  j["g_std_nf"] = num(nf.std_g);
  j["ellipse_area_nf"] = num(nf.area);
  // Monte Carlo noise from the two renders, and the spread that is left without it.
  std::vector<std::array<double, 2>> half_diff;
  for (auto& c : rc.cells)
    if (std::isfinite(c.rg_a[0]) && std::isfinite(c.rg_b[0]))
      half_diff.push_back({0.5 * (c.rg_a[0] - c.rg_b[0]), 0.5 * (c.rg_a[1] - c.rg_b[1])});
  if (half_diff.size() >= 2 && half_diff.size() == rc.cells.size()) {
    Spread mc = chroma_spread(half_diff);
    double rr = nf.cov_rr - mc.cov_rr, rg = nf.cov_rg - mc.cov_rg, gg = nf.cov_gg - mc.cov_gg;
    j["r_std_mc"] = num(mc.std_r);
    j["g_std_mc"] = num(mc.std_g);
    j["r_std_light"] = num(std::sqrt(std::max(0.0, rr)));
    j["g_std_light"] = num(std::sqrt(std::max(0.0, gg)));
    j["ellipse_area_light"] = (rr > 0 && gg > 0) ? num(ellipse_area(rr, rg, gg)) : nlohmann::json(0.0);
  } else {
    for (const char* k : {"r_std_mc", "g_std_mc", "r_std_light", "g_std_light", "ellipse_area_light"}) j[k] = nullptr;
  }
  j["corr_int_r"] = num(pearson(inten, r_nf));
  j["corr_int_g"] = num(pearson(inten, g_nf));
  j["corr_irr_r"] = num(pearson(irr_lin, r_irr));
  j["corr_irr_g"] = num(pearson(irr_lin, g_irr));
  j["slope_r_irr"] = num(ls_slope(lirr, r_irr));
  j["slope_g_irr"] = num(ls_slope(lirr, g_irr));
  j["slope_r_angle"] = num(ls_slope(ang10, r_ang));
  j["slope_g_angle"] = num(ls_slope(ang10, g_ang));
}

// Shares (fluorescence, reflected, leak) and SNR over the ROI's pixels, each pixel counting its own
// CFA colour.
void add_signal_metrics(nlohmann::ordered_json& j, const MetricImages& im, const std::vector<uint8_t>& mask,
                        const SensorDescription& sensor) {
  double parts[3] = {0, 0, 0}, ch_sum[3] = {0, 0, 0}, fl_ch[3] = {0, 0, 0};
  size_t ch_n[3] = {0, 0, 0};
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      size_t i = size_t(y) * im.width + x;
      if (!mask[i]) continue;
      int c = cfa_channel(im.cfa, x, y);
      ch_sum[c] += (*im.expected)[i];
      ++ch_n[c];
      if (im.fluorescence && im.reflected && im.leak) {
        parts[0] += (*im.fluorescence)[i];
        parts[1] += (*im.reflected)[i];
        parts[2] += (*im.leak)[i];
        fl_ch[c] += (*im.fluorescence)[i];
      }
    }
  double total = parts[0] + parts[1] + parts[2];
  bool split = im.fluorescence && im.reflected && im.leak && total > 0;
  j["share_fluorescence"] = split ? num(parts[0] / total) : nullptr;
  j["share_reflected"] = split ? num(parts[1] / total) : nullptr;
  j["share_leak"] = split ? num(parts[2] / total) : nullptr;
  const char* snr_names[3] = {"snr_R", "snr_G", "snr_B"};
  double mu[3], var_cell = 0;
  for (int c = 0; c < 3; ++c) {
    mu[c] = ch_n[c] ? ch_sum[c] / double(ch_n[c]) : kNaN;
    j[snr_names[c]] = ch_n[c] ? num(emva_snr(mu[c], sensor)) : nullptr;
  }
  // A cell holds one R, two G and one B pixel (every CFA pattern of cfa_pattern.h).
  bool all = ch_n[0] && ch_n[1] && ch_n[2];
  if (all && split) {
    double n0 = emva_noise_e(mu[0], sensor), n1 = emva_noise_e(mu[1], sensor), n2 = emva_noise_e(mu[2], sensor);
    var_cell = n0 * n0 + 2 * n1 * n1 + n2 * n2;
    double fl_cell = fl_ch[0] / double(ch_n[0]) + 2 * fl_ch[1] / double(ch_n[1]) + fl_ch[2] / double(ch_n[2]);
    j["snr_fl"] = num(fl_cell / std::sqrt(var_cell));
  } else {
    j["snr_fl"] = nullptr;
  }
}

}  // namespace

nlohmann::ordered_json roi_metrics(const MetricImages& im, const std::vector<uint8_t>& mask, const SensorDescription& sensor,
                                   RoiCells* cells_out) {
  nlohmann::ordered_json j;
  size_t pixels = 0;
  for (uint8_t m : mask) pixels += m != 0;
  RoiCells rc = roi_cells(im, mask);
  j["pixels"] = pixels;
  j["cells"] = rc.cells.size();
  j["saturated_fraction"] = rc.complete ? num(double(rc.saturated) / double(rc.complete)) : nlohmann::json(nullptr);
  add_irradiance_metrics(j, im, mask);
  add_chromaticity_metrics(j, rc);
  add_signal_metrics(j, im, mask, sensor);
  if (cells_out) *cells_out = std::move(rc);
  return j;
}

}  // namespace ofl
