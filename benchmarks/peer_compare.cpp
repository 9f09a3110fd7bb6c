// The numbers of benchmarks/vs_pbrt.sh: oralfluor and pbrt-v4 rendered the same scene
// (benchmarks/scenes/peers/) in interleaved rounds at equal samples per pixel, each with a
// reference of many more samples. For every round and renderer: camera samples per second, rays
// per camera sample, the relative RMS error against the renderer's own reference (of the total
// radiance per pixel, and per 10 nm band), and from them the time each needs to reach the same
// error. Monte Carlo error falls like 1/sqrt(time), so that time is proportional to t e^2; the
// ratio pbrt / oralfluor of t e^2 is "pbrt needs x times oralfluor's time to equal error". The
// reference's own noise is taken out of e^2 (an independent reference of N samples adds e^2 n / N
// to a render of n samples).
//
// Two clocks: the render time each renderer reports (wall clock, without loading and building),
// and CPU time (user + system of the process, minus what a 1-spp run of the same scene costs,
// scaled to the render's samples), which other processes on a shared machine disturb far less.
//
//   usage: peer_compare <dir> <rounds> [--speed-only] [--json]
//          peer_compare --agree <a.exr> <b.exr>
//          peer_compare --error <image.exr> <reference.exr>
// <dir> holds, for i = 1..rounds, oralfluor_<i>/ (radiance.exr, render.json), pbrt_<i>.exr,
// pbrt_<i>.log (pbrt's --stats output), a <stem>.time for each ("wall user system" seconds), the
// 1-spp runs oralfluor_setup_<k> and pbrt_setup_<k> (k = 1..3), pbrt_ref.json ({"spp": reference
// spp, "round_spp": spp of a round}), and unless --speed-only the references oralfluor_ref/ and
// pbrt_ref.exr.
// --agree: do two independent renders of the same scene (another seed, another estimator) agree
// within their noise? Per band and for the band sum, the image-mean difference over its standard
// error (from the spread of the per-pixel differences; pixels are independent).
#include <ImfFloatAttribute.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/image/spectral_exr.h"

using namespace ofl;
using nlohmann::json;

namespace {

struct Render {
  SpectralImage img;
  double wall = 0;         // render time the renderer reports (no loading or building)
  double process_cpu = 0;  // user + system seconds of the whole process
  double cpu = 0;          // CPU seconds of rendering alone (see cpu_of_rendering)
  int spp = 0;
  double rays = 0, camera_samples = 0;
};

double json_number(const std::string& file, const char* key) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file);
  return json::parse(in).at(key).get<double>();
}

// A number printed after `label` in pbrt's --stats output ("Camera rays traced   4194304").
double stats_number(const std::string& log, const std::string& label) {
  std::ifstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    size_t at = line.find(label);
    if (at == std::string::npos) continue;
    std::istringstream rest(line.substr(at + label.size()));
    double v = 0;
    if (rest >> v) return v;
  }
  throw std::runtime_error(log + ": no \"" + label + "\" line (was pbrt run with --stats?)");
}

// User + system seconds from "<stem>.time" ("wall user system"), 0 when there is none.
double process_cpu(const std::string& stem) {
  std::ifstream in(stem + ".time");
  double wall = 0, user = 0, sys = 0;
  if (!(in >> wall >> user >> sys)) return 0;
  return user + sys;
}

Render read_oralfluor(const std::string& stem, bool image = true) {
  Render r;
  if (image) r.img = read_spectral_exr(stem + "/radiance.exr");
  r.wall = json_number(stem + "/render.json", "render_seconds");
  r.spp = int(json_number(stem + "/render.json", "spp"));
  r.rays = json_number(stem + "/render.json", "rays");
  r.camera_samples = json_number(stem + "/render.json", "width") * json_number(stem + "/render.json", "height") * r.spp;
  r.process_cpu = process_cpu(stem);
  return r;
}

Render read_pbrt(const std::string& stem, int spp, bool image = true) {
  Render r;
  const std::string exr = stem + ".exr";
  if (image) r.img = read_spectral_exr(exr);
  Imf::InputFile f(exr.c_str());
  const auto* t = f.header().findTypedAttribute<Imf::FloatAttribute>("renderTimeSeconds");
  if (!t) throw std::runtime_error(exr + ": no renderTimeSeconds attribute");
  r.wall = t->value();
  const Imath::Box2i win = f.header().dataWindow();
  r.spp = spp;
  r.camera_samples = double(win.max.x - win.min.x + 1) * (win.max.y - win.min.y + 1) * spp;
  if (std::filesystem::exists(stem + ".log"))
    r.rays = stats_number(stem + ".log", "Regular ray intersection tests") + stats_number(stem + ".log", "Shadow ray intersection tests");
  r.process_cpu = process_cpu(stem);
  return r;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// CPU seconds of rendering alone: a run of n spp costs S + n c, the 1-spp runs S + c, so the n
// samples cost n (cpu - cpu_1) / (n - 1).
double cpu_of_rendering(const Render& r, double cpu_1spp) {
  if (r.process_cpu <= 0 || cpu_1spp <= 0 || r.spp <= 1) return 0;
  return r.spp * (r.process_cpu - cpu_1spp) / (r.spp - 1);
}

// Squared relative RMS errors against the reference: of the total (band sum) per pixel, and the
// mean over bands of each band's.
struct Errors { double total2 = 0, band2 = 0; std::vector<double> per_band2; };

Errors errors(const SpectralImage& a, const SpectralImage& ref) {
  if (a.width != ref.width || a.height != ref.height || a.bands() != ref.bands())
    throw std::runtime_error("image and reference differ in size or bands");
  const int B = a.bands();
  const size_t P = size_t(a.width) * a.height;
  std::vector<double> se(B, 0.0), mean(B, 0.0);
  double se_tot = 0, mean_tot = 0;
  for (size_t p = 0; p < P; ++p) {
    double ta = 0, tr = 0;
    for (int b = 0; b < B; ++b) {
      const double x = a.data[p * B + b], r = ref.data[p * B + b];
      se[b] += (x - r) * (x - r);
      mean[b] += r;
      ta += x;
      tr += r;
    }
    se_tot += (ta - tr) * (ta - tr);
    mean_tot += tr;
  }
  Errors e;
  e.total2 = (se_tot / P) / ((mean_tot / P) * (mean_tot / P));
  for (int b = 0; b < B; ++b) {
    e.per_band2.push_back((se[b] / P) / ((mean[b] / P) * (mean[b] / P)));
    e.band2 += e.per_band2.back() / B;
  }
  return e;
}

// e^2 of a render of n samples against a reference of N independent samples of the same
// estimator, without the reference's share.
double denoise(double e2, int n, int N) { return e2 / (1.0 + double(n) / N); }

// Image-mean radiance per band of both references, and their relative difference (band sum and
// worst band): the two renderers must agree on what they render.
json agreement(const SpectralImage& o, const SpectralImage& p) {
  const int B = o.bands();
  const size_t P = size_t(o.width) * o.height;
  double so = 0, sp = 0, worst = 0;
  for (int b = 0; b < B; ++b) {
    double mo = 0, mp = 0;
    for (size_t i = 0; i < P; ++i) { mo += o.data[i * B + b]; mp += p.data[i * B + b]; }
    so += mo;
    sp += mp;
    worst = std::max(worst, std::fabs(mo / mp - 1));
  }
  return {{"total_relative_difference", so / sp - 1}, {"worst_band_relative_difference", worst}};
}

struct Setup { double oralfluor = 0, pbrt = 0; };

Setup setup_cpu(const std::string& dir) {
  std::vector<double> o, p;
  for (int k = 1; k <= 3; ++k) {
    const std::string s = std::to_string(k);
    if (double c = process_cpu(dir + "/oralfluor_setup_" + s); c > 0) o.push_back(c);
    if (double c = process_cpu(dir + "/pbrt_setup_" + s); c > 0) p.push_back(c);
  }
  return {median(o), median(p)};
}

json range(const std::vector<double>& v) { return {*std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end())}; }

// One scene's rounds: samples per second by both clocks, rays per sample, and with references the
// time-to-equal-error ratios by both clocks.
json compare_rounds(const std::string& dir, int rounds, bool with_refs) {
  const int round_spp = int(json_number(dir + "/pbrt_ref.json", "round_spp"));
  const Setup setup = setup_cpu(dir);
  Render oref, pref;
  json out = {{"rounds", json::array()}, {"setup_cpu_seconds", {{"oralfluor", setup.oralfluor}, {"pbrt", setup.pbrt}}}};
  if (with_refs) {
    oref = read_oralfluor(dir + "/oralfluor_ref");
    pref = read_pbrt(dir + "/pbrt_ref", int(json_number(dir + "/pbrt_ref.json", "spp")));
    out["agreement"] = agreement(oref.img, pref.img);
    out["reference_spp"] = {{"oralfluor", oref.spp}, {"pbrt", pref.spp}};
  }
  std::vector<double> sps_o, sps_p, cps_o, cps_p, rps_o, rps_p, rt_w, rb_w, rt_c, rb_c;
  std::vector<std::vector<double>> per_band;  // [round][band] ratio by CPU time
  for (int i = 1; i <= rounds; ++i) {
    const std::string s = std::to_string(i);
    Render o = read_oralfluor(dir + "/oralfluor_" + s, with_refs), p = read_pbrt(dir + "/pbrt_" + s, round_spp, with_refs);
    o.cpu = cpu_of_rendering(o, setup.oralfluor);
    p.cpu = cpu_of_rendering(p, setup.pbrt);
    sps_o.push_back(o.camera_samples / o.wall);
    sps_p.push_back(p.camera_samples / p.wall);
    cps_o.push_back(o.cpu > 0 ? o.camera_samples / o.cpu : 0);
    cps_p.push_back(p.cpu > 0 ? p.camera_samples / p.cpu : 0);
    rps_o.push_back(o.rays / o.camera_samples);
    rps_p.push_back(p.rays / p.camera_samples);
    json r = {{"round", i},
              {"oralfluor", {{"wall_seconds", o.wall}, {"cpu_seconds", o.cpu}, {"camera_samples_per_second", sps_o.back()},
                             {"camera_samples_per_cpu_second", cps_o.back()}, {"rays_per_camera_sample", rps_o.back()}}},
              {"pbrt", {{"wall_seconds", p.wall}, {"cpu_seconds", p.cpu}, {"camera_samples_per_second", sps_p.back()},
                        {"camera_samples_per_cpu_second", cps_p.back()}, {"rays_per_camera_sample", rps_p.back()}}}};
    if (with_refs) {
      const Errors eo = errors(o.img, oref.img), ep = errors(p.img, pref.img);
      const double ot = denoise(eo.total2, o.spp, oref.spp), pt = denoise(ep.total2, p.spp, pref.spp);
      const double ob = denoise(eo.band2, o.spp, oref.spp), pb = denoise(ep.band2, p.spp, pref.spp);
      rt_w.push_back((p.wall * pt) / (o.wall * ot));
      rb_w.push_back((p.wall * pb) / (o.wall * ob));
      rt_c.push_back((p.cpu * pt) / (o.cpu * ot));
      rb_c.push_back((p.cpu * pb) / (o.cpu * ob));
      std::vector<double> bands;
      for (size_t b = 0; b < eo.per_band2.size(); ++b)
        bands.push_back((p.cpu * denoise(ep.per_band2[b], p.spp, pref.spp)) / (o.cpu * denoise(eo.per_band2[b], o.spp, oref.spp)));
      per_band.push_back(bands);
      r["oralfluor"]["rel_rms_total"] = std::sqrt(ot);
      r["oralfluor"]["rel_rms_band"] = std::sqrt(ob);
      r["pbrt"]["rel_rms_total"] = std::sqrt(pt);
      r["pbrt"]["rel_rms_band"] = std::sqrt(pb);
      r["equal_error_time_ratio"] = {{"total_wall", rt_w.back()}, {"band_wall", rb_w.back()}, {"total_cpu", rt_c.back()}, {"band_cpu", rb_c.back()}};
    }
    out["rounds"].push_back(r);
  }
  json m = {{"oralfluor_camera_samples_per_second", median(sps_o)}, {"pbrt_camera_samples_per_second", median(sps_p)},
            {"samples_per_second_ratio_wall", median(sps_o) / median(sps_p)},
            {"oralfluor_camera_samples_per_cpu_second", median(cps_o)}, {"pbrt_camera_samples_per_cpu_second", median(cps_p)},
            {"samples_per_second_ratio_cpu", median(cps_p) > 0 ? median(cps_o) / median(cps_p) : 0.0},
            {"oralfluor_rays_per_camera_sample", median(rps_o)}, {"pbrt_rays_per_camera_sample", median(rps_p)}};
  if (with_refs) {
    // Per band: the median over rounds of each band's ratio (CPU time), then the band least ahead.
    std::vector<double> band_medians;
    for (size_t b = 0; b < per_band[0].size(); ++b) {
      std::vector<double> v;
      for (auto& r : per_band) v.push_back(r[b]);
      band_medians.push_back(median(v));
    }
    const size_t worst = std::min_element(band_medians.begin(), band_medians.end()) - band_medians.begin();
    m["equal_error_time_ratio"] = {{"total_wall", median(rt_w)}, {"band_wall", median(rb_w)}, {"total_cpu", median(rt_c)}, {"band_cpu", median(rb_c)},
                                   {"range_total_cpu", range(rt_c)}, {"range_band_cpu", range(rb_c)},
                                   {"range_total_wall", range(rt_w)}, {"range_band_wall", range(rb_w)},
                                   {"worst_band_cpu", band_medians[worst]}, {"worst_band_nm", oref.img.band_nm[worst]}};
  }
  out["median"] = m;
  return out;
}

void print_markdown(const json& r, int rounds) {
  const bool refs = r["median"].contains("equal_error_time_ratio");
  std::printf("| round | oralfluor wall s / CPU s | pbrt wall s / CPU s | oralfluor M samples/s (wall / CPU) | pbrt M samples/s (wall / CPU) |%s\n",
              refs ? " oralfluor error total / band | pbrt error total / band | pbrt time to equal error, total (CPU / wall) | per band (CPU / wall) |" : "");
  std::printf("|---|---|---|---|---|%s\n", refs ? "---|---|---|---|" : "");
  for (auto& x : r["rounds"]) {
    const json &o = x["oralfluor"], &p = x["pbrt"];
    std::printf("| %d | %.2f / %.2f | %.2f / %.2f | %.3f / %.3f | %.3f / %.3f |", x["round"].get<int>(), o["wall_seconds"].get<double>(),
                o["cpu_seconds"].get<double>(), p["wall_seconds"].get<double>(), p["cpu_seconds"].get<double>(),
                o["camera_samples_per_second"].get<double>() * 1e-6, o["camera_samples_per_cpu_second"].get<double>() * 1e-6,
                p["camera_samples_per_second"].get<double>() * 1e-6, p["camera_samples_per_cpu_second"].get<double>() * 1e-6);
    if (refs) {
      const json& q = x["equal_error_time_ratio"];
      std::printf(" %.2f %% / %.2f %% | %.2f %% / %.2f %% | %.2fx / %.2fx | %.2fx / %.2fx |", 100 * o["rel_rms_total"].get<double>(),
                  100 * o["rel_rms_band"].get<double>(), 100 * p["rel_rms_total"].get<double>(), 100 * p["rel_rms_band"].get<double>(),
                  q["total_cpu"].get<double>(), q["total_wall"].get<double>(), q["band_cpu"].get<double>(), q["band_wall"].get<double>());
    }
    std::printf("\n");
  }
  const json& m = r["median"];
  std::printf("\nmedian of %d rounds: oralfluor %.3f M camera samples per second (wall) / %.3f M per CPU second, pbrt-v4 %.3f M / %.3f M:"
              " %.2fx (wall), %.2fx (CPU); rays per camera sample %.2f (oralfluor) and %.2f (pbrt-v4)\n",
              rounds, m["oralfluor_camera_samples_per_second"].get<double>() * 1e-6, m["oralfluor_camera_samples_per_cpu_second"].get<double>() * 1e-6,
              m["pbrt_camera_samples_per_second"].get<double>() * 1e-6, m["pbrt_camera_samples_per_cpu_second"].get<double>() * 1e-6,
              m["samples_per_second_ratio_wall"].get<double>(), m["samples_per_second_ratio_cpu"].get<double>(),
              m["oralfluor_rays_per_camera_sample"].get<double>(), m["pbrt_rays_per_camera_sample"].get<double>());
  if (!refs) return;
  const json& q = m["equal_error_time_ratio"];
  std::printf("pbrt-v4 needs %.2fx oralfluor's CPU time to equal error in the total radiance (rounds %.2f-%.2f; wall clock %.2fx, %.2f-%.2f),\n"
              "  %.2fx per 10 nm band (rounds %.2f-%.2f; wall clock %.2fx, %.2f-%.2f); the band least ahead, %.0f nm: %.2fx (CPU)\n"
              "references (oralfluor %d spp, pbrt-v4 %d spp) agree on the image-mean radiance to %+.3f %% (worst band %.2f %%)\n",
              q["total_cpu"].get<double>(), q["range_total_cpu"][0].get<double>(), q["range_total_cpu"][1].get<double>(), q["total_wall"].get<double>(),
              q["range_total_wall"][0].get<double>(), q["range_total_wall"][1].get<double>(), q["band_cpu"].get<double>(),
              q["range_band_cpu"][0].get<double>(), q["range_band_cpu"][1].get<double>(), q["band_wall"].get<double>(),
              q["range_band_wall"][0].get<double>(), q["range_band_wall"][1].get<double>(), q["worst_band_nm"].get<double>(),
              q["worst_band_cpu"].get<double>(), r["reference_spp"]["oralfluor"].get<int>(), r["reference_spp"]["pbrt"].get<int>(),
              100 * r["agreement"]["total_relative_difference"].get<double>(), 100 * r["agreement"]["worst_band_relative_difference"].get<double>());
}

int agree(const std::string& fa, const std::string& fb) {
  const SpectralImage a = read_spectral_exr(fa), b = read_spectral_exr(fb);
  if (a.width != b.width || a.height != b.height || a.bands() != b.bands()) throw std::runtime_error("the images differ in size or bands");
  const int B = a.bands();
  const size_t P = size_t(a.width) * a.height;
  auto z_of = [&](auto value) {  // value(image, pixel) -> {z, difference relative to b's mean}
    double s = 0, s2 = 0, m = 0;
    for (size_t p = 0; p < P; ++p) {
      const double d = value(a, p) - value(b, p);
      s += d;
      s2 += d * d;
      m += value(b, p);
    }
    const double mean = s / P, var = (s2 / P - mean * mean) / (P - 1);
    return std::pair<double, double>{mean / std::sqrt(var), mean / (m / P)};
  };
  double worst = 0;
  int worst_band = 0;
  for (int k = 0; k < B; ++k) {
    auto [z, rel] = z_of([&](const SpectralImage& im, size_t p) { return double(im.data[p * B + k]); });
    std::printf("%7.1f nm: difference %+.4f %% of the mean, z = %+.2f\n", a.band_nm[k], 100 * rel, z);
    if (std::fabs(z) > std::fabs(worst)) { worst = z; worst_band = k; }
  }
  auto [z, rel] = z_of([&](const SpectralImage& im, size_t p) {
    double t = 0;
    for (int k = 0; k < B; ++k) t += im.data[p * B + k];
    return t;
  });
  std::printf("band sum: difference %+.4f %% of the mean, z = %+.2f; largest |z| over %d bands: %.2f at %.0f nm\n", 100 * rel, z, B,
              std::fabs(worst), a.band_nm[worst_band]);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 4 && std::string(argv[1]) == "--agree") return agree(argv[2], argv[3]);
    if (argc == 4 && std::string(argv[1]) == "--error") {
      const Errors e = errors(read_spectral_exr(argv[2]), read_spectral_exr(argv[3]));
      std::printf("relative RMS error against the reference: total %.5f, band %.5f (reference noise included)\n", std::sqrt(e.total2), std::sqrt(e.band2));
      return 0;
    }
    if (argc < 3) {
      std::fprintf(stderr, "usage: peer_compare <dir> <rounds> [--speed-only] [--json] | --agree <a.exr> <b.exr> | --error <image.exr> <reference.exr>\n");
      return 2;
    }
    bool as_json = false, speed_only = false;
    for (int i = 3; i < argc; ++i) {
      as_json = as_json || std::string(argv[i]) == "--json";
      speed_only = speed_only || std::string(argv[i]) == "--speed-only";
    }
    const int rounds = std::atoi(argv[2]);
    const json r = compare_rounds(argv[1], rounds, !speed_only);
    if (as_json) std::printf("%s\n", r.dump(2).c_str());
    else print_markdown(r, rounds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "peer_compare: %s\n", e.what());
    return 1;
  }
  return 0;
}
